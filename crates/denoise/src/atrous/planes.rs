//! Three-component images stored as planes, row by row (`[x row | y row | z row]` per image
//! row), the compact structure-of-arrays layout the À-Trous pass streams through: one output
//! row is one contiguous chunk, so rows can be handed to threads as disjoint slices, and each
//! component is a contiguous run the compiler can vectorise.
//!
//! Each run is padded to [`Planes::stride`] = width + 16 floats: with power-of-two widths the
//! two dozen runs one pass streams through would otherwise sit a multiple of 4 KiB apart and
//! fight over the same L1 sets (1024² took twice the time per pixel of 1920×1080).

use rt_core::glam::Vec3;
use rt_core::Image;

/// A `width × height` image of three `f32` components in row-interleaved planes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Planes {
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// Distance between the starts of consecutive runs.
    pub(crate) stride: usize,
    /// `height` rows of `3·stride` values: the first, second and third components' runs, each
    /// followed by `stride − width` unused values.
    pub(crate) data: Vec<f32>,
}

/// Padding after each run, in floats (64 bytes: runs stay as aligned as the allocation).
const PAD: usize = 16;

impl Planes {
    /// Zeros.
    pub(crate) fn zeros(width: usize, height: usize) -> Self {
        let stride = width + PAD;
        Self {
            width,
            height,
            stride,
            data: vec![0.0; 3 * stride * height],
        }
    }

    /// The image's pixels, non-finite components replaced by zero (one bad sample must not
    /// spread over the filter's footprint).
    pub(crate) fn from_image(img: &Image<Vec3>) -> Self {
        let (width, height) = img.size();
        let mut p = Self::zeros(width, height);
        let stride = p.stride;
        for (y, row) in p.data.chunks_mut(3 * stride).enumerate() {
            for (x, v) in img.row(y).iter().enumerate() {
                for k in 0..3 {
                    let c = v[k];
                    row[k * stride + x] = if c.is_finite() { c } else { 0.0 };
                }
            }
        }
        p
    }

    /// Back to an image of `Vec3`.
    pub(crate) fn to_image(&self) -> Image<Vec3> {
        Image::from_fn(self.width, self.height, |x, y| {
            let [a, b, c] = self.components(y);
            Vec3::new(a[x], b[x], c[x])
        })
    }

    /// Row `y` split into its three component runs (without their padding).
    #[inline]
    pub(crate) fn components(&self, y: usize) -> [&[f32]; 3] {
        let (s, w) = (self.stride, self.width);
        let row = &self.data[3 * s * y..3 * s * (y + 1)];
        [&row[..w], &row[s..s + w], &row[2 * s..2 * s + w]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_sanitising() {
        let img = Image::from_fn(3, 2, |x, y| Vec3::new(x as f32, y as f32, (x * y) as f32));
        let p = Planes::from_image(&img);
        assert_eq!(
            p.components(1),
            [&[0.0, 1.0, 2.0][..], &[1.0; 3], &[0.0, 1.0, 2.0]]
        );
        assert_eq!(p.to_image(), img);
        let bad = Image::new(1, 1, vec![Vec3::new(f32::NAN, f32::INFINITY, 2.0)]).unwrap();
        assert_eq!(
            Planes::from_image(&bad).components(0),
            [&[0.0][..], &[0.0], &[2.0]]
        );
    }
}
