//! Sparse errors at the caches (thesis §5.1.1, §5.1.3): for each filter F_i and cache p with
//! value C(p), `e_i(p) = ‖F_i(p) − C(p)‖²` summed over RGB ([`ErrorMetric::Squared`], the
//! thesis), or `Σ_c (F_i(p) − C(p))_c² / (C(p)_c² + 0.01)` ([`ErrorMetric::Relative`], ours).
//!
//! With C independent of N, `E e_i(p) = true error² + Var(C)`; the second term is the same for
//! every filter, so the per-pixel choice is unbiased in expectation (not in the thesis).

use crate::params::{ErrorMetric, RELATIVE_EPSILON};
use rayon::prelude::*;
use rt_core::{Rgb, RgbImage};

/// The error of filter value `f` against cache value `c`.
#[inline]
pub fn cache_error(f: Rgb, c: Rgb, metric: ErrorMetric) -> f32 {
    let d = f - c;
    match metric {
        ErrorMetric::Squared => d.length_squared(),
        ErrorMetric::Relative => {
            let e = d * d / (c * c + Rgb::splat(RELATIVE_EPSILON));
            e.x + e.y + e.z
        }
    }
}

/// Per filter, the errors at the caches in cache order: `result[i][k]` is filter `i` at
/// cache `caches[k]` with value `values[k]`.
pub fn sparse_errors(
    bank: &[RgbImage],
    caches: &[(u32, u32)],
    values: &[Rgb],
    metric: ErrorMetric,
) -> Vec<Vec<f32>> {
    bank.par_iter()
        .map(|f| {
            caches
                .iter()
                .zip(values)
                .map(|(&(x, y), &c)| cache_error(f.pixel(x as usize, y as usize), c, metric))
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics() {
        let f = Rgb::new(1.0, 2.0, 3.0);
        let c = Rgb::new(1.0, 1.0, 1.0);
        assert_eq!(cache_error(f, c, ErrorMetric::Squared), 5.0);
        let r = cache_error(f, c, ErrorMetric::Relative);
        assert!((r - 5.0 / 1.01).abs() < 1e-6);
        let bank = vec![RgbImage::from_fn(2, 1, |x, _| Rgb::splat(x as f32))];
        let e = sparse_errors(
            &bank,
            &[(1, 0), (0, 0)],
            &[Rgb::ZERO, Rgb::ONE],
            ErrorMetric::Squared,
        );
        assert_eq!(e, vec![vec![3.0, 3.0]]);
    }
}
