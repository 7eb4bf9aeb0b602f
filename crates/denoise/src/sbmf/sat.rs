//! The box mean of an RGBα layer by a summed-area table ([`SummedAreaTable`], in `f64` so
//! that the box sums of large images keep their precision). SBMF's sweep-blur builds one per
//! layer and reuses it for every filter scale, which is what makes step B's cost independent
//! of the circle of confusion (thesis §4.3.2).

use crate::blocks::sat::SummedAreaTable;

/// The table of one layer.
pub(crate) struct Sat {
    w: usize,
    h: usize,
    table: SummedAreaTable<[f64; 4]>,
}

impl Sat {
    /// An empty table for `w × h` layers (allocated once, rebuilt per layer).
    pub fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            table: SummedAreaTable::new(w, h),
        }
    }

    /// Rebuilds the table from `layer` (`w × h`, row-major).
    pub fn build(&mut self, layer: &[[f32; 4]]) {
        self.table.build(layer);
    }

    /// Mean over the box of half-width `b` around `(x, y)`, clipped to the image (four
    /// lookups).
    #[inline]
    pub fn box_mean(&self, x: usize, y: usize, b: usize) -> [f32; 4] {
        let (x0, y0) = (x.saturating_sub(b), y.saturating_sub(b));
        let (x1, y1) = (
            x.saturating_add(b).saturating_add(1).min(self.w),
            y.saturating_add(b).saturating_add(1).min(self.h),
        );
        let (top, bottom) = (self.table.row(y0), self.table.row(y1));
        let (a, bb, c, d) = (top[x0], top[x1], bottom[x0], bottom[x1]);
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        // This order of the four terms (not the box mean's) is the one SBMF's images were
        // made with.
        std::array::from_fn(|k| ((d[k] - bb[k] - c[k] + a[k]) / area) as f32)
    }
}

/// Lookups per [`Sat::box_mean`].
pub(crate) const LOOKUPS_PER_BOX: u64 = 4;
