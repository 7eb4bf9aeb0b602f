//! Structure-of-arrays copies of what the À-Trous iterations read, for the row code of
//! [`super::atrous_avx2`]: per frame the guide features ([`GuidePlanes`]), per level both
//! signals' colour, variance and luminance ([`LevelPlanes`]).
//!
//! Rows are interleaved: row `y` of plane `k` is the `(y·planes + k)`-th run of `len` floats,
//! so one output row of every plane is one contiguous slice that rayon can hand to a thread.
//! A run is a zero margin, the row padded to whole vectors of 8 (`stride`), another margin: a
//! tap up to `margin` pixels left or right of a vector is an in-bounds load that reads group 0
//! (no tap is taken from it) and finite zeros outside the image. The buffers are kept across
//! frames and only reallocated (zeroed) when the size changes; margins are never written.

use super::atrous::{sigma_l, Signals};
use super::features::{Class, Features};
use super::params::SvgfParams;
use rayon::prelude::*;
use rt_core::color::luminance;

/// Planes of [`GuidePlanes`].
pub(crate) const GROUP: usize = 0;
pub(crate) const DEPTH: usize = 1;
pub(crate) const Z_SCALE: usize = 2;
pub(crate) const Z_EPS: usize = 3;
pub(crate) const NX: usize = 4;
pub(crate) const NY: usize = 5;
pub(crate) const NZ: usize = 6;
pub(crate) const SPATIAL: usize = 7;
pub(crate) const SIGMA_L: usize = 8;
pub(crate) const GUIDE_PLANES: usize = 9;

/// Planes of one signal in [`LevelPlanes`]: red, green, blue, variance, luminance.
pub(crate) const LEVEL_PLANES: usize = 10;
/// Offset of signal `s`'s planes.
pub(crate) const fn signal(s: usize) -> usize {
    5 * s
}
pub(crate) const R: usize = 0;
pub(crate) const G: usize = 1;
pub(crate) const B: usize = 2;
pub(crate) const VAR: usize = 3;
pub(crate) const LUM: usize = 4;

/// Group of a pixel as the À-Trous compares it: taps count only within one group.
fn group(c: Class) -> f32 {
    match c {
        Class::Sky => 0.0,
        Class::Mirror => 2.0,
        _ => 1.0,
    }
}

/// Width rounded up to whole vectors.
fn stride_of(w: usize) -> usize {
    w.div_ceil(8) * 8
}

/// Margin for taps up to `2·max_step` pixels from a pixel.
pub(crate) fn margin_for(max_step: usize) -> usize {
    (2 * max_step).max(8).div_ceil(8) * 8
}

/// Layout of a set of interleaved planes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Layout {
    pub(crate) w: usize,
    pub(crate) h: usize,
    /// Row length padded to whole vectors.
    pub(crate) stride: usize,
    /// Zero columns left and right of each row.
    pub(crate) margin: usize,
    /// `margin + stride + margin`.
    pub(crate) len: usize,
}

impl Layout {
    fn new(w: usize, h: usize, margin: usize) -> Self {
        let stride = stride_of(w);
        Self {
            w,
            h,
            stride,
            margin,
            len: stride + 2 * margin,
        }
    }

    /// Index of column 0 of row `y` of plane `k` of `planes`.
    #[inline]
    fn at(&self, planes: usize, k: usize, y: usize) -> usize {
        (y * planes + k) * self.len + self.margin
    }
}

/// Reallocates `data` zeroed for `size` floats if `layout` changed.
fn reshape(current: &mut Layout, data: &mut Vec<f32>, layout: Layout, size: usize) {
    if *current != layout || data.len() != size {
        *current = layout;
        data.clear();
        data.resize(size, 0.0);
    }
}

/// Per-pixel constants of every iteration of one frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct GuidePlanes {
    pub(crate) layout: Layout,
    /// `GUIDE_PLANES` interleaved planes: [`GROUP`] (0 sky, 1 surface, 2 mirror), [`DEPTH`],
    /// [`Z_SCALE`] (σ_z·|∇z|), [`Z_EPS`] (10⁻³·z), the normal [`NX`], [`NY`], [`NZ`],
    /// [`SPATIAL`] (`2s²` of Eq. 6's Gaussian, 0 where none) and [`SIGMA_L`] (Eq. 8's σ_l).
    pub(crate) data: Vec<f32>,
    /// Whether any pixel has an Eq. 6 Gaussian.
    pub(crate) any_spatial: bool,
}

impl GuidePlanes {
    /// Index of column 0 of row `y` of plane `k`.
    #[inline]
    pub(crate) fn row(&self, k: usize, y: usize) -> usize {
        self.layout.at(GUIDE_PLANES, k, y)
    }

