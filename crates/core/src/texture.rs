//! Image textures: linear RGB texels looked up with Mitsuba 3's `bitmap` options (bilinear or
//! nearest filtering; repeat, mirror or clamp wrapping, a `to_uv` transform), as colours, as
//! scalars (luminance) and as the scalar's gradient in uv, which bump mapping needs
//! ([`crate::bump`]). Mitsuba's `checkerboard` is a two-texel texture whose lookup picks a
//! texel by Mitsuba's rule ([`Texture::checkerboard`], [`Layout`]).

use crate::Rgb;
use glam::{Affine2, Vec2};

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

/// Luminance of linear sRGB primaries: what Mitsuba 3 reads from a colour texture where a
/// scalar (a bump height, a roughness) is wanted.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// How a lookup combines texels (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The four nearest texel centres, weighted bilinearly.
    #[default]
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

/// What a lookup outside [0, 1]² reads (Mitsuba's `wrap_mode`), applied per texel index.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// Tiles alternate with their mirror images.
    Mirror,
    /// The border texels extend outwards.
    Clamp,
}

impl Wrap {
    /// Texel index `i` of a row or column of `n > 0` texels.
    #[inline]
    fn index(self, i: i64, n: i64) -> i64 {
        match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let j = i.rem_euclid(2 * n);
                if j >= n {
                    2 * n - 1 - j
                } else {
                    j
                }
            }
        }
    }
}

/// How a lookup finds its texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Layout {
    /// Rows of texels covering [0, 1]².
    #[default]
    Image,
    /// Mitsuba 3's `checkerboard` (checkerboard.cpp): texel 0 (`color0`) where `frac(u) > ½`
    /// equals `frac(v) > ½`, texel 1 elsewhere.
    Checkerboard,
}

/// A linear-RGB image used to modulate material parameters. Texels outside [0, 1] (or NaN)
/// are read as clamped (NaN as 0).
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, row 0 at the top of the image.
    pub texels: Vec<Rgb>,
    /// Filtering.
    pub filter: Filter,
    /// Wrapping outside [0, 1]².
    pub wrap: Wrap,
    /// Maps the surface's uv to the image's (Mitsuba's `to_uv`; the identity by default).
    pub to_uv: Affine2,
    /// An image, or a checkerboard of its two texels.
    pub layout: Layout,
}

/// The texels and weights a lookup at one point combines.
struct Footprint {
    /// Texel indices into `texels`: the four of a bilinear lookup (top-left, top-right,
    /// bottom-left, bottom-right), or one repeated four times.
    at: [usize; 4],
    /// Fractional position between the columns and between the rows (0 for nearest).
    f: Vec2,
}

impl Texture {
    /// A bilinear, repeating texture.
    pub fn new(width: u32, height: u32, texels: Vec<Rgb>) -> Self {
        Self {
            width,
            height,
            texels,
            filter: Filter::Bilinear,
            wrap: Wrap::Repeat,
            to_uv: Affine2::IDENTITY,
            layout: Layout::Image,
        }
    }

    /// Mitsuba 3's `checkerboard`: `color0` where the fractional parts of `u` and `v` (after
    /// `to_uv`) are both at most ½ or both above, `color1` elsewhere. Piecewise constant: its
    /// gradient is zero, as a nearest lookup's.
    pub fn checkerboard(color0: Rgb, color1: Rgb, to_uv: Affine2) -> Self {
        let mut t = Self::new(2, 1, vec![color0, color1]);
        t.filter = Filter::Nearest;
        t.to_uv = to_uv;
        t.layout = Layout::Checkerboard;
        t
    }

