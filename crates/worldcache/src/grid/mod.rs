//! The fixed-grid baseline (Binder, Fricke & Keller, "Massively Parallel Path Space
//! Filtering", 2019): positions quantised to cells of edge `s0 / 2^lod`, one cached point per
//! cell at its centre. Binder's selection (tangent-space jitter of the query before
//! quantising) and the thesis' fixed grid + barycentric variant are both selections over
//! these points ([`crate::Selection`]), so the grid shares the selection, table and
//! reconstruction code with [`crate::ImplicitPoints`].
//!
//! Matched density (thesis §3.1): implicit points at LOD `L-1` have one point per LOD-`L`
//! grid cell, so `FixedGrid::new(s0, L)` is compared with `ImplicitPoints::new(s0, L - 1)`.
//!
//! Deviations from Binder: no normal or level-of-detail from the ray cone in the key (normals
//! are an option of the cache), and no screen-space filter: reconstruction is the same
//! world-space Shepard filter as for implicit points (as in the thesis' comparison).

use crate::discretisation::{
    for_each_in_range, for_each_offset, visit_pruned, voxel_of, Connectivity, Discretisation,
};
use crate::key::{Key, KeyKind, KeyParts, MAX_LEVEL};
use glam::{IVec3, Vec3};

/// Cell centres of a uniform grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedGrid {
    /// Edge of a level-0 cell (world units).
    pub s0: f32,
    /// Level (cell edge `s0 / 2^lod`).
    pub lod: u32,
}

impl FixedGrid {
    /// The grid of level `lod` under level-0 edge `s0`.
    pub fn new(s0: f32, lod: u32) -> Self {
        Self {
            s0,
            lod: lod.min(MAX_LEVEL),
        }
    }

    /// Edge of a cell.
    #[inline]
    pub fn edge(&self) -> f32 {
        self.s0 / (1u64 << self.lod) as f32
    }

    /// The centre of cell `c` and its key (`None` outside the key range).
    #[inline]
    pub fn cell_point(&self, c: IVec3) -> Option<(Vec3, Key)> {
        let key = Key::pack(KeyParts {
            kind: KeyKind::Grid,
            level: self.lod,
            voxel: c,
            octant: 0,
            normal_bin: 0,
        })?;
        Some(((c.as_vec3() + Vec3::splat(0.5)) * self.edge(), key))
    }
}

impl Discretisation for FixedGrid {
    fn kind(&self) -> KeyKind {
        KeyKind::Grid
    }

    fn spacing(&self) -> f32 {
        self.edge()
    }

    fn voxel_edge(&self) -> f32 {
        self.edge()
    }

    #[inline]
    fn for_each_candidate<F: FnMut(Vec3, Key)>(&self, x: Vec3, c: Connectivity, mut f: F) {
        let cell = voxel_of(x, self.edge());
        for_each_offset(1, |d| {
            if c.contains(d) {
                if let Some((p, k)) = self.cell_point(cell + d) {
                    f(p, k);
                }
            }
        });
    }

    #[inline]
    fn for_each_candidate_pruned<F: FnMut(Vec3, Key) -> f32>(
        &self,
        x: Vec3,
        c: Connectivity,
        mut f: F,
    ) {
        let mut bound = f32::INFINITY;
        visit_pruned(x, self.edge(), c, |cell| {
            if let Some((p, k)) = self.cell_point(cell) {
                bound = f(p, k);
            }
            bound
        });
    }

    #[inline]
    fn for_each_near<F: FnMut(Vec3, Key)>(&self, x: Vec3, distance: f32, mut f: F) {
        // Exactly the cells whose centre lies in the box [x - distance, x + distance].
        let edge = self.edge();
        let lo = ((x - Vec3::splat(distance)) / edge - Vec3::splat(0.5))
            .ceil()
            .as_ivec3();
        let hi = ((x + Vec3::splat(distance)) / edge - Vec3::splat(0.5))
            .floor()
            .as_ivec3();
        for_each_in_range(lo, hi, |c| {
            if let Some((p, k)) = self.cell_point(c) {
                f(p, k);
            }
        });
    }
}
