//! SBMF's tests: step B's invariants (partition of unity, in-focus pass-through, uniform colour,
//! work independent of τ), step A's noise reduction on a synthetic sample set, determinism and
//! parameter validation.

use super::layers::{layer_weights, Layers, MAX_SCALES};
use super::*;
use rt_core::glam::Vec3;
use rt_core::rng::SplitMix64;
use rt_film::Sample;

fn records(w: u32, h: u32, samples: &[Sample]) -> SampleRecords {
    SampleRecords::from_samples(w, h, samples).unwrap()
}

/// `spp` samples per pixel (one fewer in every third pixel) of colour `colour(x, y, k)` and
/// CoC `coc(x, y, k)`, on a plane facing the camera.
fn sample_set(
    w: u32,
    h: u32,
    spp: u32,
    mut colour: impl FnMut(u32, u32, u32) -> Rgb,
    mut coc: impl FnMut(u32, u32, u32) -> f32,
) -> SampleRecords {
    let mut v = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let n = if (x + y) % 3 == 0 { spp - 1 } else { spp };
            for k in 0..n {
                v.push(Sample {
                    pixel: y * w + x,
                    radiance: colour(x, y, k),
                    normal: Vec3::Z,
                    position: Vec3::new(x as f32, y as f32, 0.0) * 0.01,
                    albedo: Rgb::splat(0.5),
                    coc: coc(x, y, k),
                });
            }
        }
    }
    records(w, h, &v)
}

