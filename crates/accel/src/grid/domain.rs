//! The box a grid covers, its resolution, and the cell faces both the builder and the traversal
//! use.

use glam::{DVec3, Vec3};
use rt_core::Aabb;

/// A box split into `res` equal cells per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Domain {
    pub min: Vec3,
    pub max: Vec3,
    pub res: [u32; 3],
    cell: Vec3,
    inv_cell: Vec3,
}

/// Bounds of the triangles with finite vertices (the others are never hit sensibly and are left
/// out of every cell), padded on every side by 10⁻³ of the largest extent so that a flat or
/// single-point scene still has a volume, and by a few ulps of its coordinates so that faces on
/// the scene's outer triangles are not rounded inside.
pub(crate) fn padded_bounds(triangles: &[[Vec3; 3]]) -> Aabb {
    let b = triangles
        .iter()
        .filter(|t| finite(t))
        .fold(Aabb::EMPTY, |b, t| b.union(Aabb::from_points(t)));
    if b.is_empty() {
        return b;
    }
    let ext = b.extent().max_element();
    let scale = b.min.abs().max(b.max.abs()).max_element();
    let pad = (1e-3 * ext).max(1e-5 * scale).max(1e-30);
    Aabb::new(b.min - Vec3::splat(pad), b.max + Vec3::splat(pad))
}

/// True if all three vertices are finite.
pub(crate) fn finite(t: &[Vec3; 3]) -> bool {
    t.iter().all(|v| v.is_finite())
}

/// Cleary's rule: `N_i = d_i ∛(λ n / V)`, rounded to nearest and clamped to `[1, max_axis]`.
pub(crate) fn cleary(extent: DVec3, n: usize, lambda: f64, max_axis: u32) -> [u32; 3] {
    let volume = extent.x * extent.y * extent.z;
    if n == 0 || volume.is_nan() || volume <= 0.0 || !volume.is_finite() {
        return [1; 3];
    }
    let k = (lambda * n as f64 / volume).cbrt();
    extent
        .to_array()
        .map(|d| ((d * k).round().max(1.0).min(max_axis as f64)) as u32)
}

impl Domain {
    pub fn new(bounds: Aabb, res: [u32; 3]) -> Self {
        let res_f = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let cell = (bounds.max - bounds.min) / res_f;
        Self {
            min: bounds.min,
            max: bounds.max,
            res,
            cell,
            inv_cell: cell.recip(),
        }
    }

    pub fn cell_count(&self) -> usize {
        self.res.iter().map(|&r| r as usize).product()
    }

    /// `[min.x, min.y, min.z, max.x, max.y, max.z]` for the slab test.
    pub fn planes(&self) -> [f32; 6] {
        [
            self.min.x, self.min.y, self.min.z, self.max.x, self.max.y, self.max.z,
        ]
    }

    /// The face plane `k` (of `0..=res`) on `axis`; the last is the box's own face exactly.
    #[inline(always)]
    pub fn plane(&self, axis: usize, k: u32) -> f32 {
        if k >= self.res[axis] {
            self.max[axis]
        } else {
            self.min[axis] + k as f32 * self.cell[axis]
        }
    }

    /// The cell coordinate of `x` on `axis`, clamped into the grid.
    #[inline(always)]
    pub fn coord(&self, axis: usize, x: f32) -> u32 {
        // `as` saturates (and sends NaN to 0), so no input can index outside.
        let c = ((x - self.min[axis]) * self.inv_cell[axis]).floor() as i64;
        c.clamp(0, self.res[axis] as i64 - 1) as u32
    }

    #[inline(always)]
    pub fn index(&self, c: [u32; 3]) -> usize {
        (c[2] as usize * self.res[1] as usize + c[1] as usize) * self.res[0] as usize
            + c[0] as usize
    }

    /// The box of cells `lo..hi` (exclusive), in double precision, as the traversal sees it.
    pub fn cell_box(&self, lo: [u32; 3], hi: [u32; 3]) -> (DVec3, DVec3) {
        let f = |k: [u32; 3]| DVec3::from_array([0, 1, 2].map(|a| self.plane(a, k[a]) as f64));
        (f(lo), f(hi))
    }

    /// The same box in single precision.
    pub fn cell_aabb(&self, lo: [u32; 3], hi: [u32; 3]) -> Aabb {
        let f = |k: [u32; 3]| Vec3::from_array([0, 1, 2].map(|a| self.plane(a, k[a])));
        Aabb::new(f(lo), f(hi))
    }

    /// How much cells are grown when binning (see the module documentation): 10⁻³ of a cell,
    /// and at least 16 ulps of the domain's coordinates.
    pub fn margin(&self) -> DVec3 {
        let scale = self.min.abs().max(self.max.abs()).max_element() as f64;
        let floor = 16.0 * f32::EPSILON as f64 * scale;
        self.cell.as_dvec3().map(|c| (1e-3 * c).max(floor))
    }

    /// Length of the diagonal, which bounds the distances hits are computed at.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).as_dvec3().length()
    }

    /// Range of cells (inclusive) that the box `lo..hi` grown by `margin` overlaps.
    pub fn cell_range(&self, lo: DVec3, hi: DVec3, margin: DVec3) -> ([u32; 3], [u32; 3]) {
        let (lo, hi) = (lo - margin, hi + margin);
        let a = [0, 1, 2].map(|a| self.coord(a, lo[a] as f32));
        let b = [0, 1, 2].map(|a| self.coord(a, hi[a] as f32));
        (a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cleary_gives_about_lambda_n_cells_proportional_to_extent() {
        let r = cleary(DVec3::new(4.0, 2.0, 1.0), 1000, 3.0, 512);
        let cells = r.iter().product::<u32>() as f64;
        assert!((cells / 3000.0 - 1.0).abs() < 0.2, "{r:?}");
        assert_eq!((r[0] as f64 / r[2] as f64).round(), 4.0);
        assert_eq!((r[1] as f64 / r[2] as f64).round(), 2.0);
        assert_eq!(cleary(DVec3::ONE, 0, 3.0, 512), [1; 3]);
        assert_eq!(cleary(DVec3::new(1.0, 1.0, 0.0), 10, 3.0, 512), [1; 3]);
    }

    #[test]
    fn coordinates_clamp_into_the_grid() {
        let d = Domain::new(Aabb::new(Vec3::ZERO, Vec3::ONE), [4, 4, 4]);
        assert_eq!(d.coord(0, -5.0), 0);
        assert_eq!(d.coord(0, 5.0), 3);
        assert_eq!(d.coord(0, f32::NAN), 0);
        assert_eq!(d.coord(0, 0.5), 2);
        assert_eq!(d.plane(0, 4), 1.0);
    }
}
