//! The Gaussian blur: the non-adaptive family of the GREE filter bank (Bauszat's thesis
//! ch. 5; research digest seed000-denoise.md §2.1: σ = 2, 4, 8, 16 px), and the baseline the
//! edge-aware filters are measured against.
//!
//! Separable, cut at 3σ, and renormalised at the border (see [`crate::blocks::separable`]):
//! taps outside the image are dropped and the remaining weights rescaled to sum to one, so a
//! constant image stays constant up to the edge.

use crate::blocks::{check_range, separable};
use crate::{DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use rt_core::{Image, RgbImage};

/// Isotropic Gaussian blur of standard deviation `sigma` pixels.
#[derive(Clone, Debug)]
pub struct Gaussian {
    taps: Vec<f32>,
    name: String,
}

impl Gaussian {
    /// Largest σ accepted (a 193-tap kernel): beyond it the value is almost certainly a mistake.
    pub const MAX_SIGMA: f32 = 64.0;

    /// A blur of standard deviation `sigma` pixels (0 is the identity).
    pub fn new(sigma: f32) -> Result<Self, DenoiseError> {
        let sigma = check_range("gaussian", "sigma", sigma, 0.0, Self::MAX_SIGMA)?;
        Ok(Self {
            taps: separable::gaussian_taps(sigma),
            name: format!("gaussian:sigma={sigma}"),
        })
    }

    /// From spec options: `sigma` (pixels, default 2).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        Self::new(o.f32("sigma", 2.0)?)
    }
}

impl Denoiser for Gaussian {
    fn name(&self) -> &str {
        &self.name
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        let out = separable::convolve(frame.colour.pixels(), w, h, &self.taps);
        Image::new(w, h, out).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    #[test]
    fn blurs_an_impulse_symmetrically_and_refuses_bad_sigma() {
        let mut img = Image::filled(9, 9, Rgb::ZERO);
        img.pixels_mut()[40] = Rgb::splat(1.0);
        let out = Gaussian::new(1.0)
            .unwrap()
            .denoise(&NoisyFrame::new(img))
            .unwrap();
        let c = out.pixel(4, 4).x;
        assert!((c - 1.0 / (2.0 * std::f32::consts::PI)).abs() < 0.01, "{c}");
        assert!((out.pixel(3, 4).x - out.pixel(5, 4).x).abs() < 1e-7);
        assert!((out.pixel(4, 3).x / c - (-0.5f32).exp()).abs() < 1e-5);
        for bad in [-1.0, f32::NAN, f32::INFINITY, 65.0] {
            assert!(matches!(
                Gaussian::new(bad),
                Err(DenoiseError::Param { name: "sigma", .. })
            ));
        }
    }
}
