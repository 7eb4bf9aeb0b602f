//! Summed-area tables (Crow 1984): any box's sum is four lookups, whatever its size. One
//! table type for single-channel planes (the box mean below, for the guided filter) and RGBα
//! layers (SBMF's sweep-blur, which reuses one per layer for every filter scale).
//!
//! The table is kept in `f64`: a window sum is a difference of two large prefix sums, and in
//! `f32` that difference loses the digits a guided filter's covariances need.
//!
//! [`BoxMean`]: each output is the mean over the `(2r+1)²` window cut at the image border (the
//! window shrinks, so a constant image stays constant up to the edge), at a cost independent
//! of `r`.

use super::{window, STRIP_ROWS};
use rayon::prelude::*;

/// What a [`SummedAreaTable`] sums: `f64` per channel of an `f32` source pixel.
pub trait SatValue: Copy + Send + Sync {
    /// A source pixel.
    type Source: Copy + Sync;
    /// The empty sum.
    const ZERO: Self;
    /// A source pixel in `f64`.
    fn widen(p: Self::Source) -> Self;
    /// Channel-wise sum.
    fn add(self, o: Self) -> Self;
}

impl SatValue for f64 {
    type Source = f32;
    const ZERO: Self = 0.0;
    #[inline(always)]
    fn widen(p: f32) -> Self {
        f64::from(p)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
}

impl SatValue for [f64; 4] {
    type Source = [f32; 4];
    const ZERO: Self = [0.0; 4];
    #[inline(always)]
    fn widen(p: [f32; 4]) -> Self {
        p.map(f64::from)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        std::array::from_fn(|c| self[c] + o[c])
    }
}

/// A reusable summed-area table for `w × h` images (one allocation for any number of images
/// of that size): entry `(x, y)` of the `(w + 1) × (h + 1)` grid is the sum over the pixels
/// left of `x` and above `y`; row 0 and column 0 are zero.
#[derive(Debug)]
pub struct SummedAreaTable<T> {
    w: usize,
    h: usize,
    table: Vec<T>,
}

impl<T: SatValue> SummedAreaTable<T> {
    /// An empty table for images of `w × h` pixels.
    pub fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            table: vec![T::ZERO; (w + 1) * (h + 1)],
        }
    }

    /// Rebuilds the table from `src` (`w × h`, row-major).
    pub fn build(&mut self, src: &[T::Source]) {
        let (w, h) = (self.w, self.h);
        assert_eq!(src.len(), w * h, "image size");
        if src.is_empty() {
            return;
        }
        let stride = w + 1;
        // Row prefix sums (independent rows), then a running sum down the columns.
        self.table[stride..]
            .par_chunks_mut(stride)
            .zip(src.par_chunks(w))
            .for_each(|(t, row)| {
                let mut acc = T::ZERO;
                t[0] = T::ZERO;
                for (tx, &v) in t[1..].iter_mut().zip(row) {
                    acc = acc.add(T::widen(v));
                    *tx = acc;
                }
            });
        for y in 1..h {
            let (above, rest) = self.table.split_at_mut((y + 1) * stride);
            let prev = &above[y * stride..];
            for (c, &p) in rest[..stride].iter_mut().zip(prev) {
                *c = c.add(p);
            }
        }
    }

    /// Row `y` of the grid (`w + 1` entries): the sums over the pixels above `y`.
    #[inline(always)]
    pub fn row(&self, y: usize) -> &[T] {
        let stride = self.w + 1;
        &self.table[y * stride..(y + 1) * stride]
    }
}

/// The box mean of single-channel planes by a [`SummedAreaTable`].
#[derive(Debug)]
pub struct BoxMean {
    table: SummedAreaTable<f64>,
}

impl BoxMean {
    /// A table for planes of `w × h` pixels.
    pub fn new(w: usize, h: usize) -> Self {
        Self {
            table: SummedAreaTable::new(w, h),
        }
    }

    /// Writes the box mean of radius `r` of `src` into `out` (both `w × h`, row-major).
    pub fn apply(&mut self, src: &[f32], r: usize, out: &mut [f32]) {
        let (w, h) = (self.table.w, self.table.h);
        assert!(src.len() == w * h && out.len() == w * h, "plane size");
        if src.is_empty() {
            return;
        }
        self.table.build(src);
        let table = &self.table;
        out.par_chunks_mut(w * STRIP_ROWS)
            .enumerate()
            .for_each(|(s, strip)| {
                for (i, orow) in strip.chunks_mut(w).enumerate() {
                    let y = s * STRIP_ROWS + i;
                    let (y0, y1) = window(y, r, h);
                    let top = table.row(y0);
                    let bottom = table.row(y1 + 1);
                    let rows = (y1 - y0 + 1) as f64;
                    for (x, o) in orow.iter_mut().enumerate() {
                        let (x0, x1) = window(x, r, w);
                        let sum = bottom[x1 + 1] - bottom[x0] - top[x1 + 1] + top[x0];
                        *o = (sum / (rows * (x1 - x0 + 1) as f64)) as f32;
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box mean by direct summation.
    fn direct(src: &[f32], w: usize, h: usize, r: usize) -> Vec<f32> {
        let mut out = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let ((x0, x1), (y0, y1)) = (window(x, r, w), window(y, r, h));
                let mut s = 0.0f64;
                for yy in y0..=y1 {
                    for xx in x0..=x1 {
                        s += f64::from(src[yy * w + xx]);
                    }
                }
                out[y * w + x] = (s / ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64) as f32;
            }
        }
        out
    }

    #[test]
    fn matches_direct_summation_at_every_radius_and_size() {
        for (w, h) in [(1, 1), (1, 5), (6, 1), (7, 5), (19, 23)] {
            let src: Vec<f32> = (0..w * h)
                .map(|i| (rt_core::sampler::hash_u32(i as u32) % 1000) as f32 * 0.01 - 3.0)
                .collect();
            let mut b = BoxMean::new(w, h);
            let mut out = vec![0.0; w * h];
            for r in [0, 1, 2, 5, 40] {
                b.apply(&src, r, &mut out);
                let want = direct(&src, w, h, r);
                for (a, e) in out.iter().zip(&want) {
                    assert!((a - e).abs() < 1e-5, "{w}x{h} r={r}: {a} vs {e}");
                }
            }
        }
    }
}
