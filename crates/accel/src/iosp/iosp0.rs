//! IOSP-0: the heap-ordered implicit BVH that is nothing but the permuted triangle array
//! (thesis §7.3).

use super::heap::{self, MAX_TRIANGLES};
use super::lanes::SlotTest;
use super::{bounds_of, IospError, TriBox};
use crate::traversal::{Closest, Counter, SlabRay};
use crate::wide::tri4::RayPrecomp4;
use crate::ValidationError;
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray};

/// The completely implicit IOSP hierarchy: a complete binary tree over the triangles, stored
/// as a heap inside the triangle array, with no nodes at all (see the [module](super) doc and
/// its permutation contract). Besides the triangles it keeps only the scene bounds (for
/// [`Accel::bounds`], and to clip each ray before the root) and which SIMD test the CPU runs.
#[derive(Clone, Debug)]
pub struct Iosp0 {
    triangles: Vec<[Vec3; 3]>,
    bounds: Aabb,
    lanes: SlotTest,
}

impl Iosp0 {
    /// Orders `triangles` into the heap. Returns the structure and the permutation applied:
    /// `perm[i]` is the index in `triangles` of the triangle at position `i` of
    /// [`Iosp0::triangles`], which is what [`Hit::prim`] reports. Any geometry is accepted
    /// (empty, degenerate, non-finite); only the count is limited.
    ///
    /// # Errors
    ///
    /// [`IospError::TooManyTriangles`] for more than `2^31` triangles.
    pub fn build(triangles: &[[Vec3; 3]]) -> Result<(Self, Vec<u32>), IospError> {
        if triangles.len() > MAX_TRIANGLES {
            return Err(IospError::TooManyTriangles {
                structure: "iosp0",
                count: triangles.len(),
                limit: MAX_TRIANGLES,
            });
        }
        let boxes: Vec<TriBox> = triangles.iter().map(TriBox::of).collect();
        let perm = heap::build(&boxes);
        let permuted = perm.iter().map(|&i| triangles[i as usize]).collect();
        Ok((
            Self {
                triangles: permuted,
                bounds: bounds_of(triangles),
                lanes: SlotTest::detect(),
            },
            perm,
        ))
    }

    /// The triangles in heap order: node `j` owns positions `2j` and `2j + 1`.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// Bytes of the structure beyond the triangles: none.
    pub fn structure_bytes(&self) -> usize {
        0
    }

    /// Number of nodes, `ceil(n / 2)`.
    pub fn node_count(&self) -> usize {
        self.triangles.len().div_ceil(2)
    }

    /// Number of levels of the tree, `floor(log2(ceil(n / 2))) + 1` (0 when empty).
    pub fn levels(&self) -> u32 {
        heap::levels(self.triangles.len())
    }

    /// Checks that every node's slab contains all triangles of its subtree.
    ///
    /// # Errors
    ///
    /// The first broken invariant.
    pub fn validate(&self) -> Result<(), ValidationError> {
        heap::check(&self.triangles).map_err(|problem| ValidationError {
            structure: "iosp0".into(),
            problem,
        })
    }

    #[inline(always)]
    fn traverse<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        // A NaN or infinite component would pass every slab; such a ray hits nothing.
        if !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let slab = SlabRay::new(ray);
        // The root's slab bounds one axis only; the scene box clips all three first.
        let (lo, hi) = (self.bounds.min, self.bounds.max);
        let planes = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z];
        counter.boxes(1);
        let interval = slab.interval(&planes, t_max)?;
        let pre = RayPrecomp4::new(ray);
        let mut closest = Closest::new(t_max);
        heap::traverse::<ANY_HIT, C>(
            &self.triangles,
            0,
            &slab,
            &pre,
            self.lanes,
            interval,
            t_max,
            &mut closest,
            counter,
        );
        closest.hit
    }
}

impl Accel for Iosp0 {
    fn name(&self) -> &str {
        "iosp0"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The triangles only: the structure itself takes no memory.
    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(Iosp0::structure_bytes(self))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
