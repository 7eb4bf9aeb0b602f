//! Image textures (linear RGB, bilinear lookup, repeat wrapping).

use crate::Rgb;
use glam::Vec2;

/// A texel component as a reflectance multiplier: clamped to [0, 1], NaN counted as 0.
///
/// Image files decoded by the loaders are already in range; textures built in memory (or a
/// future float format) may not be, and one NaN texel would otherwise turn every path that
/// touches it into a NaN sample for the film to discard. Clamping here, per texel before the
/// bilinear weights, keeps a bad texel from spreading to its neighbours' lookups.
#[inline]
fn sanitize(c: Rgb) -> Rgb {
    // `max` first: it maps NaN to 0, and `min` then caps infinities and values above 1.
    c.max(Rgb::ZERO).min(Rgb::ONE)
}

/// A linear-RGB image used to modulate material colour. Texels outside [0, 1] (or NaN) are
/// read as clamped (NaN as 0).
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, row 0 at the top of the image.
    pub texels: Vec<Rgb>,
}

impl Texture {
    /// Bilinear lookup at `uv` with repeat wrapping. `v = 0` is the bottom row of the image (the
    /// OBJ and .ruv convention; glTF's top-left origin is converted at load time).
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.width as i64, self.height as i64);
        if w == 0 || h == 0 || !uv.is_finite() {
            return Rgb::ONE;
        }
        let x = uv.x.rem_euclid(1.0) * w as f32 - 0.5;
        let y = (1.0 - uv.y.rem_euclid(1.0)) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: i64, j: i64| {
            sanitize(self.texels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize])
        };
        let (i, j) = (x0 as i64, y0 as i64);
        let top = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let bot = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bot * fy
    }
}

impl crate::content_hash::ContentHash for Texture {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Texture {
            width,
            height,
            texels,
        } = self;
        width.content_hash(out);
        height.content_hash(out);
        texels.content_hash(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_texels_read_as_clamped_reflectances() {
        let t = Texture {
            width: 2,
            height: 1,
            texels: vec![
                Rgb::new(f32::NAN, f32::INFINITY, -2.0),
                Rgb::new(0.5, f32::NEG_INFINITY, 3.0),
            ],
        };
        for i in 0..50 {
            let c = t.lookup(Vec2::new(i as f32 / 49.0, 0.5));
            assert!(
                c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0,
                "{c}"
            );
        }
        assert_eq!(t.lookup(Vec2::new(0.25, 0.5)), Rgb::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn lookup_of_constant_texture_is_constant_and_v_is_bottom_up() {
        let t = Texture {
            width: 1,
            height: 2,
            texels: vec![Rgb::X, Rgb::Y],
        };
        // Row 0 (top) is red: v near 1.
        assert!((t.lookup(Vec2::new(0.5, 0.75)) - Rgb::X).length() < 1e-6);
        assert!((t.lookup(Vec2::new(0.5, 0.25)) - Rgb::Y).length() < 1e-6);
    }
}
