//! Pearson's χ² goodness-of-fit test of a direction sampler against its pdf (pbrt's and
//! Mitsuba's test): sampled directions are binned in (θ, φ) over the sphere, the expected count
//! of each bin is the pdf integrated over it, bins expecting fewer than 5 samples are pooled,
//! and the p-value is the χ² survival function. A family of tests is judged at a Šidák-corrected
//! per-test level ([`sidak`]) so that the family-wise false-alarm rate is what it claims.

use rt_core::glam::Vec3;
use std::f64::consts::PI;

/// Bins in θ (polar angle from +z) and in φ.
pub const THETA_BINS: usize = 40;
/// Bins in φ.
pub const PHI_BINS: usize = 80;

/// The bin of unit direction `d`.
pub fn bin_of(d: Vec3) -> usize {
    let theta = (d.z.clamp(-1.0, 1.0) as f64).acos();
    let phi = (d.y as f64).atan2(d.x as f64).rem_euclid(2.0 * PI);
    let t = ((theta / PI * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    t * PHI_BINS + p
}

/// Expected fraction of samples per bin: the solid-angle `pdf` integrated over each bin
/// (midpoint rule on a `sub × sub` sub-grid per bin, with the sin θ Jacobian).
pub fn expected(pdf: impl Fn(Vec3) -> f64, sub: usize) -> Vec<f64> {
    let mut out = vec![0.0; THETA_BINS * PHI_BINS];
    let dtheta = PI / (THETA_BINS * sub) as f64;
    let dphi = 2.0 * PI / (PHI_BINS * sub) as f64;
    for t in 0..THETA_BINS * sub {
        let theta = (t as f64 + 0.5) * dtheta;
        for p in 0..PHI_BINS * sub {
            let phi = (p as f64 + 0.5) * dphi;
            let d = Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
            );
            out[(t / sub) * PHI_BINS + p / sub] += pdf(d) * theta.sin() * dtheta * dphi;
        }
    }
    out
}

/// The result of [`test()`].
#[derive(Clone, Copy, Debug)]
pub struct ChiSquare {
    /// The statistic.
    pub chi2: f64,
    /// Degrees of freedom (cells − 1).
    pub dof: usize,
    /// `P(χ²_dof ≥ chi2)`.
    pub p_value: f64,
    /// Samples observed in the pooled cells that expect fewer than 5 in total (where, if the
    /// pool itself is too small to be a cell, the pdf says almost nothing may fall).
    pub stray: f64,
    /// Samples expected there.
    pub stray_expected: f64,
}

/// Pearson's test of `observed` counts against `expected` fractions of `n` samples. Cells
/// expecting fewer than 5 are pooled into one cell (if that pool expects 5 or more).
pub fn test(observed: &[f64], expected: &[f64], n: usize) -> ChiSquare {
    let (mut chi2, mut cells, mut pool_e, mut pool_o) = (0.0, 0usize, 0.0, 0.0);
    for (e, o) in expected.iter().map(|e| e * n as f64).zip(observed) {
        if e < 5.0 {
            pool_e += e;
            pool_o += o;
            continue;
        }
        chi2 += (o - e) * (o - e) / e;
        cells += 1;
    }
    let (mut stray, mut stray_expected) = (0.0, 0.0);
    if pool_e >= 5.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells += 1;
    } else {
        (stray, stray_expected) = (pool_o, pool_e);
    }
    let dof = cells.saturating_sub(1).max(1);
    ChiSquare {
        chi2,
        dof,
        p_value: 1.0 - gamma_p(dof as f64 / 2.0, chi2 / 2.0),
        stray,
        stray_expected,
    }
}

impl ChiSquare {
    /// True if the sampler passes at per-test level `alpha`: the p-value is at least `alpha`
    /// and no more samples fall where the pdf puts almost none than a Poisson count could
    /// (mean `stray_expected`; the bound is its mean plus 10 standard deviations plus 20).
    pub fn passes(&self, alpha: f64) -> bool {
        let stray_bound = 20.0 + self.stray_expected + 10.0 * self.stray_expected.sqrt();
        self.p_value >= alpha && self.stray <= stray_bound
    }
}

/// The per-test level that gives a family of `tests` independent tests the family-wise
/// false-alarm rate `family_alpha` (Šidák): `1 − (1 − family_alpha)^(1/tests)`.
pub fn sidak(family_alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - family_alpha).powf(1.0 / tests.max(1) as f64)
}

/// Regularised lower incomplete gamma P(a, x) by series / continued fraction (Numerical
/// Recipes), for the χ² survival function.
pub fn gamma_p(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        let c = [
            76.18009172947146,
            -86.50532032941677,
            24.01409824083091,
            -1.231739572450155,
            0.1208650973866179e-2,
            -0.5395239384953e-5,
        ];
        let mut y = x;
        let t = x + 5.5 - (x + 0.5) * (x + 5.5).ln();
        let mut s = 1.000000000190015;
        for ci in c {
            y += 1.0;
            s += ci / y;
        }
        -t + (2.5066282746310005 * s / x).ln()
    }
    if x <= 0.0 {
        return 0.0;
    }
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        sum * (-x + a * x.ln() - ln_gamma(a)).exp()
    } else {
        let (mut b, mut c, mut d) = (x + 1.0 - a, 1.0 / 1e-300, 1.0 / (x + 1.0 - a));
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < 1e-300 {
                d = 1e-300;
            }
            c = b + an / c;
            if c.abs() < 1e-300 {
                c = 1e-300;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        1.0 - (-x + a * x.ln() - ln_gamma(a)).exp() * h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn survival_function_matches_tables() {
        // χ²(10) upper 1 % point is 23.209; χ²(1) upper 5 % point is 3.841.
        assert!(((1.0 - gamma_p(5.0, 23.209 / 2.0)) - 0.01).abs() < 1e-4);
        assert!(((1.0 - gamma_p(0.5, 3.841 / 2.0)) - 0.05).abs() < 1e-4);
        assert!((sidak(0.01, 1) - 0.01).abs() < 1e-12);
        assert!((1.0 - (1.0 - sidak(0.01, 21)).powi(21) - 0.01).abs() < 1e-12);
    }
}
