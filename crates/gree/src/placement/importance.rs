//! The importance half of cache placement: the density P_FN = P_F · P_N of thesis Eq. 5.1 and
//! weighted sampling without replacement from it.
//!
//! - P_F(p) is the bank variance, `(1/m) Σ_i (F_i(p) − F_μ(p))²`, averaged over the three
//!   channels (the thesis writes F_m for F_i, a typo; it does not say how channels are reduced).
//! - P_N(p) = exp(−v̂(p) / (2σ_r²)) with v̂(p) the variance of N's pixel mean averaged over
//!   channels and divided by μ², μ the mean bank radiance ([`crate::scale`]). So σ_r is a
//!   standard deviation relative to μ, not in absolute radiance (deviation). The Gaussian's constant factor cancels in the normalisation and is dropped.
//! - Everything is kept as `ln P_F + ln P_N`, so a strongly peaked P_N never underflows.
//!
//! Deviation: the thesis draws with a 2-D CDF and removes duplicates; here the draw is
//! without replacement by the Efraimidis–Spirakis keys (each pixel gets `u^(1/w)`, the
//! `count` largest win), which equals drawing one pixel at a time from the renormalised
//! density of the pixels not yet drawn. In log form the key is `ln(−ln u) − ln w`, smallest
//! wins. Pixels of zero density are taken only when the positive ones run out, uniformly.

use rayon::prelude::*;
use rt_core::rng::SplitMix64;
use rt_core::RgbImage;

/// `ln(P_F(p) · P_N(p))` per pixel (unnormalised; `−∞` where the bank agrees exactly).
/// `bank` and `variance_of_mean` must have the same size; `mu` is the radiance scale.
/// Pixel-parallel; each value is computed alone, so the bits do not depend on threads.
pub fn log_density(
    bank: &[RgbImage],
    variance_of_mean: &RgbImage,
    sigma_r: f32,
    mu: f64,
) -> Vec<f64> {
    let m = bank.len() as f64;
    let inv_two_sr2 = 1.0 / (2.0 * sigma_r as f64 * sigma_r as f64);
    let inv_mu2 = 1.0 / (mu * mu);
    (0..variance_of_mean.pixels().len())
        .into_par_iter()
        .map(|p| {
            let mut mean = [0.0f64; 3];
            for f in bank {
                let v = f.pixels()[p];
                for (c, s) in mean.iter_mut().enumerate() {
                    *s += v[c] as f64;
                }
            }
            mean.iter_mut().for_each(|s| *s /= m);
            let mut var = 0.0f64;
            for f in bank {
                let v = f.pixels()[p];
                for (c, s) in mean.iter().enumerate() {
                    let d = v[c] as f64 - s;
                    var += d * d;
                }
            }
            let p_f = var / (3.0 * m);
            let n = variance_of_mean.pixels()[p];
            let v_hat = (n.x as f64 + n.y as f64 + n.z as f64) / 3.0 * inv_mu2;
            p_f.ln() - v_hat * inv_two_sr2
        })
        .collect()
}

/// A uniform in the open interval (0, 1).
fn open_uniform(rng: &mut SplitMix64) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
}

/// `count` distinct indices drawn without replacement with probability ∝ `exp(log_w)`,
/// skipping `excluded` ones (fewer only if fewer are left), in the order drawn.
pub fn sample_without_replacement(
    log_w: &[f64],
    excluded: &[bool],
    count: usize,
    rng: &mut SplitMix64,
) -> Vec<usize> {
    // (class, key, index): class 0 = positive density, 1 = zero density (uniform fill).
    let mut keys: Vec<(u8, f64, usize)> = Vec::with_capacity(log_w.len());
    for (i, &lw) in log_w.iter().enumerate() {
        let u = open_uniform(rng);
        if excluded[i] {
            continue;
        }
        if lw.is_finite() {
            keys.push((0, (-u.ln()).ln() - lw, i));
        } else if lw == f64::INFINITY {
            keys.push((0, f64::NEG_INFINITY, i));
        } else {
            keys.push((1, u, i));
        }
    }
    let count = count.min(keys.len());
    let cmp = |a: &(u8, f64, usize), b: &(u8, f64, usize)| {
        a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2))
    };
    if count == 0 {
        return Vec::new();
    }
    if count < keys.len() {
        keys.select_nth_unstable_by(count - 1, cmp);
    }
    keys.truncate(count);
    keys.sort_unstable_by(cmp);
    keys.into_iter().map(|k| k.2).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    #[test]
    fn density_prefers_disagreement_and_low_noise() {
        let a = RgbImage::from_fn(3, 1, |_, _| Rgb::splat(1.0));
        let b = RgbImage::from_fn(3, 1, |x, _| Rgb::splat(if x == 0 { 1.0 } else { 2.0 }));
        let var = RgbImage::from_fn(3, 1, |x, _| Rgb::splat(if x == 2 { 0.5 } else { 0.0 }));
        let lw = log_density(&[a, b], &var, 0.5, 1.0);
        assert_eq!(lw[0], f64::NEG_INFINITY); // filters agree
        assert!((lw[1] - 0.25f64.ln()).abs() < 1e-12);
        assert!((lw[2] - (0.25f64.ln() - 0.5 / 0.5)).abs() < 1e-12);
    }

    /// Scaling all radiance by k scales variances by k², and with σ_r relative to μ the
    /// density changes only by a constant factor (k²): the draw is the same.
    #[test]
    fn density_is_scale_free() {
        let a = RgbImage::from_fn(8, 8, |x, y| Rgb::splat((x * y) as f32 * 0.1));
        let b = RgbImage::from_fn(8, 8, |x, _| Rgb::splat(x as f32 * 0.2));
        let v = RgbImage::from_fn(8, 8, |_, y| Rgb::splat(y as f32 * 0.01));
        let s = |img: &RgbImage| RgbImage::from_fn(8, 8, |x, y| img.pixel(x, y) * 8.0);
        let vs = RgbImage::from_fn(8, 8, |x, y| v.pixel(x, y) * 64.0);
        let mu = crate::scale::mean_radiance(&[a.clone(), b.clone()]);
        let mu_s = crate::scale::mean_radiance(&[s(&a), s(&b)]);
        let l1 = log_density(&[a.clone(), b.clone()], &v, 0.15, mu);
        let l2 = log_density(&[s(&a), s(&b)], &vs, 0.15, mu_s);
        for (x, y) in l1.iter().zip(&l2) {
            if x.is_finite() {
                assert!((y - x - 64f64.ln()).abs() < 1e-9, "{x} {y}");
            }
        }
    }

    #[test]
    fn without_replacement_and_fill() {
        let lw = vec![0.0, f64::NEG_INFINITY, 1.0, f64::NEG_INFINITY, 2.0];
        let excluded = vec![false, false, false, false, true];
        let mut rng = SplitMix64::new(1);
        let got = sample_without_replacement(&lw, &excluded, 10, &mut rng);
        assert_eq!(got.len(), 4);
        let mut sorted = got.clone();
        sorted.sort();
        assert_eq!(sorted, vec![0, 1, 2, 3]);
        // Positive densities come first.
        let mut first: Vec<_> = got[..2].to_vec();
        first.sort();
        assert_eq!(first, vec![0, 2]);
    }
}