    /// The texels around `uv`, or `None` for an empty image or a non-finite `uv`.
    #[inline]
    fn footprint(&self, uv: Vec2) -> Option<Footprint> {
        let (w, h) = (self.width as i64, self.height as i64);
        let uv = self.to_uv.transform_point2(uv);
        if self.layout == Layout::Checkerboard {
            if !uv.is_finite() {
                return None;
            }
            let high = (uv - uv.floor()).cmpgt(Vec2::splat(0.5));
            let k = (high.x != high.y) as usize;
            return Some(Footprint {
                at: [k; 4],
                f: Vec2::ZERO,
            });
        }
        if w == 0 || h == 0 || !uv.is_finite() {
            return None;
        }
        // `v = 0` is the bottom row. Repeat wraps the coordinate first, as lookups always
        // did, so that large coordinates keep their precision.
        let (u, v) = match self.wrap {
            Wrap::Repeat => (uv.x.rem_euclid(1.0), uv.y.rem_euclid(1.0)),
            _ => (uv.x, uv.y),
        };
        let (x, y) = (u * w as f32, (1.0 - v) * h as f32);
        let index = |i: i64, j: i64| (self.wrap.index(j, h) * w + self.wrap.index(i, w)) as usize;
        match self.filter {
            Filter::Nearest => {
                let k = index(x.floor() as i64, y.floor() as i64);
                Some(Footprint {
                    at: [k; 4],
                    f: Vec2::ZERO,
                })
            }
            Filter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (i, j) = (x0 as i64, y0 as i64);
                Some(Footprint {
                    at: [
                        index(i, j),
                        index(i + 1, j),
                        index(i, j + 1),
                        index(i + 1, j + 1),
                    ],
                    f: Vec2::new(x - x0, y - y0),
                })
            }
        }
    }

    /// The least and greatest luminance a lookup can return (lookups interpolate between
    /// texels, and luminance is linear); 1 for an empty image, which reads white.
    pub fn luminance_range(&self) -> (f32, f32) {
        if self.texels.is_empty() {
            return (1.0, 1.0);
        }
        self.texels
            .iter()
            .map(|&t| luminance(sanitize(t)))
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l), hi.max(l))
            })
    }

    /// Colour at `uv` (white for an empty image or a non-finite `uv`). `v = 0` is the bottom
    /// row of the image (the OBJ and .ruv convention; glTF's top-left origin is converted at
    /// load time).
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        self.interpolate(uv, sanitize)
    }

    /// [`Texture::lookup`] without the upper clamp: texels are read as they are, negative or
    /// NaN components as 0 and infinities as the largest finite value. For parameters that are
    /// not reflectances, such as a conductor's index of refraction (`eta` above 1, `k` often
    /// above 3), which the loaders read from float images or checkerboard constants.
    pub fn lookup_unbounded(&self, uv: Vec2) -> Rgb {
        self.interpolate(uv, |c| c.max(Rgb::ZERO).min(Rgb::splat(f32::MAX)))
    }

    /// The bilinear (or nearest) combination at `uv` of texels passed through `texel`.
    #[inline]
    fn interpolate(&self, uv: Vec2, texel: impl Fn(Rgb) -> Rgb) -> Rgb {
        let Some(fp) = self.footprint(uv) else {
            return Rgb::ONE;
        };
        let at = |k: usize| texel(self.texels[fp.at[k]]);
        let (fx, fy) = (fp.f.x, fp.f.y);
        let top = at(0) * (1.0 - fx) + at(1) * fx;
        let bot = at(2) * (1.0 - fx) + at(3) * fx;
        top * (1.0 - fy) + bot * fy
    }

    /// The luminance at `uv` and its gradient `(∂/∂u, ∂/∂v)`: the derivative of the bilinear
    /// interpolant, zero for nearest lookups (piecewise constant) and where the lookup is
    /// undefined (value 1 there, as [`Texture::lookup`]).
    pub fn scalar_gradient(&self, uv: Vec2) -> (f32, Vec2) {
        let Some(fp) = self.footprint(uv) else {
            return (1.0, Vec2::ZERO);
        };
        let at = |k: usize| luminance(sanitize(self.texels[fp.at[k]]));
        let (a, b, c, d) = (at(0), at(1), at(2), at(3));
        let (fx, fy) = (fp.f.x, fp.f.y);
        let top = a * (1.0 - fx) + b * fx;
        let bot = c * (1.0 - fx) + d * fx;
        let value = top * (1.0 - fy) + bot * fy;
        if self.filter == Filter::Nearest {
            return (value, Vec2::ZERO);
        }
        // x grows with u; y (rows, top down) falls as v grows.
        let d_dx = (b - a) * (1.0 - fy) + (d - c) * fy;
        let d_dy = bot - top;
        let grad = Vec2::new(d_dx * self.width as f32, -d_dy * self.height as f32);
        // The chain rule through `to_uv`: the gradient in the surface's uv.
        (value, self.to_uv.matrix2.transpose() * grad)
    }
}

