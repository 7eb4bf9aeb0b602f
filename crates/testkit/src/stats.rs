//! Image statistics of films rendered with a variance buffer ([`crate::render`] keeps it).
//! The comparison of two renders within noise is `rt_validate::stress::compare` (a block
//! z-test whose tolerance follows from the per-pixel variances and a false-alarm rate),
//! re-exported here.

pub use rt_validate::stress::compare::{
    compare, compare_estimates, image_mean, normal_equivalent, normal_quantile_upper,
    student_t_upper, Comparison, Estimate, ALPHA,
};
pub use rt_validate::stress::invalid_values;

use rt_core::Rgb;
use rt_film::PixelStats;

/// The variance of a pixel's mean; panics if the film keeps no variance buffer.
pub fn variance_of_mean(p: &PixelStats) -> Rgb {
    p.variance_of_mean()
        .expect("the film keeps the variance buffer")
}
