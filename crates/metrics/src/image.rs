//! A plain linear-RGB image and the checks every metric makes before it reads pixels.

use crate::error::{MetricsError, Result, Role};
use rt_core::Rgb;

/// A linear RGB image: `width × height` pixels in row-major order, top row first.
///
/// Any size is allowed, including 0×0; the metrics reject empty images instead, so that the
/// error can say which of the two images was empty.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    width: usize,
    height: usize,
    pixels: Vec<Rgb>,
}

impl RgbImage {
    /// An image from its pixels, row-major, top row first.
    pub fn new(width: usize, height: usize, pixels: Vec<Rgb>) -> Result<Self> {
        if width.checked_mul(height) != Some(pixels.len()) {
            return Err(MetricsError::PixelCount {
                width,
                height,
                pixels: pixels.len(),
            });
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// An image whose pixel `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> Rgb) -> Self {
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// All pixels, row-major.
    pub fn pixels(&self) -> &[Rgb] {
        &self.pixels
    }

    /// The pixels, giving up the image.
    pub fn into_pixels(self) -> Vec<Rgb> {
        self.pixels
    }

    /// Row `y` (0 is the top).
    pub fn row(&self, y: usize) -> &[Rgb] {
        &self.pixels[y * self.width..(y + 1) * self.width]
    }

    /// Pixel `(x, y)`.
    pub fn pixel(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }

    /// The first non-finite channel value in row-major order, as an error about `role`.
    fn check_finite(&self, role: Role) -> Result<()> {
        // A fast scan first: images are almost always clean, and only a failure needs the
        // position.
        if self.pixels.iter().all(|p| p.is_finite()) {
            return Ok(());
        }
        for (i, p) in self.pixels.iter().enumerate() {
            for (c, channel) in ['R', 'G', 'B'].into_iter().enumerate() {
                if !p[c].is_finite() {
                    return Err(MetricsError::NonFinite {
                        role,
                        x: i % self.width,
                        y: i / self.width,
                        channel,
                        value: p[c],
                    });
                }
            }
        }
        Ok(())
    }
}

/// Checks that two images can be compared: neither is empty, they have the same size, and every
/// value is finite (test image first). Every metric in this crate calls it; callers that want to
/// report problems before doing other work can call it themselves.
pub fn validate_pair(test: &RgbImage, reference: &RgbImage) -> Result<()> {
    for (img, role) in [(test, Role::Test), (reference, Role::Reference)] {
        if img.pixels.is_empty() {
            return Err(MetricsError::Empty {
                role,
                width: img.width,
                height: img.height,
            });
        }
    }
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(MetricsError::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        });
    }
    test.check_finite(Role::Test)?;
    reference.check_finite(Role::Reference)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn construction_checks_the_pixel_count() {
        assert!(RgbImage::new(2, 2, vec![Rgb::ZERO; 4]).is_ok());
        assert_eq!(
            RgbImage::new(2, 2, vec![Rgb::ZERO; 3]),
            Err(MetricsError::PixelCount {
                width: 2,
                height: 2,
                pixels: 3
            })
        );
        assert!(RgbImage::new(usize::MAX, 2, vec![]).is_err());
        let img = RgbImage::from_fn(3, 2, |x, y| Rgb::new(x as f32, y as f32, 0.0));
        assert_eq!(img.pixel(2, 1), Rgb::new(2.0, 1.0, 0.0));
        assert_eq!(img.row(1)[0], Rgb::new(0.0, 1.0, 0.0));
        assert_eq!(img.into_pixels().len(), 6);
    }

    #[test]
    fn pairs_are_validated_in_a_fixed_order() {
        let a = RgbImage::from_fn(3, 2, |_, _| Rgb::ONE);
        let empty = RgbImage::new(0, 5, vec![]).unwrap();
        assert!(validate_pair(&a, &a).is_ok());
        assert_eq!(
            validate_pair(&empty, &a),
            Err(MetricsError::Empty {
                role: Role::Test,
                width: 0,
                height: 5
            })
        );
        assert!(matches!(
            validate_pair(&a, &empty),
            Err(MetricsError::Empty {
                role: Role::Reference,
                ..
            })
        ));
        let b = RgbImage::from_fn(2, 3, |_, _| Rgb::ONE);
        let e = validate_pair(&a, &b).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the test image is 3x2 but the reference image is 2x3"
        );
        let mut nan = a.clone().into_pixels();
        nan[4].z = f32::INFINITY;
        nan[5].x = f32::NAN;
        let nan = RgbImage::new(3, 2, nan).unwrap();
        let e = validate_pair(&a, &nan).unwrap_err();
        assert_eq!(
            e,
            MetricsError::NonFinite {
                role: Role::Reference,
                x: 1,
                y: 1,
                channel: 'B',
                value: f32::INFINITY
            }
        );
        assert_eq!(
            e.to_string(),
            "the reference image has a non-finite value (inf) at pixel (1, 1), channel B"
        );
        // The test image is checked first.
        assert!(matches!(
            validate_pair(&nan, &nan),
            Err(MetricsError::NonFinite {
                role: Role::Test,
                ..
            })
        ));
    }
}
