//! Filter-cache placement (thesis §5.1.2): `m_poisson = m − round(κ·m)` blue-noise pixels
//! ([`blue_noise()`]) first, then `round(κ·m)` pixels drawn without replacement from
//! P_FN = P_F · P_N (Eq. 5.1, [`importance`]) among the pixels not yet taken.
//!
//! Deviations: the blue-noise set is generated per image and seed rather than precomputed;
//! the importance draw is without replacement; σ_r is relative to the mean bank radiance
//! (see [`importance`]).

pub mod blue_noise;
pub mod importance;

pub use blue_noise::blue_noise;
pub use importance::{log_density, sample_without_replacement};

use rt_core::rng::SplitMix64;
use rt_core::RgbImage;

/// What [`place`] needs besides the bank and the variance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacementParams {
    /// Total number of caches (at most the number of pixels).
    pub count: usize,
    /// κ, the share drawn by importance.
    pub kappa: f32,
    /// σ_r, relative to `mu`.
    pub sigma_r: f32,
    /// The radiance scale μ ([`crate::scale::mean_radiance`]).
    pub mu: f64,
    /// Seed.
    pub seed: u32,
}

/// The cache pixels: the blue-noise part first, then the importance part in draw order. All
/// distinct, in bounds, `min(count, pixels)` of them, deterministic per seed. `bank` must be
/// non-empty and every image the size of `variance_of_mean`.
pub fn place(
    bank: &[RgbImage],
    variance_of_mean: &RgbImage,
    params: &PlacementParams,
) -> Vec<(u32, u32)> {
    let (w, h) = (variance_of_mean.width(), variance_of_mean.height());
    let count = params.count.min(w * h);
    let m_importance = ((params.kappa.clamp(0.0, 1.0) as f64) * count as f64).round() as usize;
    let m_poisson = count - m_importance;
    let mut caches = blue_noise(w, h, m_poisson, params.seed);
    if m_importance == 0 {
        return caches;
    }
    let mut excluded = vec![false; w * h];
    for &(x, y) in &caches {
        excluded[y as usize * w + x as usize] = true;
    }
    let log_w = log_density(bank, variance_of_mean, params.sigma_r, params.mu);
    let mut rng = SplitMix64::new(0x1a90_0000_0000_0000 ^ params.seed as u64);
    let drawn = sample_without_replacement(&log_w, &excluded, m_importance, &mut rng);
    caches.extend(drawn.into_iter().map(|i| ((i % w) as u32, (i / w) as u32)));
    caches
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    fn params(count: usize, kappa: f32, seed: u32) -> PlacementParams {
        PlacementParams {
            count,
            kappa,
            sigma_r: 1.0,
            mu: 0.5,
            seed,
        }
    }

    /// Bank of two filters whose variance is 4× larger on the left half than on the right.
    fn bank(w: usize, h: usize) -> Vec<RgbImage> {
        let a = RgbImage::from_fn(w, h, |_, _| Rgb::ZERO);
        let b = RgbImage::from_fn(w, h, |x, _| Rgb::splat(if x < w / 2 { 1.0 } else { 0.5 }));
        vec![a, b]
    }

    #[test]
    fn count_distinct_in_bounds_deterministic() {
        let (w, h) = (64, 48);
        let bank = bank(w, h);
        let var = RgbImage::from_fn(w, h, |x, y| Rgb::splat(((x ^ y) % 7) as f32 * 0.01));
        for kappa in [0.0, 0.6, 1.0] {
            let p = place(&bank, &var, &params(300, kappa, 5));
            assert_eq!(p.len(), 300);
            let mut seen = vec![false; w * h];
            for &(x, y) in &p {
                assert!((x as usize) < w && (y as usize) < h);
                assert!(!std::mem::replace(
                    &mut seen[y as usize * w + x as usize],
                    true
                ));
            }
            assert_eq!(p, place(&bank, &var, &params(300, kappa, 5)));
            assert_ne!(p, place(&bank, &var, &params(300, kappa, 6)));
        }
        // All pixels, importance part included.
        assert_eq!(place(&bank, &var, &params(w * h + 5, 0.5, 1)).len(), w * h);
    }

    #[test]
    fn kappa_zero_is_the_blue_noise_set() {
        let (w, h) = (64, 48);
        let var = RgbImage::from_fn(w, h, |_, _| Rgb::ZERO);
        assert_eq!(
            place(&bank(w, h), &var, &params(150, 0.0, 9)),
            blue_noise(w, h, 150, 9)
        );
        // With κ > 0 the blue-noise part is a prefix of the same set, rounded: 150 − 90.
        let mixed = place(&bank(w, h), &var, &params(150, 0.6, 9));
        assert_eq!(&mixed[..60], &blue_noise(w, h, 60, 9)[..]);
    }

    /// Draws k = 400 of 256² pixels by importance alone. Left pixels weigh 4, right ones 1,
    /// so each draw lands left with probability between 4·(H−k)/(4·(H−k)+H) = 0.7980 and
    /// 4H/(4H+H−k) = 0.8020 (H = 32768 pixels per half; the bounds allow for depletion). The
    /// left count has mean within 320 ± 0.8 and standard deviation ≤ sqrt(400·0.8·0.2) ≈ 8.0;
    /// 5σ + 0.8 = 41. Uniform placement would give 200.
    #[test]
    fn importance_concentrates_where_p_f_is_large() {
        let (w, h) = (256, 256);
        let var = RgbImage::from_fn(w, h, |_, _| Rgb::ZERO);
        let p = place(&bank(w, h), &var, &params(400, 1.0, 3));
        let left = p.iter().filter(|&&(x, _)| (x as usize) < w / 2).count();
        assert!((left as f64 - 320.0).abs() <= 41.0, "left = {left}");
    }

    /// The same check for P_N: equal bank variance everywhere, noisier left half with
    /// P_N(left)/P_N(right) = 1/4, so about 80 of 400 land left (tolerance as above).
    #[test]
    fn importance_avoids_noisy_pixels() {
        let (w, h) = (256, 256);
        let a = RgbImage::from_fn(w, h, |_, _| Rgb::ZERO);
        let b = RgbImage::from_fn(w, h, |_, _| Rgb::splat(1.0));
        // μ = 0.5, σ_r = 1: P_N = exp(−v/μ²/2) = 1/4 for v = 2·ln 4·μ².
        let v_left = (2.0 * 4f64.ln() * 0.25) as f32;
        let var = RgbImage::from_fn(w, h, |x, _| {
            Rgb::splat(if x < w / 2 { v_left } else { 0.0 })
        });
        let p = place(&[a, b], &var, &params(400, 1.0, 4));
        let left = p.iter().filter(|&&(x, _)| (x as usize) < w / 2).count();
        assert!((left as f64 - 80.0).abs() <= 41.0, "left = {left}");
    }
}
