//! The `Accel` seam: the only interface through which integrators query geometry.
//!
//! Implementations live in `rt-accel` (binary, four- and eight-wide BVHs, two-level and clustered
//! BVHs, grids, IOSP; `rt_accel::AccelSpec` names and builds them). Integrators
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
/// whose [`Accel::counts_traversal`] is true fill them in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounters {
    /// Boxes tested: every child box of every inner node visited (a four-wide node counts its
    /// occupied slots), plus the root's bounds where the structure tests them apart (`bvh8`
    /// does not: its root node's child boxes already bound the scene).
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
///
/// A structure implements two queries, [`Accel::closest_hit`] and [`Accel::any_hit`], once
/// each: both take optional [`TraversalCounters`], so benchmarks can count the work of the same
/// code that renders. An implementation dispatches on the option once per ray (e.g. to a
/// traversal generic over a counter whose uncounted form compiles to nothing), so the uncounted
/// path pays one branch per ray, not one per node. [`Accel::intersect`], [`Accel::occluded`] and
/// [`Accel::occluded_toward`] are the uncounted shorthands integrators call; they are not meant
/// to be overridden.
pub trait Accel: Send + Sync {
    /// Short name for reports ("bvh", "brute-force", ...).
    fn name(&self) -> &str;

    /// Closest hit with `t ∈ (0, t_max]`, counting work into `counters` when given (and
    /// [`Accel::counts_traversal`]).
    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit>;

    /// True if anything is hit with `t ∈ (0, t_max]`; implementations stop at the first hit.
    /// `toward` is the light-side endpoint of a shadow ray when there is one: structures with a
    /// shadow cache start where the last occluder toward the same light region was found. The
    /// answer never depends on it.
    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        let _ = toward;
        self.closest_hit(ray, t_max, counters).is_some()
    }

    /// Bounds of all geometry.
    fn bounds(&self) -> Aabb;

    /// Bytes of memory held by the structure (nodes and any primitive copies it keeps).
    fn memory_bytes(&self) -> usize;

    /// The part of [`Accel::memory_bytes`] that is the structure's own, beyond one copy of
    /// the triangles' vertices (36 bytes a triangle, in whatever layout): nodes, cells, index
    /// maps, padding. `None` if the structure does not tell them apart.
    fn structure_bytes(&self) -> Option<usize> {
        None
    }

    /// True if the queries really fill the counters they are given.
    fn counts_traversal(&self) -> bool {
        false
    }

    /// Moves the structure to `scene` as it is now (after [`crate::Scene::set_time`]) in
    /// place, if it can: two-level structures refit or rebuild their top level. False if the
    /// caller must build a new structure (flat structures, or a scene whose instances are not
    /// the ones the structure was built over).
    fn update(&mut self, scene: &crate::Scene) -> bool {
        let _ = scene;
        false
    }

    /// True if the structure places moving instances where they are at each ray's
    /// [`Ray::time`] (two-level structures), as motion blur needs; flat structures hold the
    /// scene as it is at one time and ignore it.
    fn interpolates_motion(&self) -> bool {
        false
    }

    /// Closest hits of a stream of rays, uncounted: `hits[i]` is what
    /// [`Accel::intersect`]`(&rays[i], t_max[i])` returns, whatever order or grouping the
    /// structure traces them in. Wavefront integrators hand over a whole stage's rays at once,
    /// so a structure may trace coherent ones as packets (as Embree's `rtcIntersect4/8/16` and
    /// ray streams do); the default traces them one by one.
    fn intersect_stream(&self, rays: &[Ray], t_max: &[f32], hits: &mut [Option<Hit>]) {
        for ((ray, &t), hit) in rays.iter().zip(t_max).zip(hits.iter_mut()) {
            *hit = self.intersect(ray, t);
        }
    }

    /// Occlusion of a stream of shadow rays, uncounted: `occluded[i]` is what
    /// [`Accel::occluded_toward`]`(&rays[i], t_max[i], target)` returns, with `target` the
    /// light-side endpoint `toward[i]` when it is finite, else [`Accel::occluded`]. The default
    /// traces them one by one.
    fn occluded_stream(&self, rays: &[Ray], t_max: &[f32], toward: &[Vec3], occluded: &mut [bool]) {
        for (((ray, &t), &p), o) in rays.iter().zip(t_max).zip(toward).zip(occluded.iter_mut()) {
            *o = if p.is_finite() {
                self.occluded_toward(ray, t, p)
            } else {
                self.occluded(ray, t)
            };
        }
    }

    /// Closest hit with `t ∈ (0, t_max]`, uncounted.
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.closest_hit(ray, t_max, None)
    }

    /// True if anything is hit with `t ∈ (0, t_max]`, uncounted.
    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.any_hit(ray, t_max, None, None)
    }

    /// Occlusion of a shadow ray toward the light sample `target`, uncounted.
    fn occluded_toward(&self, ray: &Ray, t_max: f32, target: Vec3) -> bool {
        self.any_hit(ray, t_max, Some(target), None)
    }
}
