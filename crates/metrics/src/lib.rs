//! `rt-metrics`: how far an image is from a reference.
//!
//! Convergence plots, estimator comparisons and denoiser evaluations all reduce to the same
//! question, so the answer lives in one library that `render compare` (and later
//! `render experiment`) call. [`compare`] returns every metric at once; [`mse`], [`relmse`],
//! [`psnr`], [`ssim`] and [`error_image`] are there for callers that want one. Definitions, all
//! over linear RGB with `a` the test image and `b` the reference:
//!
//! | metric | definition |
//! |---|---|
//! | MSE | mean over pixels and the 3 channels of `(a − b)²` |
//! | relMSE | mean over pixels and channels of `(a − b)² / (b² + ε)`, ε = 0.01 by default |
//! | RMSE | `sqrt(MSE)` |
//! | PSNR | `10·log10(peak² / MSE)` dB, peak = 1 by default; `+inf` when MSE = 0 |
//! | SSIM | Wang et al. 2004 on clamped linear luminance, 11×11 Gaussian window ([`ssim`]) |
//!
//! Sequences have their own metrics in [`temporal`]: temporal error (flicker under a fixed
//! camera), temporal relMSE (frame differences against the reference's) and lag (frames to
//! recover after a sudden change), and a frame-by-frame [`temporal::SequenceComparison`].
//!
//! Sums are taken in `f64` in a fixed order (per row or band of rows, then in order), so every
//! result is the same bits for any number of threads. Inputs are checked first
//! ([`validate_pair`]): empty images, different sizes and NaN or infinite values are typed errors
//! ([`MetricsError`]) that say which image, and for a bad value which pixel and channel.
//!
//! The crate reads and writes no files; it sees plain [`RgbImage`]s. Depends on `rt-core` (for
//! `Rgb` and the sRGB curve), `rayon` and `thiserror`.
//!
//! ```
//! use rt_core::Rgb;
//! use rt_metrics::{compare, CompareOptions, RgbImage};
//! let reference = RgbImage::from_fn(16, 16, |_, _| Rgb::splat(0.5));
//! let test = RgbImage::from_fn(16, 16, |_, _| Rgb::splat(0.6));
//! let m = compare(&test, &reference, &CompareOptions::default())?;
//! assert!((m.mse - 0.01).abs() < 1e-7);
//! assert!((m.relmse - 0.01 / (0.25 + 0.01)).abs() < 1e-6);
//! assert!((m.psnr - 20.0).abs() < 1e-4);
//! # Ok::<(), rt_metrics::MetricsError>(())
//! ```
#![forbid(unsafe_code)]

mod error;
mod error_metrics;
mod false_colour;
mod image;
mod reduce;
mod ssim;
pub mod temporal;

pub use error::{MetricsError, Result, Role};
pub use error_metrics::{mse, psnr, relmse, DEFAULT_EPSILON, DEFAULT_PEAK};
pub use false_colour::{error_image, viridis, FalseColourOptions};
pub use image::{validate_pair, RgbImage};
pub use ssim::ssim;

/// Settings of [`compare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompareOptions {
    /// relMSE's ε (default [`DEFAULT_EPSILON`] = 0.01); must be positive.
    pub epsilon: f64,
    /// PSNR's peak value (default [`DEFAULT_PEAK`] = 1); must be positive.
    pub peak: f64,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            epsilon: DEFAULT_EPSILON,
            peak: DEFAULT_PEAK,
        }
    }
}

/// Every metric of a test image against a reference (definitions in the crate documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Mean squared error.
    pub mse: f64,
    /// Relative mean squared error with the [`CompareOptions::epsilon`] it was computed with.
    pub relmse: f64,
    /// Root mean squared error, `sqrt(mse)`.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB; `+inf` for identical images.
    pub psnr: f64,
    /// Mean structural similarity, 1 for identical images.
    pub ssim: f64,
}

/// Compares `test` with `reference`: validates the pair once, then computes every metric.
pub fn compare(test: &RgbImage, reference: &RgbImage, opts: &CompareOptions) -> Result<Metrics> {
    let epsilon = error::positive("epsilon", opts.epsilon)?;
    let peak = error::positive("peak", opts.peak)?;
    validate_pair(test, reference)?;
    let (mse, relmse) = error_metrics::mse_and_relmse(test, reference, epsilon);
    Ok(Metrics {
        mse,
        relmse,
        rmse: mse.sqrt(),
        psnr: psnr(mse, peak),
        ssim: ssim::mean_ssim_checked(test, reference),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    #[test]
    fn compare_agrees_with_the_single_metrics() {
        let a = RgbImage::from_fn(20, 13, |x, y| {
            Rgb::new(x as f32 / 20.0, y as f32 / 13.0, 0.5)
        });
        let b = RgbImage::from_fn(20, 13, |x, y| {
            Rgb::new(y as f32 / 13.0, 0.3, x as f32 / 20.0)
        });
        let opts = CompareOptions {
            epsilon: 0.05,
            peak: 2.0,
        };
        let m = compare(&a, &b, &opts).unwrap();
        assert_eq!(m.mse, mse(&a, &b).unwrap());
        assert_eq!(m.relmse, relmse(&a, &b, 0.05).unwrap());
        assert_eq!(m.rmse, m.mse.sqrt());
        assert_eq!(m.psnr, psnr(m.mse, 2.0));
        assert_eq!(m.ssim, ssim(&a, &b).unwrap());
    }

    #[test]
    fn identical_images() {
        let a = RgbImage::from_fn(12, 12, |x, y| Rgb::splat((x * y) as f32 / 144.0));
        let m = compare(&a, &a, &CompareOptions::default()).unwrap();
        assert_eq!(
            m,
            Metrics {
                mse: 0.0,
                relmse: 0.0,
                rmse: 0.0,
                psnr: f64::INFINITY,
                ssim: 1.0
            }
        );
    }

    #[test]
    fn options_are_checked() {
        let a = RgbImage::from_fn(2, 2, |_, _| Rgb::ONE);
        let e = compare(
            &a,
            &a,
            &CompareOptions {
                peak: 0.0,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "peak must be positive and finite, got 0");
        assert!(compare(
            &a,
            &a,
            &CompareOptions {
                epsilon: -0.01,
                ..Default::default()
            },
        )
        .is_err());
    }
}
