//! GREE on a synthetic two-region case: filter A is exact on the left half and noisy on the
//! right, B the other way round; the caches see the truth plus small independent noise.

mod common;

use common::{mse, truth, with_noise, Independent};
use rt_gree::{composite, GreeParams, Rgb, RgbImage};

const W: usize = 128;
const H: usize = 96;

struct Case {
    truth: RgbImage,
    noisy: RgbImage,
    variance: RgbImage,
    bank: Vec<RgbImage>,
}

fn case() -> Case {
    let truth = truth(W, H);
    let sigma_n = 0.15;
    let noisy = with_noise(&truth, sigma_n, 1, |_, _| true);
    let variance = RgbImage::from_fn(W, H, |_, _| Rgb::splat(sigma_n * sigma_n));
    let a = with_noise(&truth, 0.1, 2, |x, _| x >= W / 2);
    let b = with_noise(&truth, 0.1, 3, |x, _| x < W / 2);
    Case {
        truth,
        noisy,
        variance,
        bank: vec![a, b],
    }
}

#[test]
fn composite_beats_every_filter_and_the_argmin() {
    let c = case();
    let params = GreeParams::default();
    let mut renderer = Independent::new(&c.truth, 0.5, 9);
    let out = composite(&c.noisy, &c.variance, &c.bank, &mut renderer, &params).unwrap();
    let (ma, mb) = (mse(&c.bank[0], &c.truth), mse(&c.bank[1], &c.truth));
    let m_argmin = mse(&out.argmin_image, &c.truth);
    let m = mse(&out.image, &c.truth);
    eprintln!("A {ma:.2e} B {mb:.2e} argmin {m_argmin:.2e} GREE {m:.2e}");
    assert!(m <= 0.9 * ma.min(mb), "{m} vs {ma}, {mb}");
    // The graph cut removes isolated wrong picks (fusion alone, on the argmin labels, does not
    // come close to this).
    assert!(
        m < 0.5 * m_argmin,
        "graph cut should remove isolated wrong picks: {m} vs {m_argmin}"
    );
    assert!(out.energy.1 <= out.energy.0);
    // The labels follow the regions away from the seam.
    let wrong = (0..W * H)
        .filter(|&p| {
            let x = p % W;
            (x + 6 < W / 2 && out.labels[p] != 0) || (x > W / 2 + 6 && out.labels[p] != 1)
        })
        .count();
    assert!(
        wrong * 100 < W * H,
        "{wrong} wrong labels away from the seam"
    );
    // Budget: the caches traced what the budget says, and the renderer agrees.
    let budget = params.budget_split();
    assert_eq!((budget.n, budget.c), (28, 108));
    assert_eq!(out.caches.len(), budget.caches(W * H));
    assert_eq!(out.samples_traced, budget.cache_samples(W * H));
    assert_eq!(renderer.traced, out.samples_traced);
    assert_eq!(out.error_maps.len(), 2);
    assert!(out.error_maps.iter().all(|m| m.len() == W * H));
}

#[test]
fn same_bits_for_any_thread_count() {
    let c = case();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut r = Independent::new(&c.truth, 0.5, 9);
            composite(
                &c.noisy,
                &c.variance,
                &c.bank,
                &mut r,
                &GreeParams::default(),
            )
            .unwrap()
        })
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.image, b.image);
    assert_eq!(a.labels, b.labels);
    assert_eq!(a.error_maps, b.error_maps);
    assert_eq!(a.caches, b.caches);
    assert_eq!(a.energy, b.energy);
}
