//! Pieces every traversal and validator in this crate shares.

use rt_core::{Aabb, TraversalCounters};

/// Each slab distance `(plane - origin) * (1 / dir)` carries three roundings, so it is within
/// `gamma(3)` of the exact value; comparing a near against a far distance can therefore be off by
/// `2 gamma(3)`, and widening the far side by that much means a box the ray really touches is
/// never culled (Ize, "Robust BVH Ray Traversal", JCGT 2013). `gamma(n) = n u / (1 - n u)` with
/// unit roundoff `u = 2^-24`.
pub(crate) const FAR_SCALE: f32 = {
    let u = f32::EPSILON * 0.5;
    let gamma3 = 3.0 * u / (1.0 - 3.0 * u);
    1.0 + 2.0 * gamma3
};
const _: () = assert!(FAR_SCALE > 1.0 && FAR_SCALE < 1.0 + 1e-6);

/// Where traversal work is tallied; [`NoCount`] compiles away.
pub(crate) trait Counter {
    fn boxes(&mut self, n: u64);
    fn triangle(&mut self);
}

/// The counter of the uncounted queries.
pub(crate) struct NoCount;

impl Counter for NoCount {
    #[inline(always)]
    fn boxes(&mut self, _: u64) {}
    #[inline(always)]
    fn triangle(&mut self) {}
}

impl Counter for TraversalCounters {
    #[inline(always)]
    fn boxes(&mut self, n: u64) {
        self.nodes_visited += n;
    }
    #[inline(always)]
    fn triangle(&mut self) {
        self.prims_tested += 1;
    }
}

/// True if `inner` lies within `outer` (for the `validate` methods).
pub(crate) fn inside(inner: &Aabb, outer: &Aabb) -> bool {
    inner.min.cmpge(outer.min).all() && inner.max.cmple(outer.max).all()
}