fn sbmf(layers: usize, max_coc: f32) -> Sbmf {
    Sbmf::new(SbmfParams {
        layers,
        max_coc,
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn layer_weights_are_a_partition_of_unity_for_any_coverage() {
    let mut rng = SplitMix64::from_state(1);
    let mut clamped = 0;
    for case in 0..10_000 {
        let scales = if case % 2 == 0 { 2 } else { 4 };
        let own = case % scales;
        let cov: [f32; MAX_SCALES] = std::array::from_fn(|_| rng.f32() * 0.9);
        let w = layer_weights(&cov, scales, own);
        let sum: f32 = w[..scales].iter().sum();
        assert!(
            (sum - 1.0).abs() < 1e-5,
            "{cov:?} own {own}: {w:?} sums to {sum}"
        );
        assert!(w.iter().all(|&x| x >= 0.0));
        let others: f32 = (0..scales).filter(|&f| f != own).map(|f| cov[f]).sum();
        if others <= 1.0 {
            // Where the thesis' formula needs no clamping it is used as is.
            assert!((w[own] - (1.0 - others)).abs() < 1e-6);
        } else {
            clamped += 1;
            assert_eq!(w[own], 0.0);
        }
    }
    assert!(clamped > 100, "the clamped case was exercised ({clamped})");
}

#[test]
fn an_in_focus_image_passes_through_step_b_unchanged() {
    let mut rng = SplitMix64::from_state(2);
    let (w, h) = (23, 17);
    let rec = sample_set(
        w,
        h,
        4,
        |_, _, _| Rgb::new(rng.f32(), 3.0 * rng.f32(), 0.1),
        |_, _, _| 0.0,
    );
    let colour = rec.radiance().to_vec();
    for layers in [3, 7] {
        let (img, stats) = sbmf(layers, 0.0)
            .step_b(&rec, &colour, w as usize, h as usize)
            .unwrap();
        assert_eq!(stats.tau, 0.0);
        for i in 0..(w * h) as usize {
            let r = rec.pixel_range(i);
            let mean = colour[r.clone()].iter().copied().sum::<Rgb>() / r.len() as f32;
            let got = img.pixels()[i];
            assert!(
                (got - mean).abs().max_element() <= 1e-6 * mean.max_element().max(1.0),
                "{i}: {got} vs {mean}"
            );
        }
    }
    // A set τ with every CoC zero: still all on the focal layer, which is not blurred.
    let (img, _) = sbmf(7, 16.0)
        .step_b(&rec, &colour, w as usize, h as usize)
        .unwrap();
    let r = rec.pixel_range(40);
    let mean = colour[r.clone()].iter().copied().sum::<Rgb>() / r.len() as f32;
    assert!((img.pixels()[40] - mean).abs().max_element() < 1e-6);
}

#[test]
fn a_uniform_colour_stays_uniform_for_any_coc_distribution() {
    let c = Rgb::new(0.3, 1.7, 0.05);
    let (w, h) = (40, 30);
    for (seed, spread) in [(3, 2.0), (4, 10.0), (5, 40.0)] {
        let mut rng = SplitMix64::from_state(seed);
        let rec = sample_set(
            w,
            h,
            4,
            |_, _, _| c,
            |x, _, _| {
                // Depth bands plus noise: fronts, backs and the focal plane side by side.
                let band = ((x / 7) % 3) as f32 - 1.0;
                band * spread * rng.f32()
            },
        );
        for layers in [3, 7] {
            let colour = rec.radiance().to_vec();
            let (img, _) = sbmf(layers, 0.0)
                .step_b(&rec, &colour, w as usize, h as usize)
                .unwrap();
            for p in img.pixels() {
                assert!(
                    (*p - c).abs().max_element() < 1e-5,
                    "{p} vs {c} (spread {spread}, {layers} layers)"
                );
            }
        }
    }
}

#[test]
fn step_b_work_does_not_depend_on_the_circle_of_confusion() {
    let mut rng = SplitMix64::from_state(6);
    let (w, h) = (48, 32);
    let rec = sample_set(
        w,
        h,
        4,
        |_, _, _| Rgb::splat(rng.f32()),
        |x, y, _| (x as f32 - 24.0) * 0.7 + y as f32 * 0.1,
    );
    let colour = rec.radiance().to_vec();
    for layers in [3, 7] {
        let lookups: Vec<u64> = [1.0, 4.0, 8.0, 16.0]
            .iter()
            .map(|&tau| {
                sbmf(layers, tau)
                    .step_b(&rec, &colour, w as usize, h as usize)
                    .unwrap()
                    .1
                    .sat_lookups
            })
            .collect();
        assert!(lookups[0] > 0);
        assert!(
            lookups.iter().all(|&n| n == lookups[0]),
            "{layers} layers: {lookups:?}"
        );
        // Four lookups per box: every scale but 0, every layer, every pixel.
        assert_eq!(
            lookups[0],
            (w * h) as u64 * layers as u64 * (layers as u64 / 2) * 4
        );
    }
}

#[test]
fn defocus_spreads_a_bright_sample_by_its_coc_and_keeps_the_in_focus_one_sharp() {
    // A dark in-focus plane with one bright pixel: in focus it stays one pixel; in front of
    // the focal plane (CoC −6) it becomes a box of about the disc's area; behind it (CoC 6)
    // the in-focus plane in front hides its blur.
    let (w, h) = (41, 41);
    let bright = |x: u32, y: u32| (x, y) == (20, 20);
    for (coc, want_spread) in [(0.0f32, false), (-6.0, true), (6.0, false)] {
        let rec = sample_set(
            w,
            h,
            2,
            |x, y, _| {
                if bright(x, y) {
                    Rgb::splat(100.0)
                } else {
                    Rgb::ZERO
                }
            },
            |x, y, _| if bright(x, y) { coc } else { 0.0 },
        );
        let colour = rec.radiance().to_vec();
        let (img, _) = sbmf(7, 6.0)
            .step_b(&rec, &colour, w as usize, h as usize)
            .unwrap();
        let lit = img.pixels().iter().filter(|p| p.x > 1e-3).count();
        if want_spread {
            // Half-width round((√π·6 − 1)/2) = 5: an 11×11 box, 121 ≈ π·6² pixels.
            assert_eq!(lit, 121, "defocused");
        } else {
            assert_eq!(lit, 1, "in focus or hidden (CoC {coc})");
        }
    }
}

/// Two regions (normals and albedos differ) with smooth true radiance; samples are the truth
/// times heavy-tailed noise of mean 1.
fn noisy_two_region_set(w: u32, h: u32, spp: u32, seed: u64) -> (SampleRecords, Vec<Rgb>) {
    let mut rng = SplitMix64::from_state(seed);
    let truth = |x: u32, y: u32| {
        let left = x < w / 2;
        let shade = 0.9 + 0.2 * (y as f32 / h as f32);
        if left {
            Rgb::new(0.8, 0.6, 0.4) * shade
        } else {
            Rgb::new(0.1, 0.2, 0.3) * (2.0 - shade)
        }
    };
    let mut v = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let left = x < w / 2;
            for _ in 0..spp {
                // Exponential noise (mean 1, σ 1): like GI noise, skewed with a long tail.
                let n = -(1.0 - rng.f32()).max(1e-6).ln();
                v.push(Sample {
                    pixel: y * w + x,
                    radiance: truth(x, y) * n,
                    normal: if left { Vec3::Z } else { Vec3::X },
                    position: if left {
                        Vec3::new(x as f32 * 0.01, y as f32 * 0.01, 0.0)
                    } else {
                        Vec3::new(0.5, y as f32 * 0.01, x as f32 * 0.01)
                    },
                    albedo: if left {
                        Rgb::splat(0.8)
                    } else {
                        Rgb::splat(0.2)
                    },
                    coc: 0.0,
                });
            }
        }
    }
    let truth_img = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| truth(x, y))
        .collect();
    (records(w, h, &v), truth_img)
}

fn mse(a: &[Rgb], b: &[Rgb]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| ((*p - *q) * (*p - *q)).element_sum() as f64)
        .sum::<f64>()
        / (3 * a.len()) as f64
}

