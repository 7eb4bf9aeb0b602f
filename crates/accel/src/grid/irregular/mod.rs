//! The irregular grid of Pérard-Gayot, Kalojanov and Slusallek (2017): the structure, its
//! `Accel` impl and its invariants. The build is in [`build`], [`merge`] and [`expand`], the
//! walk in [`traverse`].

mod build;
mod expand;
mod merge;
mod traverse;

use super::domain::{finite, Domain};
use super::{Binning, GridError};
use crate::ValidationError;
use glam::Vec3;
use rt_core::{Aabb, Accel};

/// Knobs of [`IrregularGrid::build`]; defaults as explained in the [module documentation](super).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IrregularGridParams {
    /// Cleary density of the top level (λ₁).
    pub lambda_top: f32,
    /// Cleary density of the second level (λ₂), per top cell.
    pub lambda_sub: f32,
    /// Deepest second-level subdivision: `2^max_depth` cells per axis in a top cell (at most 10).
    pub max_depth: u32,
    /// SAH cost of visiting a cell (`C_t`), relative to `intersection_cost`.
    pub traversal_cost: f32,
    /// SAH cost of one ray–triangle test (`C_i`).
    pub intersection_cost: f32,
    /// Whether to merge cells at all (off: the plain two-level grid, for comparisons).
    pub merge: bool,
    /// Rounds of expansion (each over x, y and z, both directions); 0 for none.
    pub expansion_passes: u32,
    /// How triangles are assigned to cells.
    pub binning: Binning,
}

impl Default for IrregularGridParams {
    fn default() -> Self {
        Self {
            lambda_top: 0.12,
            lambda_sub: 2.4,
            max_depth: 3,
            traversal_cost: 1.0,
            intersection_cost: 1.0,
            merge: true,
            expansion_passes: 3,
            binning: Binning::Exact,
        }
    }
}

/// A box of virtual cells: `lo..hi` per axis, `hi` exclusive.
type VBox = [u16; 6];

/// An irregular grid over triangles (see the [module documentation](super)).
#[derive(Clone, Debug)]
pub struct IrregularGrid {
    /// The virtual grid; `None` for a scene without a finite triangle.
    domain: Option<Domain>,
    /// The cell owning each virtual cell.
    map: Vec<u32>,
    /// Per cell, what the traversal reads: the expanded box it leaves the cell by and the
    /// cell's range of `indices`, side by side so that a cell costs one cache line.
    records: Vec<Record>,
    /// Per cell, the box it was merged into (the virtual cells `map` sends to it).
    boxes: Vec<VBox>,
    /// The cells' triangle lists, one after another.
    indices: Vec<u32>,
    triangles: Vec<[Vec3; 3]>,
}

/// A cell as the traversal reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Record {
    expanded: VBox,
    start: u32,
    end: u32,
}

/// One cell of an [`IrregularGrid`], in virtual-cell coordinates and in space.
#[derive(Clone, Copy, Debug)]
pub struct IrregularCell<'a> {
    /// First virtual cell of the cell's own box.
    pub lo: [u32; 3],
    /// One past its last virtual cell.
    pub hi: [u32; 3],
    /// First virtual cell of the expanded box.
    pub expanded_lo: [u32; 3],
    /// One past the last virtual cell of the expanded box.
    pub expanded_hi: [u32; 3],
    /// The cell's own box in space.
    pub bounds: Aabb,
    /// The expanded box in space.
    pub expanded_bounds: Aabb,
    /// Its triangles (caller indices, increasing).
    pub triangles: &'a [u32],
}

fn unpack(b: &VBox) -> ([u32; 3], [u32; 3]) {
    (
        [b[0], b[1], b[2]].map(u32::from),
        [b[3], b[4], b[5]].map(u32::from),
    )
}

