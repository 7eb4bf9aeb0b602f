//! The k×k box filter.

use crate::{DenoiseError, Denoiser, NoisyFrame};
use rt_core::Rgb;

/// Mean over a `(2r+1)²` window, clamped at the image border (the window shrinks, so a constant
/// image stays constant up to the edge).
#[derive(Clone, Debug)]
pub struct BoxBlur {
    radius: usize,
}

impl BoxBlur {
    /// A filter of the given radius (0 is the identity). Radii above 64 are rejected: they are
    /// almost certainly a mistake and would be slow with this direct implementation.
    pub fn new(radius: usize) -> Result<Self, DenoiseError> {
        if radius > 64 {
            return Err(DenoiseError::Param {
                name: "radius",
                message: format!("must be at most 64, got {radius}"),
            });
        }
        Ok(Self { radius })
    }
}

impl Denoiser for BoxBlur {
    fn name(&self) -> &str {
        "box"
    }

    fn apply(&self, frame: &NoisyFrame) -> Vec<Rgb> {
        let (w, h, r) = (frame.width, frame.height, self.radius);
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
        let tmp = pass(&frame.beauty, true);
        pass(&tmp, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_stays_constant_and_mean_is_kept_inside() {
        let f = NoisyFrame::from_beauty(5, 4, vec![Rgb::splat(2.0); 20]);
        assert!(BoxBlur::new(2)
            .unwrap()
            .apply(&f)
            .iter()
            .all(|p| (*p - Rgb::splat(2.0)).length() < 1e-6));
        let mut img = vec![Rgb::ZERO; 25];
        img[12] = Rgb::splat(9.0);
        let f = NoisyFrame::from_beauty(5, 5, img);
        let out = BoxBlur::new(1).unwrap().apply(&f);
        assert!((out[12].x - 1.0).abs() < 1e-6 && (out[6].x - 1.0).abs() < 1e-6 && out[0].x == 0.0);
        assert_eq!(BoxBlur::new(0).unwrap().apply(&f), f.beauty);
        assert!(BoxBlur::new(65).is_err());
    }
}
