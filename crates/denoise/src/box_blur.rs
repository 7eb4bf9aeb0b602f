//! The k×k box filter: the simplest member of a filter bank, and a baseline.

use crate::{DenoiseError, Denoiser, NoisyFrame, Options};
use rt_core::{Image, Rgb, RgbImage};

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
        let r = self.radius;
        // Separable: rows, then columns.
        let pass = |src: &[Rgb], horizontal: bool| -> Vec<Rgb> {
            let mut out = vec![Rgb::ZERO; w * h];
            for y in 0..h {
                for x in 0..w {
                    let (c, n) = if horizontal { (x, w) } else { (y, h) };
                    let (lo, hi) = (c.saturating_sub(r), (c + r).min(n - 1));
                    let mut sum = Rgb::ZERO;
                    for k in lo..=hi {
                        sum += if horizontal {
                            src[y * w + k]
                        } else {
                            src[k * w + x]
                        };
                    }
                    out[y * w + x] = sum / (hi - lo + 1) as f32;
                }
            }
            out
        };
        let tmp = pass(frame.colour.pixels(), true);
        Image::new(w, h, pass(&tmp, false)).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
