//! A plain linear-RGB image: the one image type the crates pass around (film means, references
//! read from disk, denoised results, error maps). Reading and writing files is `rt_film`'s job.

use crate::Rgb;

/// [`RgbImage::new`] got a pixel vector whose length is not `width × height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{pixels} pixels do not make a {width}x{height} image")]
pub struct PixelCountError {
    /// Width asked for.
    pub width: usize,
    /// Height asked for.
    pub height: usize,
    /// Pixels given.
    pub pixels: usize,
}

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
    pub fn new(width: usize, height: usize, pixels: Vec<Rgb>) -> Result<Self, PixelCountError> {
        if width.checked_mul(height) != Some(pixels.len()) {
            return Err(PixelCountError {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn construction_checks_the_pixel_count() {
        assert!(RgbImage::new(2, 2, vec![Rgb::ZERO; 4]).is_ok());
        assert_eq!(
            RgbImage::new(2, 2, vec![Rgb::ZERO; 3]),
            Err(PixelCountError {
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
}
