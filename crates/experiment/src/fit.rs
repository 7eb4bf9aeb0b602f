//! Convergence rates and equal-time comparisons from the measured (budget, error) points.

/// A least-squares line through points, with the slope's standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Slope.
    pub slope: f64,
    /// Standard error of the slope from the residuals (`sqrt(RSS / (n − 2) / Sxx)`); NaN with
    /// fewer than three points, where the residuals say nothing.
    pub se: f64,
    /// Number of points used.
    pub points: usize,
}

/// Ordinary least squares of `ln y` on `ln x` over the points with `x > 0` and `y > 0`: the
/// slope of a log-log plot. `None` with fewer than two usable points or all `x` equal.
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<Fit> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = xy.len();
    if n < 2 {
        return None;
    }
    let mx = xy.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let my = xy.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let se = if n > 2 {
        let rss: f64 = xy
            .iter()
            .map(|p| (p.1 - my - slope * (p.0 - mx)).powi(2))
            .sum();
        (rss / (n - 2) as f64 / sxx).sqrt()
    } else {
        f64::NAN
    };
    Some(Fit {
        slope,
        se,
        points: n,
    })
}

/// The value of a curve given by points (sorted by `x`, positive) at `x`, interpolating
/// linearly between neighbours in log-log space (where error curves are close to straight).
/// `None` outside the curve's range.
pub fn log_log_interpolate(curve: &[(f64, f64)], x: f64) -> Option<f64> {
    let (first, last) = (curve.first()?, curve.last()?);
    if x < first.0 || x > last.0 {
        return None;
    }
    let i = curve.partition_point(|p| p.0 < x);
    if i < curve.len() && curve[i].0 == x {
        return Some(curve[i].1);
    }
    let (a, b) = (curve[i - 1], curve[i]);
    let t = (x.ln() - a.0.ln()) / (b.0.ln() - a.0.ln());
    Some((a.1.ln() + t * (b.1.ln() - a.1.ln())).exp())
}

/// At which times to compare methods: within the range every curve covers, the time budgets
/// that methods asked for if at least two fall in it, else `count` times spread evenly on a
/// log scale. Empty when the ranges do not overlap.
pub fn comparison_times(curves: &[&[(f64, f64)]], budgets: &[f64], count: usize) -> Vec<f64> {
    let lo = curves
        .iter()
        .filter_map(|c| c.first().map(|p| p.0))
        .fold(f64::NEG_INFINITY, f64::max);
    let hi = curves
        .iter()
        .filter_map(|c| c.last().map(|p| p.0))
        .fold(f64::INFINITY, f64::min);
    if curves.is_empty() || !(lo > 0.0 && lo <= hi) {
        return Vec::new();
    }
    let mut inside: Vec<f64> = budgets
        .iter()
        .copied()
        .filter(|&t| t >= lo && t <= hi)
        .collect();
    inside.sort_by(f64::total_cmp);
    inside.dedup();
    if inside.len() >= 2 {
        return inside;
    }
    if lo == hi || count < 2 {
        return vec![lo];
    }
    // Clamped: exp(ln x) need not give x back, and the ends must stay inside every curve.
    (0..count)
        .map(|i| {
            (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (count - 1) as f64)
                .exp()
                .clamp(lo, hi)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_a_power_law_is_its_exponent() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0, 16.0]
            .iter()
            .map(|&x| (x, 3.0 / x))
            .collect();
        let f = log_log_slope(&pts).unwrap();
        assert!((f.slope + 1.0).abs() < 1e-12, "{f:?}");
        assert!(f.se < 1e-12);
        assert_eq!(f.points, 5);
        // Noise shows in the standard error; non-positive points are left out.
        let noisy = [(1.0, 1.0), (2.0, 0.6), (4.0, 0.2), (8.0, 0.13), (16.0, 0.0)];
        let f = log_log_slope(&noisy).unwrap();
        assert_eq!(f.points, 4);
        assert!(f.se > 0.01 && f.slope < -0.8, "{f:?}");
        assert!(log_log_slope(&[(1.0, 1.0)]).is_none());
        assert!(log_log_slope(&[(2.0, 1.0), (2.0, 3.0)]).is_none());
        assert!(log_log_slope(&[(1.0, 1.0), (2.0, 0.5)])
            .unwrap()
            .se
            .is_nan());
    }

    #[test]
    fn interpolation_is_straight_in_log_log() {
        let c = [(1.0, 1.0), (4.0, 0.25)];
        assert!((log_log_interpolate(&c, 2.0).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(log_log_interpolate(&c, 4.0), Some(0.25));
        assert_eq!(log_log_interpolate(&c, 1.0), Some(1.0));
        assert_eq!(log_log_interpolate(&c, 0.5), None);
        assert_eq!(log_log_interpolate(&c, 5.0), None);
    }

    #[test]
    fn comparison_times_lie_where_every_curve_is() {
        let a = [(0.1, 1.0), (1.0, 0.1)];
        let b = [(0.2, 1.0), (2.0, 0.1)];
        let t = comparison_times(&[&a, &b], &[], 3);
        assert_eq!(t.len(), 3);
        assert!((t[0] - 0.2).abs() < 1e-12 && (t[2] - 1.0).abs() < 1e-12);
        assert!((t[1] - 0.2f64.sqrt()).abs() < 1e-12);
        for &x in &t {
            assert!(log_log_interpolate(&a, x).is_some() && log_log_interpolate(&b, x).is_some());
        }
        assert_eq!(
            comparison_times(&[&a, &b], &[0.25, 0.5, 4.0], 3),
            vec![0.25, 0.5]
        );
        let far = [(5.0, 1.0), (6.0, 0.5)];
        assert!(comparison_times(&[&a, &far], &[], 3).is_empty());
    }
}
