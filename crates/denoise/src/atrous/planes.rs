//! Three-component images stored as planes, row by row (`[x row | y row | z row]` per image
//! row), the compact structure-of-arrays layout the À-Trous pass streams through: one output
//! row is one contiguous chunk, so rows can be handed to threads as disjoint slices, and each
//! component is a contiguous run the compiler can vectorise.

use rt_core::glam::Vec3;
use rt_core::Image;

/// A `width × height` image of three `f32` components in row-interleaved planes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Planes {
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// `height` rows of `3·width` values: the first, second and third components' runs.
    pub(crate) data: Vec<f32>,
}

impl Planes {
    /// Zeros.
    pub(crate) fn zeros(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0.0; 3 * width * height],
        }
    }

    /// The image's pixels, non-finite components replaced by zero (one bad sample must not
    /// spread over the filter's footprint).
    pub(crate) fn from_image(img: &Image<Vec3>) -> Self {
        let (width, height) = img.size();
        let mut p = Self::zeros(width, height);
        for y in 0..height {
            let row = &mut p.data[3 * width * y..3 * width * (y + 1)];
            for (x, v) in img.row(y).iter().enumerate() {
                for k in 0..3 {
                    let c = v[k];
                    row[k * width + x] = if c.is_finite() { c } else { 0.0 };
                }
            }
        }
        p
    }

    /// Back to an image of `Vec3`.
    pub(crate) fn to_image(&self) -> Image<Vec3> {
        let w = self.width;
        Image::from_fn(w, self.height, |x, y| {
            let row = self.row(y);
            Vec3::new(row[x], row[w + x], row[2 * w + x])
        })
    }

    /// Row `y`: the three component runs, concatenated.
    #[inline]
    pub(crate) fn row(&self, y: usize) -> &[f32] {
        &self.data[3 * self.width * y..3 * self.width * (y + 1)]
    }

    /// Row `y` split into its three component runs.
    #[inline]
    pub(crate) fn components(&self, y: usize) -> [&[f32]; 3] {
        let (a, rest) = self.row(y).split_at(self.width);
        let (b, c) = rest.split_at(self.width);
        [a, b, c]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_sanitising() {
        let img = Image::from_fn(3, 2, |x, y| Vec3::new(x as f32, y as f32, (x * y) as f32));
        let p = Planes::from_image(&img);
        assert_eq!(p.row(1), &[0.0, 1.0, 2.0, 1.0, 1.0, 1.0, 0.0, 1.0, 2.0]);
        assert_eq!(p.to_image(), img);
        let bad = Image::new(1, 1, vec![Vec3::new(f32::NAN, f32::INFINITY, 2.0)]).unwrap();
        assert_eq!(Planes::from_image(&bad).data, vec![0.0, 0.0, 2.0]);
    }
}
