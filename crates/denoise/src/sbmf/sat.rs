//! Summed-area table of an RGBα layer (Crow 1984), in `f64` so that the box sums of large
//! images keep their precision: any box's sum is four lookups, whatever its size. SBMF's
//! sweep-blur builds one per layer and reuses it for every filter scale, which is what makes
//! step B's cost independent of the circle of confusion (thesis §4.3.2).

/// The table: entry `(x, y)` of the `(w+1) × (h+1)` grid is the sum over pixels `< x`, `< y`.
pub(crate) struct Sat {
    w: usize,
    h: usize,
    t: Vec<[f64; 4]>,
}

impl Sat {
    /// An empty table for `w × h` layers (allocated once, rebuilt per layer).
    pub fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            t: vec![[0.0; 4]; (w + 1) * (h + 1)],
        }
    }

    /// Rebuilds the table from `layer` (`w × h`, row-major).
    pub fn build(&mut self, layer: &[[f32; 4]]) {
        let stride = self.w + 1;
        for y in 0..self.h {
            let mut run = [0.0f64; 4];
            for x in 0..self.w {
                let p = layer[y * self.w + x];
                for c in 0..4 {
                    run[c] += p[c] as f64;
                }
                let above = self.t[y * stride + x + 1];
                self.t[(y + 1) * stride + x + 1] = std::array::from_fn(|c| above[c] + run[c]);
            }
        }
    }

    /// Mean over the box of half-width `b` around `(x, y)`, clipped to the image (four
    /// lookups).
    #[inline]
    pub fn box_mean(&self, x: usize, y: usize, b: usize) -> [f32; 4] {
        let stride = self.w + 1;
        let (x0, y0) = (x.saturating_sub(b), y.saturating_sub(b));
        let (x1, y1) = (
            x.saturating_add(b).saturating_add(1).min(self.w),
            y.saturating_add(b).saturating_add(1).min(self.h),
        );
        let (a, bb, c, d) = (
            self.t[y0 * stride + x0],
            self.t[y0 * stride + x1],
            self.t[y1 * stride + x0],
            self.t[y1 * stride + x1],
        );
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        std::array::from_fn(|k| ((d[k] - bb[k] - c[k] + a[k]) / area) as f32)
    }
}

/// Lookups per [`Sat::box_mean`].
pub(crate) const LOOKUPS_PER_BOX: u64 = 4;
