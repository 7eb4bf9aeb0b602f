//! The k×k box filter: the simplest member of a filter bank, and a baseline.

use crate::{DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use rt_core::{Image, RgbImage};

/// Mean over a `(2r+1)²` window, clamped at the image border (the window shrinks, so a constant
/// image stays constant up to the edge).
#[derive(Clone, Debug)]
pub struct BoxBlur {
    radius: usize,
    name: String,
}

impl BoxBlur {
    /// Largest radius accepted: beyond it the direct implementation is slow and the value is
    /// almost certainly a mistake.
    pub const MAX_RADIUS: usize = 64;

    /// A filter of the given radius (0 is the identity).
    pub fn new(radius: usize) -> Result<Self, DenoiseError> {
        if radius > Self::MAX_RADIUS {
            return Err(DenoiseError::Param {
                denoiser: "box",
                name: "radius",
                message: format!("must be at most {}, got {radius}", Self::MAX_RADIUS),
            });
        }
        Ok(Self {
            radius,
            name: format!("box:radius={radius}"),
        })
    }

    /// From spec options: `radius` (default 2).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        Self::new(o.usize("radius", 2)?)
    }
}

impl Denoiser for BoxBlur {
    fn name(&self) -> &str {
        &self.name
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        // A box is the separable filter with equal taps: the same border cut, rows in parallel.
        let taps = vec![1.0; self.radius + 1];
        let out = crate::blocks::separable::convolve(frame.colour.pixels(), w, h, &taps);
        Image::new(w, h, out).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    fn frame(w: usize, h: usize, px: Vec<Rgb>) -> NoisyFrame {
        NoisyFrame::new(Image::new(w, h, px).unwrap())
    }

    #[test]
    fn constant_stays_constant_and_mean_is_kept_inside() {
        let f = frame(5, 4, vec![Rgb::splat(2.0); 20]);
        let out = BoxBlur::new(2).unwrap().denoise(&f).unwrap();
        assert!(out
            .pixels()
            .iter()
            .all(|p| (*p - Rgb::splat(2.0)).length() < 1e-6));
        let mut img = vec![Rgb::ZERO; 25];
        img[12] = Rgb::splat(9.0);
        let f = frame(5, 5, img);
        let out = BoxBlur::new(1).unwrap().denoise(&f).unwrap();
        let out = out.pixels();
        assert!((out[12].x - 1.0).abs() < 1e-6 && (out[6].x - 1.0).abs() < 1e-6 && out[0].x == 0.0);
        assert_eq!(BoxBlur::new(0).unwrap().denoise(&f).unwrap(), f.colour);
        assert!(BoxBlur::new(65).is_err());
    }
}
