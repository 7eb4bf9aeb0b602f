//! The uniform grid: build (Cleary's resolution, conservative binning) and the `Accel` impl.

mod dda;

use super::domain::{cleary, padded_bounds, Domain};
use super::lists::{bin, Lists};
use super::{check_count, check_positive, Binning, GridError};
use glam::Vec3;
use rt_core::{Aabb, Accel};

/// Knobs of [`UniformGrid::build`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformGridParams {
    /// Cleary's density λ: about `λ N` cells for `N` triangles (3 in seed 002).
    pub lambda: f32,
    /// Largest number of cells per axis (at least 1).
    pub max_resolution: u32,
    /// How triangles are assigned to cells.
    pub binning: Binning,
}

impl Default for UniformGridParams {
    fn default() -> Self {
        Self {
            lambda: 3.0,
            max_resolution: 512,
            binning: Binning::Exact,
        }
    }
}

/// A uniform grid over triangles, walked by 3D-DDA (see the [module documentation](super)).
#[derive(Clone, Debug)]
pub struct UniformGrid {
    /// `None` for a scene without a finite triangle.
    domain: Option<Domain>,
    lists: Lists,
    triangles: Vec<[Vec3; 3]>,
}

impl UniformGrid {
    /// Builds the grid over `triangles`, whose indices become [`Hit::prim`](rt_core::Hit::prim). Any triangles are
    /// accepted; those with a non-finite vertex are never hit.
    pub fn build(triangles: &[[Vec3; 3]], params: &UniformGridParams) -> Result<Self, GridError> {
        check_count(triangles.len())?;
        check_positive("lambda", params.lambda)?;
        let bounds = padded_bounds(triangles);
        if bounds.is_empty() {
            return Ok(Self {
                domain: None,
                lists: Lists::default(),
                triangles: triangles.to_vec(),
            });
        }
        let res = cleary(
            bounds.extent().as_dvec3(),
            triangles.len(),
            params.lambda as f64,
            params.max_resolution.clamp(1, 1 << 16),
        );
        let domain = Domain::new(bounds, res);
        let pairs = bin(
            triangles,
            0..triangles.len() as u32,
            &domain,
            domain.diagonal(),
            params.binning,
        );
        let lists = Lists::from_pairs(domain.cell_count(), &pairs)?;
        Ok(Self {
            domain: Some(domain),
            lists,
            triangles: triangles.to_vec(),
        })
    }

    /// Cells per axis (`[0; 3]` for an empty scene).
    pub fn resolution(&self) -> [u32; 3] {
        self.domain.map_or([0; 3], |d| d.res)
    }

    /// The triangles (caller indices, increasing) listed in cell `c`, or `None` outside the grid.
    pub fn cell_triangles(&self, c: [u32; 3]) -> Option<&[u32]> {
        let d = self.domain.as_ref()?;
        (0..3)
            .all(|a| c[a] < d.res[a])
            .then(|| self.lists.get(d.index(c)))
    }

    /// The box of cell `c`, as the traversal computes its faces.
    pub fn cell_bounds(&self, c: [u32; 3]) -> Option<Aabb> {
        let d = self.domain.as_ref()?;
        (0..3)
            .all(|a| c[a] < d.res[a])
            .then(|| d.cell_aabb(c, c.map(|x| x + 1)))
    }

    /// Number of triangle references in all lists.
    pub fn references(&self) -> usize {
        self.lists.indices.len()
    }

    /// Bytes of the cells and lists (offsets and indices), without the triangle copies.
    pub fn structure_bytes(&self) -> usize {
        self.lists.bytes()
    }
}

impl Accel for UniformGrid {
    fn name(&self) -> &str {
        "uniform-grid"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.domain.map_or(Aabb::EMPTY, |d| Aabb::new(d.min, d.max))
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes() + std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(UniformGrid::structure_bytes(self))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
