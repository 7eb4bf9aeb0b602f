//! Building blocks shared by the filter-bank denoisers: the separable Gaussian with border
//! renormalisation ([`separable`]), the summed-area-table box mean ([`sat`]), per-offset patch
//! distances for non-local means ([`patch`]) and parameter checks.
//!
//! Every block keeps the denoisers' contract: no allocation inside per-pixel loops, rayon only
//! over independent rows writing disjoint outputs, and an arithmetic order that does not
//! depend on the number of threads, so results are the same bits on any pool.

pub mod patch;
pub mod sat;
pub mod separable;

use crate::DenoiseError;

/// Rows per parallel work item for filters whose rows are independent: a fixed size (not one
/// derived from the thread count), so any per-strip arithmetic is the same on every pool.
pub const STRIP_ROWS: usize = 16;

/// Checks that `value` is finite and in `[lo, hi]`; `what` is the parameter's name.
pub fn check_range(
    denoiser: &'static str,
    what: &'static str,
    value: f32,
    lo: f32,
    hi: f32,
) -> Result<f32, DenoiseError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(DenoiseError::Param {
            denoiser,
            name: what,
            message: format!("must be a number in [{lo}, {hi}], got {value}"),
        })
    }
}

/// Checks that `value` is finite, positive and at most `hi`.
pub fn check_positive(
    denoiser: &'static str,
    what: &'static str,
    value: f32,
    hi: f32,
) -> Result<f32, DenoiseError> {
    if value.is_finite() && value > 0.0 && value <= hi {
        Ok(value)
    } else {
        Err(DenoiseError::Param {
            denoiser,
            name: what,
            message: format!("must be a number in (0, {hi}], got {value}"),
        })
    }
}

/// Checks that an integer is in `[lo, hi]`.
pub fn check_count(
    denoiser: &'static str,
    what: &'static str,
    value: usize,
    lo: usize,
    hi: usize,
) -> Result<usize, DenoiseError> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(DenoiseError::Param {
            denoiser,
            name: what,
            message: format!("must be in [{lo}, {hi}], got {value}"),
        })
    }
}

/// `e^x` for `x ≤ 0`, to about 3e-7 relative (0 below `-87`, and for NaN): a weight function
/// for filters that evaluate one per neighbour, where the library `exp` dominated the cost.
/// Pure arithmetic, so the same bits on every machine.
#[inline]
pub fn exp_neg(x: f32) -> f32 {
    // NaN goes to -87 (the comparison is false), positive input to 0.
    let x = if x > -87.0 { x.min(0.0) } else { -87.0 };
    // n = round(x / ln2) by the 1.5·2^23 trick (no SSE4.1 `round` needed): n ∈ [-126, 0].
    let n = (x * std::f32::consts::LOG2_E + 12_582_912.0) - 12_582_912.0;
    // f = x − n·ln2 with ln2 split in two (Cody & Waite: 0.6933594 is 355/512 as an f32, exact
    // times any n here) so f keeps its digits: |f| ≤ ln2/2.
    let f = (x - n * 0.693_359_4) + n * 2.121_944_4e-4;
    // e^f by its Taylor series to degree 6 (error < (ln2/2)^7 / 7! ≈ 1.2e-7).
    let p = 1.0
        + f * (1.0
            + f * (1.0 / 2.0
                + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0 + f * (1.0 / 720.0))))));
    f32::from_bits(((n as i32 + 127) as u32) << 23) * p
}

/// The `[lo, hi]` range of a window of half size `r` centred on `c` in `0..n`, clamped to it.
#[inline]
pub fn window(c: usize, r: usize, n: usize) -> (usize, usize) {
    (c.saturating_sub(r), (c + r).min(n - 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_neg_matches_exp() {
        for i in 0..=100_000 {
            let x = -87.0 * i as f32 / 100_000.0;
            let (a, e) = (exp_neg(x), x.exp());
            assert!((a - e).abs() <= 4e-7 * e, "{x}: {a} vs {e}");
        }
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(-200.0), exp_neg(-87.0));
        assert!(exp_neg(-87.0) > 0.0 && exp_neg(-87.0) < 1e-37);
        assert_eq!(exp_neg(f32::NAN), exp_neg(-87.0));
        assert_eq!(exp_neg(5.0), 1.0);
    }
}
