//! Image statistics of films rendered with a variance buffer ([`crate::render`] keeps it).
//! The comparison of two renders within noise is `rt_validate::stress::compare` (a block
//! z-test whose tolerance follows from the per-pixel variances and a false-alarm rate),
//! re-exported here.

pub use rt_validate::stress::compare::{compare, normal_quantile_upper, Comparison, ALPHA};

use rt_core::Rgb;
use rt_film::{Film, PixelStats};

/// The variance of a pixel's mean; panics if the film keeps no variance buffer.
pub fn variance_of_mean(p: &PixelStats) -> Rgb {
    p.variance_of_mean()
        .expect("the film keeps the variance buffer")
}

/// Mean over all pixels and channels and its standard error (from the per-pixel variances of
/// the mean; pixels are independent).
pub fn image_mean(film: &Film) -> (f64, f64) {
    let n = film.pixels().len() as f64 * 3.0;
    let mut sum = 0.0;
    let mut var = 0.0;
    for p in film.pixels() {
        let (m, v) = (p.mean(), variance_of_mean(&p));
        sum += (m.x + m.y + m.z) as f64;
        var += (v.x + v.y + v.z) as f64;
    }
    (sum / n, var.sqrt() / n)
}