impl crate::content_hash::ContentHash for Texture {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Texture {
            width,
            height,
            texels,
            filter,
            wrap,
            to_uv,
            layout,
        } = self;
        width.content_hash(out);
        height.content_hash(out);
        texels.content_hash(out);
        // Only when not the default, so that scenes keep the hashes they had before the options.
        if (*filter, *wrap) != (Filter::Bilinear, Wrap::Repeat) {
            format!("{filter:?}{wrap:?}").content_hash(out);
        }
        if *to_uv != Affine2::IDENTITY || *layout != Layout::Image {
            format!("{to_uv:?}{layout:?}").content_hash(out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_texels_read_as_clamped_reflectances() {
        let t = Texture::new(
            2,
            1,
            vec![
                Rgb::new(f32::NAN, f32::INFINITY, -2.0),
                Rgb::new(0.5, f32::NEG_INFINITY, 3.0),
            ],
        );
        for i in 0..50 {
            let c = t.lookup(Vec2::new(i as f32 / 49.0, 0.5));
            assert!(
                c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0,
                "{c}"
            );
        }
        assert_eq!(t.lookup(Vec2::new(0.25, 0.5)), Rgb::new(0.0, 1.0, 0.0));
        // Unbounded: values above 1 kept, still finite and non-negative everywhere.
        for i in 0..50 {
            let c = t.lookup_unbounded(Vec2::new(i as f32 / 49.0, 0.5));
            assert!(c.is_finite() && c.min_element() >= 0.0, "{c}");
        }
        assert_eq!(
            t.lookup_unbounded(Vec2::new(0.75, 0.5)),
            Rgb::new(0.5, 0.0, 3.0)
        );
        assert_eq!(
            t.lookup_unbounded(Vec2::new(0.25, 0.5)),
            Rgb::new(0.0, f32::MAX, 0.0)
        );
    }

    #[test]
    fn lookup_of_constant_texture_is_constant_and_v_is_bottom_up() {
        let t = Texture::new(1, 2, vec![Rgb::X, Rgb::Y]);
        // Row 0 (top) is red: v near 1.
        assert!((t.lookup(Vec2::new(0.5, 0.75)) - Rgb::X).length() < 1e-6);
        assert!((t.lookup(Vec2::new(0.5, 0.25)) - Rgb::Y).length() < 1e-6);
    }

    /// A row of four texels 0, 1/3, 2/3, 1 read outside [0, 1] under each wrap mode, and
    /// between texel centres under each filter.
    #[test]
    fn wrap_modes_and_filters_read_the_texels_mitsuba_reads() {
        let row: Vec<Rgb> = (0..4).map(|i| Rgb::splat(i as f32 / 3.0)).collect();
        let mut t = Texture::new(4, 1, row);
        t.filter = Filter::Nearest;
        // Texel centres of the tile to the right, u in (1, 2).
        let right = |t: &Texture| -> Vec<f32> {
            (0..4)
                .map(|i| t.lookup(Vec2::new(1.125 + i as f32 * 0.25, 0.5)).x * 3.0)
                .collect()
        };
        let close = |a: Vec<f32>, b: [f32; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4);
        t.wrap = Wrap::Repeat;
        assert!(close(right(&t), [0.0, 1.0, 2.0, 3.0]), "{:?}", right(&t));
        t.wrap = Wrap::Mirror;
        assert!(close(right(&t), [3.0, 2.0, 1.0, 0.0]), "{:?}", right(&t));
        t.wrap = Wrap::Clamp;
        assert!(close(right(&t), [3.0; 4]), "{:?}", right(&t));
        // Halfway between the first two texel centres (u = 0.25).
        let mid = Vec2::new(0.25, 0.5);
        t.filter = Filter::Nearest;
        assert!((t.lookup(mid).x - 1.0 / 3.0).abs() < 1e-6);
        t.filter = Filter::Bilinear;
        assert!((t.lookup(mid).x - 1.0 / 6.0).abs() < 1e-6);
    }

    /// Mitsuba 3's rule (checkerboard.cpp): `color0` where `frac(u) > ½` equals
    /// `frac(v) > ½`, after `to_uv`; checked away from the edges (within 1e-3 of a half).
    #[test]
    fn checkerboard_follows_mitsubas_rule() {
        let (c0, c1) = (Rgb::new(0.4, 0.1, 0.0), Rgb::new(0.2, 0.9, 1.0));
        let to_uv = Affine2::from_scale_angle_translation(Vec2::new(3.0, 5.0), 0.3, Vec2::X);
        let t = Texture::checkerboard(c0, c1, to_uv);
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut checked = 0;
        for _ in 0..2000 {
            let uv = Vec2::new(rng.f32() * 4.0 - 2.0, rng.f32() * 4.0 - 2.0);
            let p = to_uv.transform_point2(uv);
            let f = p - p.floor();
            if (f - 0.5).abs().min_element() < 1e-3 || f.min_element() < 1e-3 {
                continue;
            }
            let want = if (f.x > 0.5) == (f.y > 0.5) { c0 } else { c1 };
            assert_eq!(t.lookup(uv), want, "uv {uv}");
            checked += 1;
        }
        assert!(checked > 1900);
        // On the edges: ½ and 0 belong to the lower half.
        let t = Texture::checkerboard(c0, c1, Affine2::IDENTITY);
        for (uv, want) in [
            ((0.5, 0.5), c0),
            ((0.0, 0.0), c0),
            ((0.5, 0.7), c1),
            ((1.0, 0.3), c0),
        ] {
            assert_eq!(t.lookup(Vec2::from(uv)), want, "uv {uv:?}");
        }
    }

    /// The gradient is the finite difference of the scalar lookup, in both directions.
    #[test]
    fn scalar_gradient_is_the_derivative_of_the_lookup() {
        let texels = (0..12)
            .map(|i| Rgb::new((i * 7 % 5) as f32 / 4.0, (i % 3) as f32 / 2.0, 0.3))
            .collect();
        let mut t = Texture::new(4, 3, texels);
        // A `to_uv` that shears, scales and moves: the gradient is in the surface's uv.
        t.to_uv = Affine2::from_cols_array(&[1.3, 0.2, -0.4, 0.9, 0.1, 0.25]);
        let h = 1e-3;
        for uv in [
            Vec2::new(0.3, 0.4),
            Vec2::new(0.61, 0.77),
            Vec2::new(0.05, 0.2),
        ] {
            let (v, g) = t.scalar_gradient(uv);
            assert!((v - luminance(t.lookup(uv))).abs() < 1e-6);
            let fd =
                |d: Vec2| (luminance(t.lookup(uv + d)) - luminance(t.lookup(uv - d))) / (2.0 * h);
            let (gu, gv) = (fd(Vec2::new(h, 0.0)), fd(Vec2::new(0.0, h)));
            assert!((g.x - gu).abs() < 1e-2 * (1.0 + gu.abs()), "{g} vs {gu}");
            assert!((g.y - gv).abs() < 1e-2 * (1.0 + gv.abs()), "{g} vs {gv}");
        }
    }
}
