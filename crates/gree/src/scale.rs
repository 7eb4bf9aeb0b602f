//! The one radiance scale that makes `sigma_r` and `lambda` dimensionless (not in the
//! thesis, whose σ_r and λ are absolute): the mean over the bank's filters, pixels and channels.

use rt_core::RgbImage;

/// Below this the mean bank radiance is taken as 1 (a black image has no scale to remove).
pub const MIN_SCALE: f64 = 1e-12;

/// Mean over all filters, pixels and channels of the bank, or 1 when that is not positive
/// (a black image). Summed in `f64`, in order.
pub fn mean_radiance(bank: &[RgbImage]) -> f64 {
    let mut sum = 0.0f64;
    let mut count = 0usize;
    for img in bank {
        for p in img.pixels() {
            sum += p.x as f64 + p.y as f64 + p.z as f64;
        }
        count += 3 * img.pixels().len();
    }
    let mean = if count == 0 { 0.0 } else { sum / count as f64 };
    if mean.is_finite() && mean > MIN_SCALE {
        mean
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    #[test]
    fn mean_of_the_bank() {
        let a = RgbImage::from_fn(2, 2, |_, _| Rgb::new(1.0, 2.0, 3.0));
        let b = RgbImage::from_fn(2, 2, |_, _| Rgb::splat(0.0));
        assert_eq!(mean_radiance(&[a, b.clone()]), 1.0);
        assert_eq!(mean_radiance(&[b]), 1.0);
        let c = RgbImage::from_fn(2, 2, |_, _| Rgb::splat(4.0));
        assert_eq!(mean_radiance(&[c]), 4.0);
    }
}
