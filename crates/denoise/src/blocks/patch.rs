//! Patch distances for non-local means, one search offset at a time: the caller gives the
//! per-pixel distance term between pixel `p` and `p + offset`, and the patch distance is that
//! term's box mean over the patch around `p` (Buades et al. 2005; computed per offset as in
//! Darbon et al. 2008 and Rousselle et al. 2012, so the cost per pixel and offset does not
//! grow with the patch size beyond a `2·patch + 1`-row column sum).
//!
//! Work is done by horizontal strips of rows: a strip computes the term on its rows plus the
//! patch margin above and below, so strips are independent and a rayon task per strip writes
//! only its own rows. The patch is cut at the image border (the mean is over the pixels inside).

use super::window;

/// Scratch buffers for one strip, allocated once per strip and reused for every offset.
#[derive(Debug, Default)]
pub struct PatchScratch {
    term: Vec<f32>,
    prefix: Vec<f64>,
    hsum: Vec<f32>,
    inv_cols: Vec<f32>,
    /// Each column's patch range `[a, b]`.
    cols: Vec<(usize, usize)>,
}

impl PatchScratch {
    /// Writes into `dist` (`(y1 - y0) × w`) the mean of the per-pixel term over the patch of
    /// radius `patch` around each pixel of rows `y0..y1` of a `w × h` image. `term(y, row)`
    /// fills `row` with the term of the pixels of row `y`; it is called for rows
    /// `y0 - patch..y1 + patch` (clamped to the image).
    pub fn patch_means(
        &mut self,
        (w, h): (usize, usize),
        (y0, y1): (usize, usize),
        patch: usize,
        term: impl Fn(usize, &mut [f32]),
        dist: &mut [f32],
    ) {
        debug_assert_eq!(dist.len(), (y1 - y0) * w);
        let ylo = y0.saturating_sub(patch);
        let yhi = (y1 + patch).min(h);
        let rows = yhi - ylo;
        self.term.resize(rows * w, 0.0);
        self.hsum.resize(rows * w, 0.0);
        self.prefix.resize(w + 1, 0.0);
        if self.cols.len() != w || self.cols.first() != Some(&window(0, patch, w)) {
            self.cols = (0..w).map(|x| window(x, patch, w)).collect();
            self.inv_cols = self
                .cols
                .iter()
                .map(|(a, b)| 1.0 / (b - a + 1) as f32)
                .collect();
        }
        for (i, row) in self.term.chunks_mut(w).enumerate() {
            term(ylo + i, row);
        }
        // Horizontal window sums from a per-row prefix sum (f64: a difference of prefixes).
        for (row, hs) in self.term.chunks(w).zip(self.hsum.chunks_mut(w)) {
            let mut acc = 0.0f64;
            for (p, &t) in self.prefix[1..].iter_mut().zip(row) {
                acc += f64::from(t);
                *p = acc;
            }
            for (o, &(a, b)) in hs.iter_mut().zip(&self.cols) {
                *o = (self.prefix[b + 1] - self.prefix[a]) as f32;
            }
        }
        // Vertical sums of the horizontal sums, then the mean.
        for (i, drow) in dist.chunks_mut(w).enumerate() {
            let y = y0 + i;
            let (a, b) = window(y, patch, h);
            drow.copy_from_slice(&self.hsum[(a - ylo) * w..(a - ylo + 1) * w]);
            for r in a + 1..=b {
                for (d, &s) in drow
                    .iter_mut()
                    .zip(&self.hsum[(r - ylo) * w..(r - ylo + 1) * w])
                {
                    *d += s;
                }
            }
            let inv_rows = 1.0 / (b - a + 1) as f32;
            for (d, &c) in drow.iter_mut().zip(&self.inv_cols) {
                *d *= c * inv_rows;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patch_means_match_direct_summation_in_every_strip() {
        let (w, h) = (9, 11);
        let term =
            |x: usize, y: usize| (rt_core::sampler::hash_u32((y * w + x) as u32) % 97) as f32;
        for patch in [0, 1, 3, 12] {
            let mut s = PatchScratch::default();
            for (y0, y1) in [(0, 4), (4, 8), (8, 11), (0, 11)] {
                let mut dist = vec![0.0; (y1 - y0) * w];
                let rows = |y: usize, row: &mut [f32]| {
                    for (x, t) in row.iter_mut().enumerate() {
                        *t = term(x, y);
                    }
                };
                s.patch_means((w, h), (y0, y1), patch, rows, &mut dist);
                for y in y0..y1 {
                    for x in 0..w {
                        let ((xa, xb), (ya, yb)) = (window(x, patch, w), window(y, patch, h));
                        let mut sum = 0.0;
                        for yy in ya..=yb {
                            for xx in xa..=xb {
                                sum += term(xx, yy);
                            }
                        }
                        let want = sum / ((xb - xa + 1) * (yb - ya + 1)) as f32;
                        let got = dist[(y - y0) * w + x];
                        assert!((got - want).abs() < 1e-4 * want.max(1.0), "{got} {want}");
                    }
                }
            }
        }
    }
}