    /// Fills the planes from the frame's features (the same arithmetic as the per-pixel
    /// code of [`super::atrous`], so both give the same bits), with margins for taps up to
    /// `2·max_step` pixels away.
    pub(crate) fn fill(&mut self, f: &Features, p: &SvgfParams, lengths: &[f32], max_step: usize) {
        let (w, h) = (f.w, f.h);
        let layout = Layout::new(w, h, margin_for(max_step));
        reshape(
            &mut self.layout,
            &mut self.data,
            layout,
            GUIDE_PLANES * h * layout.len,
        );
        let (len, margin) = (layout.len, layout.margin);
        self.any_spatial = self
            .data
            .par_chunks_mut(GUIDE_PLANES * len)
            .enumerate()
            .map(|(y, rows)| {
                let mut any = false;
                for x in 0..w {
                    let i = y * w + x;
                    let z = f.depth[i];
                    let n = f.normal[i];
                    let spatial = f.sigma_spatial[i];
                    let d = if spatial > 0.0 {
                        let s = (2.0 * spatial).max(1e-3);
                        any = true;
                        2.0 * s * s
                    } else {
                        0.0
                    };
                    let values = [
                        group(f.class[i]),
                        z,
                        p.sigma_z * f.depth_step[i],
                        1e-3 * z,
                        n.x,
                        n.y,
                        n.z,
                        d,
                        sigma_l(p, lengths[i]),
                    ];
                    for (k, v) in values.into_iter().enumerate() {
                        rows[k * len + margin + x] = v;
                    }
                }
                any
            })
            .reduce(|| false, |a, b| a | b);
    }
}

/// Both signals of one level.
#[derive(Clone, Debug, Default)]
pub(crate) struct LevelPlanes {
    pub(crate) layout: Layout,
    /// `LEVEL_PLANES` interleaved planes, per signal `s` at [`signal`]`(s)` + [`R`], [`G`],
    /// [`B`], [`VAR`], [`LUM`].
    pub(crate) data: Vec<f32>,
}

impl LevelPlanes {
    /// Index of column 0 of row `y` of plane `k`.
    #[inline]
    pub(crate) fn row(&self, k: usize, y: usize) -> usize {
        self.layout.at(LEVEL_PLANES, k, y)
    }

    /// Makes room for a level of `layout` (contents unspecified, margins zero).
    pub(crate) fn reshape(&mut self, layout: Layout) {
        reshape(
            &mut self.layout,
            &mut self.data,
            layout,
            LEVEL_PLANES * layout.h * layout.len,
        );
    }

    /// Copies `signals` (of the size of `layout`) in, with their luminances.
    pub(crate) fn load(&mut self, layout: Layout, signals: &[Signals]) {
        self.reshape(layout);
        let (w, len, margin) = (layout.w, layout.len, layout.margin);
        self.data
            .par_chunks_mut(LEVEL_PLANES * len)
            .enumerate()
            .for_each(|(y, rows)| {
                for x in 0..w {
                    let px = &signals[y * w + x];
                    for s in 0..2 {
                        let c = px.colour[s];
                        let values = [c.x, c.y, c.z, px.variance[s], luminance(c)];
                        for (k, v) in values.into_iter().enumerate() {
                            rows[(signal(s) + k) * len + margin + x] = v;
                        }
                    }
                }
            });
    }

    /// Pixel `(x, y)` as [`Signals`].
    #[inline]
    pub(crate) fn get(&self, x: usize, y: usize) -> Signals {
        let v = |k: usize| self.data[self.row(k, y) + x];
        let colour = |s: usize| {
            let o = signal(s);
            rt_core::Rgb::new(v(o + R), v(o + G), v(o + B))
        };
        Signals {
            colour: [colour(0), colour(1)],
            variance: [v(signal(0) + VAR), v(signal(1) + VAR)],
        }
    }

    /// Copies the level out.
    pub(crate) fn store(&self, out: &mut [Signals]) {
        let w = self.layout.w;
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                *o = self.get(x, y);
            }
        });
    }

    /// True if every colour and variance is finite: then a tap whose weight is 0 adds exactly
    /// nothing, which the vector code relies on instead of skipping it as the per-pixel code
    /// does.
    pub(crate) fn finite(&self) -> bool {
        (0..self.layout.h).into_par_iter().all(|y| {
            (0..2).all(|s| {
                (R..=VAR).all(|k| {
                    let a = self.row(signal(s) + k, y);
                    // A fold, not `all`: it vectorises.
                    self.data[a..a + self.layout.w]
                        .iter()
                        .fold(true, |ok, v| ok & v.is_finite())
                })
            })
        })
    }
}
