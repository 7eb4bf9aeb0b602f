//! The `Accel` seam: the only interface through which integrators query geometry.
//!
//! Implementations live in `rt-accel` (binned-SAH BVH now; QBVH and IOSP later). Integrators
//! take `&dyn Accel`: one virtual call per ray is noise next to the traversal itself, and it keeps
//! the integrators independent of which structure the user picked.

use crate::{Aabb, Ray};
use glam::Vec3;

/// A closest-hit result: primitive index (in the scene's triangle order) and the hit's
/// parametric distance and barycentrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the triangle in scene order.
    pub prim: u32,
    /// Barycentric weight of vertex 1.
    pub b1: f32,
    /// Barycentric weight of vertex 2.
    pub b2: f32,
}

/// Counts of traversal work, for benchmarks and for comparing structures. Only implementations
/// that override [`Accel::intersect_counted`] fill them in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounters {
    /// Boxes tested: every child box of every inner node visited (a four-wide node counts its
    /// occupied slots), plus the root's bounds.
    pub nodes_visited: u64,
    /// Leaves entered (their triangles then tested).
    pub leaves_visited: u64,
    /// Ray–triangle tests performed.
    pub prims_tested: u64,
}

impl std::ops::AddAssign for TraversalCounters {
    fn add_assign(&mut self, o: Self) {
        self.nodes_visited += o.nodes_visited;
        self.leaves_visited += o.leaves_visited;
        self.prims_tested += o.prims_tested;
    }
}

/// A ray-query acceleration structure over the scene's triangles.
pub trait Accel: Send + Sync {
    /// Short name for reports ("bvh", "brute-force", ...).
    fn name(&self) -> &str;

    /// Closest hit with `t ∈ (0, t_max]`.
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit>;

    /// True if anything is hit with `t ∈ (0, t_max]`. Implementations should stop at the first hit.
    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.intersect(ray, t_max).is_some()
    }

    /// Occlusion of a shadow ray whose light-side endpoint is `target` (the light sample the
    /// ray goes toward). Always the same answer as [`Accel::occluded`]; structures with a
    /// shadow cache use `target` to start where the last occluder toward the same light region
    /// was found.
    fn occluded_toward(&self, ray: &Ray, t_max: f32, target: Vec3) -> bool {
        let _ = target;
        self.occluded(ray, t_max)
    }

    /// Like [`Accel::occluded_toward`], also counting work into `counters` if the structure
    /// supports it.
    fn occluded_toward_counted(
        &self,
        ray: &Ray,
        t_max: f32,
        target: Vec3,
        counters: &mut TraversalCounters,
    ) -> bool {
        let _ = counters;
        self.occluded_toward(ray, t_max, target)
    }

    /// Bounds of all geometry.
    fn bounds(&self) -> Aabb;

    /// Bytes of memory held by the structure (nodes and any primitive copies it keeps).
    fn memory_bytes(&self) -> usize;

    /// Like [`Accel::intersect`], also counting work into `counters` if the structure supports it.
    fn intersect_counted(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
    ) -> Option<Hit> {
        let _ = counters;
        self.intersect(ray, t_max)
    }

    /// True if [`Accel::intersect_counted`] really counts.
    fn counts_traversal(&self) -> bool {
        false
    }
}
