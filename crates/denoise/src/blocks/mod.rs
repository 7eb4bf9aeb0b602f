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

/// The `[lo, hi]` range of a window of half size `r` centred on `c` in `0..n`, clamped to it.
#[inline]
pub fn window(c: usize, r: usize, n: usize) -> (usize, usize) {
    (c.saturating_sub(r), (c + r).min(n - 1))
}
