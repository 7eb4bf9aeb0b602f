//! Deterministic parallel sums.

use rayon::prelude::*;

/// Sums `part(i)` over `0..parts` (rows, bands of rows): each part on one worker, then the
/// per-part results in index order. The result is therefore the same bits for any thread
/// count, which a floating-point `par_iter().sum()` (whose grouping depends on work stealing)
/// would not guarantee.
pub(crate) fn ordered_sum<const N: usize>(
    parts: usize,
    part: impl Fn(usize) -> [f64; N] + Sync + Send,
) -> [f64; N] {
    let per_part: Vec<[f64; N]> = (0..parts).into_par_iter().map(part).collect();
    let mut total = [0.0; N];
    for r in &per_part {
        for (t, v) in total.iter_mut().zip(r) {
            *t += v;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_in_row_order() {
        // Summed left to right, 1 + 1e16 - 1e16 is 0 in f64; any other grouping could give 1.
        let rows = [1.0, 1e16, -1e16];
        let [s] = ordered_sum(3, |y| [rows[y]]);
        assert_eq!(s, (1.0 + 1e16) - 1e16);
        assert_eq!(ordered_sum(0, |_| [1.0, 2.0]), [0.0, 0.0]);
    }
}
