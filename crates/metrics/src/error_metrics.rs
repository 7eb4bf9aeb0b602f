//! Per-pixel error metrics: MSE, relMSE, RMSE and PSNR.
//!
//! All are means over every pixel *and* each of the three channels (so over `3·W·H` terms),
//! accumulated in `f64` whatever the `f32` pixels hold. `a` is the test image, `b` the reference.

use crate::error::{positive, Result};
use crate::image::{validate_pair, RgbImage};
use crate::reduce::ordered_sum;
use rt_core::Rgb;

/// The relMSE epsilon used unless another is given.
pub const DEFAULT_EPSILON: f64 = 0.01;

/// The PSNR peak value used unless another is given.
pub const DEFAULT_PEAK: f64 = 1.0;

/// Squared error and relative squared error of one pixel, each summed over its three channels.
#[inline]
pub(crate) fn pixel_errors(a: Rgb, b: Rgb, epsilon: f64) -> (f64, f64) {
    let (mut sq, mut rel) = (0.0, 0.0);
    for c in 0..3 {
        let (a, b) = (f64::from(a[c]), f64::from(b[c]));
        let d2 = (a - b) * (a - b);
        sq += d2;
        rel += d2 / (b * b + epsilon);
    }
    (sq, rel)
}

/// `(MSE, relMSE)` of an already validated pair, in one pass over the pixels.
pub(crate) fn mse_and_relmse(test: &RgbImage, reference: &RgbImage, epsilon: f64) -> (f64, f64) {
    let [sq, rel] = ordered_sum(test.height(), |y| {
        let (mut sq, mut rel) = (0.0, 0.0);
        for (&a, &b) in test.row(y).iter().zip(reference.row(y)) {
            let (s, r) = pixel_errors(a, b, epsilon);
            sq += s;
            rel += r;
        }
        [sq, rel]
    });
    let n = (3 * test.pixels().len()) as f64;
    (sq / n, rel / n)
}

/// Mean squared error: the mean over pixels and the three channels of `(a − b)²`.
pub fn mse(test: &RgbImage, reference: &RgbImage) -> Result<f64> {
    validate_pair(test, reference)?;
    Ok(mse_and_relmse(test, reference, DEFAULT_EPSILON).0)
}

/// Relative mean squared error: the mean over pixels and the three channels of
/// `(a − b)² / (b² + epsilon)`, where `b` is the reference.
///
/// This is the relative MSE of Rousselle, Knaus and Zwicker, "Adaptive sampling and
/// reconstruction using greedy error minimization" (2011), as used across the adaptive-sampling
/// and denoising literature, applied to each channel. `epsilon` (usually [`DEFAULT_EPSILON`] =
/// 0.01) keeps black reference pixels from dividing by zero, so it must be positive. Papers
/// differ in epsilon, so always report it with the value.
pub fn relmse(test: &RgbImage, reference: &RgbImage, epsilon: f64) -> Result<f64> {
    let epsilon = positive("epsilon", epsilon)?;
    validate_pair(test, reference)?;
    Ok(mse_and_relmse(test, reference, epsilon).1)
}

/// Peak signal-to-noise ratio in decibels, `10·log10(peak² / mse)`; `+inf` when `mse` is 0.
///
/// Rendered images are linear HDR and have no natural peak; `peak` = 1 ([`DEFAULT_PEAK`]) is a
/// convention (the white of a [0, 1] display image), so PSNRs are comparable only at equal peaks.
pub fn psnr(mse: f64, peak: f64) -> f64 {
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (peak * peak / mse).log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MetricsError;

    fn img(w: usize, h: usize, v: &[[f32; 3]]) -> RgbImage {
        RgbImage::new(w, h, v.iter().map(|&c| Rgb::from_array(c)).collect()).unwrap()
    }

    #[test]
    fn hand_computed_two_pixel_images() {
        let a = img(2, 1, &[[0.5, 0.0, 1.0], [2.0, 1.0, 0.0]]);
        let b = img(2, 1, &[[0.0, 0.0, 1.0], [1.0, 1.0, 0.5]]);
        // Squared errors 0.25, 0, 0, 1, 0, 0.25 over six terms.
        assert!((mse(&a, &b).unwrap() - 1.5 / 6.0).abs() < 1e-15);
        // Relative: 0.25/0.01, 0, 0, 1/1.01, 0, 0.25/0.26.
        let rel = (25.0 + 1.0 / 1.01 + 0.25 / 0.26) / 6.0;
        assert!((relmse(&a, &b, 0.01).unwrap() - rel).abs() < 1e-12);
        // The epsilon option: 0.25/1, 1/2, 0.25/1.25.
        let rel1 = (0.25 + 0.5 + 0.2) / 6.0;
        assert!((relmse(&a, &b, 1.0).unwrap() - rel1).abs() < 1e-12);
    }

    #[test]
    fn relmse_divides_by_the_reference_only() {
        let zero = img(1, 1, &[[0.0; 3]]);
        let one = img(1, 1, &[[1.0; 3]]);
        assert!((relmse(&one, &zero, 0.01).unwrap() - 100.0).abs() < 1e-12);
        assert!((relmse(&zero, &one, 0.01).unwrap() - 1.0 / 1.01).abs() < 1e-12);
        assert_eq!(mse(&one, &zero).unwrap(), mse(&zero, &one).unwrap());
    }

    #[test]
    fn identical_images_have_no_error() {
        let a = RgbImage::from_fn(7, 5, |x, y| Rgb::new(x as f32, y as f32, 0.3));
        assert_eq!(mse(&a, &a).unwrap(), 0.0);
        assert_eq!(relmse(&a, &a, 0.01).unwrap(), 0.0);
        assert_eq!(psnr(0.0, 1.0), f64::INFINITY);
    }

    #[test]
    fn psnr_definition() {
        assert!((psnr(0.01, 1.0) - 20.0).abs() < 1e-12);
        assert!((psnr(0.01, 10.0) - 40.0).abs() < 1e-12);
        assert!((psnr(1.0, 1.0)).abs() < 1e-12);
    }

    #[test]
    fn bad_epsilon_is_rejected() {
        let a = img(1, 1, &[[0.0; 3]]);
        for eps in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                relmse(&a, &a, eps),
                Err(MetricsError::InvalidOption {
                    name: "epsilon",
                    ..
                })
            ));
        }
    }

    #[test]
    fn accumulates_in_f64() {
        // 786 432 terms of 1e-8: an f32 running sum would drift far outside this tolerance.
        let a = RgbImage::from_fn(4096, 64, |_, _| Rgb::splat(1e-4));
        let b = RgbImage::from_fn(4096, 64, |_, _| Rgb::ZERO);
        let m = mse(&a, &b).unwrap();
        let expected = f64::from(1e-4f32).powi(2);
        assert!((m - expected).abs() < 1e-12 * expected, "{m}");
    }
}
