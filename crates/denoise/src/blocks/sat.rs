//! The box mean by summed-area table: each output is the mean over the `(2r+1)²` window cut at
//! the image border (the window shrinks, so a constant image stays constant up to the edge),
//! at a cost independent of `r`.
//!
//! The table is kept in `f64`: a window sum is a difference of two large prefix sums, and in
//! `f32` that difference loses the digits a guided filter's covariances need.

use super::{window, STRIP_ROWS};
use rayon::prelude::*;

/// A reusable summed-area table for `w × h` single-channel planes (one allocation for any
/// number of planes of that size).
#[derive(Debug)]
pub struct BoxMean {
    w: usize,
    h: usize,
    /// `(w + 1) × (h + 1)` prefix sums; row 0 and column 0 are zero.
    table: Vec<f64>,
}

impl BoxMean {
    /// A table for planes of `w × h` pixels.
    pub fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            table: vec![0.0; (w + 1) * (h + 1)],
        }
    }

    /// Writes the box mean of radius `r` of `src` into `out` (both `w × h`, row-major).
    pub fn apply(&mut self, src: &[f32], r: usize, out: &mut [f32]) {
        let (w, h) = (self.w, self.h);
        assert!(src.len() == w * h && out.len() == w * h, "plane size");
        if src.is_empty() {
            return;
        }
        let stride = w + 1;
        // Row prefix sums (independent rows), then a running sum down the columns.
        self.table[stride..]
            .par_chunks_mut(stride)
            .zip(src.par_chunks(w))
            .for_each(|(t, row)| {
                let mut acc = 0.0f64;
                t[0] = 0.0;
                for (tx, &v) in t[1..].iter_mut().zip(row) {
                    acc += f64::from(v);
                    *tx = acc;
                }
            });
        for y in 1..h {
            let (above, rest) = self.table.split_at_mut((y + 1) * stride);
            let prev = &above[y * stride..];
            for (c, &p) in rest[..stride].iter_mut().zip(prev) {
                *c += p;
            }
        }
        let table = &self.table;
        out.par_chunks_mut(w * STRIP_ROWS)
            .enumerate()
            .for_each(|(s, strip)| {
                for (i, orow) in strip.chunks_mut(w).enumerate() {
                    let y = s * STRIP_ROWS + i;
                    let (y0, y1) = window(y, r, h);
                    let top = &table[y0 * stride..(y0 + 1) * stride];
                    let bottom = &table[(y1 + 1) * stride..(y1 + 2) * stride];
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
