//! A plain image of any pixel type: the one image type the crates pass around (film means,
//! references read from disk, denoised results, error maps, feature buffers). [`RgbImage`] is
//! the linear-RGB case. Reading and writing files is `rt_film`'s job.

use crate::Rgb;

/// [`Image::new`] got a pixel vector whose length is not `width × height`.
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

/// `width × height` pixels of type `T` in row-major order, top row first.
///
/// Any size is allowed, including 0×0; the metrics reject empty images instead, so that the
/// error can say which of the two images was empty.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Image<T> {
    width: usize,
    height: usize,
    pixels: Vec<T>,
}

/// A linear RGB image.
pub type RgbImage = Image<Rgb>;

impl<T> Image<T> {
    /// An image from its pixels, row-major, top row first.
    pub fn new(width: usize, height: usize, pixels: Vec<T>) -> Result<Self, PixelCountError> {
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
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> T) -> Self {
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
    pub fn pixels(&self) -> &[T] {
        &self.pixels
    }

    /// All pixels, row-major, to change in place.
    pub fn pixels_mut(&mut self) -> &mut [T] {
        &mut self.pixels
    }

    /// The pixels, giving up the image.
    pub fn into_pixels(self) -> Vec<T> {
        self.pixels
    }

    /// Row `y` (0 is the top).
    pub fn row(&self, y: usize) -> &[T] {
        &self.pixels[y * self.width..(y + 1) * self.width]
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    /// True for an image without pixels.
    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }

    /// The image with `f` applied to every pixel.
    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Image<U> {
        Image {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        }
    }
}

impl<T: Copy> Image<T> {
    /// An image of one value.
    pub fn filled(width: usize, height: usize, value: T) -> Self {
        Self {
            width,
            height,
            pixels: vec![value; width * height],
        }
    }

    /// Pixel `(x, y)`.
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> T {
        self.pixels[y * self.width + x]
    }

    /// Pixel `(x, y)` with coordinates clamped to the image (the edge is repeated), for filters
    /// whose windows reach past the border.
    #[inline]
    pub fn clamped(&self, x: isize, y: isize) -> T {
        let x = x.clamp(0, self.width as isize - 1) as usize;
        let y = y.clamp(0, self.height as isize - 1) as usize;
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