#[test]
fn sbmf_removes_most_of_the_noise_of_a_synthetic_sample_set_and_keeps_the_edge() {
    let (w, h) = (64, 48);
    let (rec, truth) = noisy_two_region_set(w, h, 4, 7);
    let noisy: Vec<Rgb> = (0..(w * h) as usize)
        .map(|i| {
            let r = rec.pixel_range(i);
            rec.radiance()[r.clone()].iter().copied().sum::<Rgb>() / r.len() as f32
        })
        .collect();
    let out = Sbmf::new(SbmfParams::default())
        .unwrap()
        .filter_samples(&rec, w as usize, h as usize)
        .unwrap();
    let (before, after) = (mse(&noisy, &truth), mse(out.pixels(), &truth));
    assert!(after < 0.02 * before, "MSE {before} -> {after}");
    // The edge between the regions survives: a plain blur of the same reach would mix them.
    let blurred = fallback::box_blurred_pixels(&rec, w as usize, h as usize, 8);
    assert!(
        after < 0.2 * mse(&blurred, &truth),
        "{after} vs box {}",
        mse(&blurred, &truth)
    );
    // One manifold cannot follow both regions: the samples near the edge fall back to the box.
    let one = Sbmf::new(SbmfParams {
        manifolds: 1,
        ..Default::default()
    })
    .unwrap();
    let (_, stats) = one.step_a(&rec, w as usize, h as usize).unwrap();
    let out1 = one.filter_samples(&rec, w as usize, h as usize).unwrap();
    assert!(stats.fallbacks > 0 && mse(out1.pixels(), &truth) > 4.0 * after);
}

#[test]
fn results_are_the_same_bits_on_one_and_two_threads() {
    let (rec, _) = noisy_two_region_set(37, 29, 3, 8);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let s = sbmf(7, 0.0);
            let colour = rec
                .radiance()
                .iter()
                .enumerate()
                .map(|(j, c)| *c * (1.0 + j as f32 * 1e-3))
                .collect::<Vec<_>>();
            let a = s.filter_samples(&rec, 37, 29).unwrap();
            // A non-trivial CoC for step B.
            let mut v: Vec<Sample> = (0..rec.len()).map(|j| rec.sample(j)).collect();
            for (j, s) in v.iter_mut().enumerate() {
                s.coc = (j % 11) as f32 - 5.0;
            }
            let rec2 = records(37, 29, &v);
            let b = s.step_b(&rec2, &colour, 37, 29).unwrap().0;
            (a, b)
        })
    };
    let bits = |i: &RgbImage| {
        i.pixels()
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(bits(&one.0), bits(&two.0));
    assert_eq!(bits(&one.1), bits(&two.1));
}

#[test]
fn parameters_are_validated_and_inputs_checked() {
    let bad = |p: SbmfParams| Sbmf::new(p).unwrap_err().to_string();
    let d = SbmfParams::default;
    assert!(bad(SbmfParams {
        manifolds: 4,
        ..d()
    })
    .contains("manifolds"));
    assert!(bad(SbmfParams {
        manifolds: 0,
        ..d()
    })
    .contains("manifolds"));
    assert!(bad(SbmfParams { layers: 5, ..d() }).contains("layers: must be 3 or 7"));
    assert!(bad(SbmfParams {
        sigma_spatial: 0.0,
        ..d()
    })
    .contains("sigma_spatial"));
    assert!(bad(SbmfParams {
        sigma_normal: f32::NAN,
        ..d()
    })
    .contains("sigma_normal"));
    assert!(bad(SbmfParams {
        max_coc: -1.0,
        ..d()
    })
    .contains("max_coc"));
    assert!(bad(SbmfParams {
        fallback_radius: 65,
        ..d()
    })
    .contains("fallback_radius"));
    for m in [1, 3, 7, 15] {
        assert!(Sbmf::new(SbmfParams {
            manifolds: m,
            ..d()
        })
        .is_ok());
    }
    let mut o = Options::of("sbmf", "manifolds=7:layers=3").unwrap();
    let s = Sbmf::from_options(&mut o).unwrap();
    o.finish().unwrap();
    assert_eq!((s.params().manifolds, s.params().layers), (7, 3));
    let rec = SampleRecords::empty(4, 3);
    let s = sbmf(7, 0.0);
    assert!(s.filter_samples(&rec, 3, 4).is_err(), "size mismatch");
    assert_eq!(
        s.filter_samples(&rec, 4, 3).unwrap().pixels(),
        &[Rgb::ZERO; 12]
    );
    assert!(s.step_b(&rec, &[Rgb::ONE], 4, 3).is_err(), "colour count");
}

#[test]
fn layers_classify_linearly_between_the_two_nearest() {
    let l = Layers { n_f: 3, tau: 6.0 };
    assert_eq!(l.classify(0.0), (3, 4, 0.0));
    let (a, b, t) = l.classify(-3.0);
    assert_eq!((a, b), (1, 2));
    assert!((t - 0.5).abs() < 1e-6);
    assert_eq!(l.classify(100.0), (6, 6, 0.0));
    assert_eq!(l.classify(-100.0), (0, 1, 0.0));
    assert_eq!((l.scale(0), l.scale(3), l.scale(6)), (3, 0, 3));
    assert_eq!(l.half_width(0), 0);
    // A huge τ (an outlier CoC sets it) clips every box to the image instead of overflowing.
    let (rec, _) = noisy_two_region_set(8, 6, 2, 9);
    let colour = rec.radiance().to_vec();
    let (img, _) = sbmf(7, 1e30).step_b(&rec, &colour, 8, 6).unwrap();
    assert!(img.pixels().iter().all(|p| p.is_finite()));
}