impl IrregularGrid {
    /// Builds the grid over `triangles`, whose indices become [`Hit::prim`](rt_core::Hit::prim). Any triangles are
    /// accepted; those with a non-finite vertex are never hit.
    pub fn build(triangles: &[[Vec3; 3]], params: &IrregularGridParams) -> Result<Self, GridError> {
        build::build(triangles, params)
    }

    /// Virtual cells per axis (`[0; 3]` for an empty scene).
    pub fn virtual_resolution(&self) -> [u32; 3] {
        self.domain.map_or([0; 3], |d| d.res)
    }

    /// Number of cells after merging.
    pub fn cell_count(&self) -> usize {
        self.boxes.len()
    }

    /// Cell `i`.
    pub fn cell(&self, i: usize) -> Option<IrregularCell<'_>> {
        let d = self.domain.as_ref()?;
        let (lo, hi) = unpack(self.boxes.get(i)?);
        let (expanded_lo, expanded_hi) = unpack(&self.records[i].expanded);
        Some(IrregularCell {
            lo,
            hi,
            expanded_lo,
            expanded_hi,
            bounds: d.cell_aabb(lo, hi),
            expanded_bounds: d.cell_aabb(expanded_lo, expanded_hi),
            triangles: self.list(i),
        })
    }

    /// All cells, in index order.
    pub fn cells(&self) -> impl Iterator<Item = IrregularCell<'_>> {
        (0..self.cell_count()).filter_map(|i| self.cell(i))
    }

    /// The cell owning virtual cell `v`, or `None` outside the grid.
    pub fn owner(&self, v: [u32; 3]) -> Option<usize> {
        let d = self.domain.as_ref()?;
        (0..3)
            .all(|a| v[a] < d.res[a])
            .then(|| self.map[d.index(v)] as usize)
    }

    /// The virtual cell holding `p` strictly inside (farther than 10⁻³ of a virtual cell from
    /// its faces), or `None` (outside the grid or near a face).
    pub fn virtual_cell_strictly_at(&self, p: Vec3) -> Option<[u32; 3]> {
        let d = self.domain.as_ref()?;
        let mut v = [0; 3];
        for a in 0..3 {
            let c = d.coord(a, p[a]);
            let (lo, hi) = (d.plane(a, c), d.plane(a, c + 1));
            let m = 1e-3 * (hi - lo);
            if !(p[a] > lo + m && p[a] < hi - m) {
                return None;
            }
            v[a] = c;
        }
        Some(v)
    }

    /// The triangles of cell `i`.
    fn list(&self, i: usize) -> &[u32] {
        let r = &self.records[i];
        self.indices
            .get(r.start as usize..r.end as usize)
            .unwrap_or_default()
    }

    /// Number of triangle references in all lists.
    pub fn references(&self) -> usize {
        self.indices.len()
    }

    /// Bytes of the virtual grid, the cells and the lists, without the triangle copies.
    pub fn structure_bytes(&self) -> usize {
        std::mem::size_of_val(self.map.as_slice())
            + std::mem::size_of_val(self.records.as_slice())
            + std::mem::size_of_val(self.boxes.as_slice())
            + std::mem::size_of_val(self.indices.as_slice())
    }

    /// Checks the invariants: every virtual cell maps to exactly one cell and the cells' own
    /// boxes tile the grid without overlap (each box is exactly the virtual cells mapped to
    /// it); lists are sorted and name real triangles; every expanded box holds its own box and
    /// covers only cells whose triangles are a subset of its own. Costs one pass over the
    /// virtual grid per cell's expanded box.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let fail = |problem: String| {
            Err(ValidationError {
                structure: "irregular-grid".into(),
                problem,
            })
        };
        let Some(d) = self.domain.as_ref() else {
            return if self.boxes.is_empty() && self.map.is_empty() {
                Ok(())
            } else {
                fail("cells without a domain".into())
            };
        };
        if self.map.len() != d.cell_count() {
            return fail(format!("map of {} for {:?}", self.map.len(), d.res));
        }
        let n = self.boxes.len();
        if self.records.len() != n {
            return fail("cell arrays of different lengths".into());
        }
        if let Some(v) = self.map.iter().position(|&c| c as usize >= n) {
            return fail(format!("virtual cell {v} maps to no cell"));
        }
        let mut volume = 0usize;
        for i in 0..n {
            let (lo, hi) = unpack(&self.boxes[i]);
            let (elo, ehi) = unpack(&self.records[i].expanded);
            if (0..3).any(|a| lo[a] >= hi[a] || hi[a] > d.res[a]) {
                return fail(format!("cell {i}: box {lo:?}..{hi:?}"));
            }
            if (0..3).any(|a| elo[a] > lo[a] || ehi[a] < hi[a] || ehi[a] > d.res[a]) {
                return fail(format!(
                    "cell {i}: expanded {elo:?}..{ehi:?} vs {lo:?}..{hi:?}"
                ));
            }
            volume += (0..3).map(|a| (hi[a] - lo[a]) as usize).product::<usize>();
            let list = self.list(i);
            if list.windows(2).any(|w| w[0] >= w[1])
                || list.iter().any(|&t| t as usize >= self.triangles.len())
            {
                return fail(format!("cell {i}: list not sorted or out of range"));
            }
            let mut bad = None;
            for_each_in(elo, ehi, |v| {
                let owner = self.map[d.index(v)] as usize;
                let inside = (0..3).all(|a| v[a] >= lo[a] && v[a] < hi[a]);
                if inside != (owner == i) {
                    bad.get_or_insert(format!("cell {i}: virtual cell {v:?} owned by {owner}"));
                } else if !is_subset(self.list(owner), list) {
                    bad.get_or_insert(format!(
                        "cell {i} expanded over {v:?} of cell {owner}, not a subset"
                    ));
                }
            });
            if let Some(b) = bad {
                return fail(b);
            }
        }
        if volume != self.map.len() {
            return fail(format!(
                "boxes cover {volume} of {} virtual cells",
                self.map.len()
            ));
        }
        Ok(())
    }

    /// Checks that every cell lists every triangle that overlaps its expanded box (by
    /// [`super::triangle_box_overlap`]); costs a test per cell and triangle, for tests.
    pub fn validate_coverage(&self) -> Result<(), ValidationError> {
        for (i, cell) in self.cells().enumerate() {
            for (t, tri) in self.triangles.iter().enumerate() {
                if !finite(tri) {
                    continue;
                }
                let b = cell.expanded_bounds;
                if super::triangle_box_overlap(tri, b.min, b.max)
                    && cell.triangles.binary_search(&(t as u32)).is_err()
                {
                    return Err(ValidationError {
                        structure: "irregular-grid".into(),
                        problem: format!("cell {i} misses triangle {t}"),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Calls `f` on every virtual cell of `lo..hi`.
fn for_each_in(lo: [u32; 3], hi: [u32; 3], mut f: impl FnMut([u32; 3])) {
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                f([x, y, z]);
            }
        }
    }
}

/// True if the sorted `a` is a subset of the sorted `b`.
fn is_subset(a: &[u32], b: &[u32]) -> bool {
    if a.len() > b.len() {
        return false;
    }
    let mut j = 0;
    for &x in a {
        while j < b.len() && b[j] < x {
            j += 1;
        }
        if j == b.len() || b[j] != x {
            return false;
        }
        j += 1;
    }
    true
}

impl Accel for IrregularGrid {
    fn name(&self) -> &str {
        "irregular-grid"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.domain.map_or(Aabb::EMPTY, |d| Aabb::new(d.min, d.max))
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes() + std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(IrregularGrid::structure_bytes(self))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subsets() {
        assert!(is_subset(&[], &[1]));
        assert!(is_subset(&[1, 3], &[1, 2, 3]));
        assert!(!is_subset(&[1, 4], &[1, 2, 3]));
        assert!(!is_subset(&[0], &[1, 2, 3]));
        assert!(!is_subset(&[1, 2], &[2]));
    }
}
