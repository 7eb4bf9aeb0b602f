//! An IOSP structure for callers that cannot reorder their triangles: hits are mapped back to
//! the caller's order through the permutation, at 4 bytes per triangle. The renderer reorders
//! the scene instead ([`crate::BuildInput::SceneToReorder`]) and stores nothing.

use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};

/// `inner` (built over permuted triangles) answering in the original triangle order.
pub struct Unpermuted<A> {
    inner: A,
    perm: Vec<u32>,
}

impl<A: Accel> Unpermuted<A> {
    /// `inner` and the permutation its build returned (`perm[i]`: the original index of its
    /// triangle `i`).
    pub fn new(inner: A, perm: Vec<u32>) -> Self {
        Self { inner, perm }
    }
}

impl<A: Accel> Accel for Unpermuted<A> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        self.inner.closest_hit(ray, t_max, counters).map(|mut h| {
            h.prim = self.perm[h.prim as usize];
            h
        })
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        self.inner.any_hit(ray, t_max, toward, counters)
    }

    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes() + std::mem::size_of_val(self.perm.as_slice())
    }

    /// The inner structure's only: the index map stands in for the caller reordering its
    /// per-triangle data, which the renderer does instead of keeping a map
    /// ([`crate::BuildInput::SceneToReorder`]); [`Accel::memory_bytes`] counts it.
    fn structure_bytes(&self) -> Option<usize> {
        self.inner.structure_bytes()
    }

    fn counts_traversal(&self) -> bool {
        self.inner.counts_traversal()
    }
}
