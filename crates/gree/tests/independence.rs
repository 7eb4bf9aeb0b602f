//! Cache samples must be independent of N (not stated in the thesis). With a bank holding the
//! identity (N itself) and a good filter, a renderer that hands back N's own values makes the
//! identity's measured error zero at every cache, so GREE picks the identity almost
//! everywhere; with honest, independent caches it almost never does.

mod common;

use common::{mse, truth, with_noise, Independent, ReusesN};
use rt_gree::{composite, GreeParams, Rgb, RgbImage};

#[test]
fn reusing_n_biases_selection_toward_the_identity() {
    let (w, h) = (96, 96);
    let truth = truth(w, h);
    let sigma = 0.2;
    let noisy = with_noise(&truth, sigma, 1, |_, _| true);
    let variance = RgbImage::from_fn(w, h, |_, _| Rgb::splat(sigma * sigma / 28.0));
    // A good "denoiser": a quarter of N's noise.
    let good = with_noise(&truth, sigma / 4.0, 2, |_, _| true);
    let bank = vec![noisy.clone(), good];
    let params = GreeParams::default();
    let identity_share =
        |labels: &[u16]| labels.iter().filter(|&&l| l == 0).count() as f64 / labels.len() as f64;

    let honest = composite(
        &noisy,
        &variance,
        &bank,
        &mut Independent::new(&truth, 1.0, 5),
        &params,
    )
    .unwrap();
    let reused = composite(&noisy, &variance, &bank, &mut ReusesN(&noisy), &params).unwrap();
    let (s_honest, s_reused) = (
        identity_share(&honest.labels),
        identity_share(&reused.labels),
    );
    eprintln!("identity share: independent {s_honest:.3}, reusing N {s_reused:.3}");
    assert!(s_honest < 0.1, "{s_honest}");
    assert!(s_reused > 0.9, "{s_reused}");
    // And it costs quality.
    assert!(mse(&reused.image, &truth) > 4.0 * mse(&honest.image, &truth));
}
