//! Pieces every traversal and validator in this crate shares.

mod stack;

pub(crate) use stack::{insert_by_distance, Stack};

use glam::Vec3;
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Aabb, Hit, Ray, TraversalCounters};
use std::ops::Range;

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
    fn leaf(&mut self);
    fn triangle(&mut self) {
        self.triangles(1);
    }
    fn triangles(&mut self, n: u64);
}

/// Runs `$body` with `$c` bound to the given counters, or to [`NoCount`] without them: one
/// branch per query, and each arm a traversal monomorphised for its counter.
macro_rules! with_counter {
    ($counters:expr, |$c:ident| $body:expr) => {
        match $counters {
            Some($c) => $body,
            None => {
                let $c = &mut $crate::traversal::NoCount;
                $body
            }
        }
    };
}
pub(crate) use with_counter;

/// The `closest_hit` and `any_hit` of an [`rt_core::Accel`] impl whose structure has an
/// inherent `traverse::<ANY_HIT, C: Counter>(&self, ray, t_max, counter) -> Option<Hit>`
/// (any hit: the first one found): each query dispatches once on its counters
/// ([`with_counter!`]), and the shadow-ray target is not used.
macro_rules! queries_by_traverse {
    () => {
        fn closest_hit(
            &self,
            ray: &rt_core::Ray,
            t_max: f32,
            counters: Option<&mut rt_core::TraversalCounters>,
        ) -> Option<rt_core::Hit> {
            $crate::traversal::with_counter!(counters, |c| self.traverse::<false, _>(ray, t_max, c))
        }

        fn any_hit(
            &self,
            ray: &rt_core::Ray,
            t_max: f32,
            _toward: Option<glam::Vec3>,
            counters: Option<&mut rt_core::TraversalCounters>,
        ) -> bool {
            $crate::traversal::with_counter!(counters, |c| self
                .traverse::<true, _>(ray, t_max, c)
                .is_some())
        }
    };
}
pub(crate) use queries_by_traverse;

/// The counter of the uncounted queries.
pub(crate) struct NoCount;

impl Counter for NoCount {
    #[inline(always)]
    fn boxes(&mut self, _: u64) {}
    #[inline(always)]
    fn leaf(&mut self) {}
    #[inline(always)]
    fn triangles(&mut self, _: u64) {}
}

impl Counter for TraversalCounters {
    #[inline(always)]
    fn boxes(&mut self, n: u64) {
        self.nodes_visited += n;
    }
    #[inline(always)]
    fn leaf(&mut self) {
        self.leaves_visited += 1;
    }
    #[inline(always)]
    fn triangles(&mut self, n: u64) {
        self.prims_tested += n;
    }
}

/// The closest hit of one query so far, and the leaf test that improves it.
///
/// Triangles are tested against the caller's `t_max`, not against the closest hit so far, and
/// the closest is kept with an exact `<` (ties to the lower triangle index). The result is then
/// the minimum of exactly the values
/// [`intersect_triangle`] computes over the leaves entered, independent of visiting order, and
/// agrees bit for bit with a brute-force loop unless a triangle's computed hit lies outside its
/// own box by more than the culling margin (overlapping coplanar triangles, nearly degenerate
/// ones). Starting at infinity rather than `t_max` makes `<` reject the NaN and infinite
/// distances that overflowing vertex coordinates produce.
pub(crate) struct Closest {
    /// The hit, if any.
    pub hit: Option<Hit>,
    t: f32,
    /// Distance beyond which boxes are culled: `t_max` until something is hit.
    pub cull_t: f32,
}

impl Closest {
    #[inline(always)]
    pub(crate) fn new(t_max: f32) -> Self {
        Self {
            hit: None,
            t: f32::INFINITY,
            cull_t: t_max,
        }
    }

    /// Tests the leaf-ordered triangles `range` (caller ids in `ids`); returns true when an
    /// any-hit query has its answer.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn test_leaf<const ANY_HIT: bool, C: Counter>(
        &mut self,
        pre: &RayPrecomp,
        triangles: &[[Vec3; 3]],
        ids: &[u32],
        range: Range<usize>,
        t_max: f32,
        counter: &mut C,
    ) -> bool {
        counter.leaf();
        for i in range {
            counter.triangle();
            let Some(h) = intersect_triangle(pre, &triangles[i], t_max) else {
                continue;
            };
            if self.offer::<ANY_HIT>(h.t, ids[i], h.b1, h.b2) {
                return true;
            }
        }
        false
    }

    /// Offers a hit with `t <= t_max`; returns true when an any-hit query has its answer.
    #[inline(always)]
    pub(crate) fn offer<const ANY_HIT: bool>(
        &mut self,
        t: f32,
        prim: u32,
        b1: f32,
        b2: f32,
    ) -> bool {
        // Equal distances go to the lower triangle index, as in a brute-force loop over the
        // triangles in order: the answer is then the same whatever order leaves are visited
        // in (ray streams trace packets of rays in an order of their own).
        if t < self.t || (t == self.t && self.hit.is_some_and(|h| prim < h.prim)) {
            self.hit = Some(Hit { t, prim, b1, b2 });
            if ANY_HIT {
                return true;
            }
            self.t = t;
            self.cull_t = t;
        }
        false
    }
}

/// Per-ray constants of the slab test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlabRay {
    org: [f32; 3],
    /// `1 / dir`, so a zero component, of either sign, becomes an infinity of the same sign.
    inv: [f32; 3],
    /// Sign bit of `inv` per axis: picks the near plane as `bounds[axis + 3 * neg]`. The sign bit
    /// rather than `< 0` is what matches `-0.0` to its `-inf`.
    neg: [bool; 3],
}

impl SlabRay {
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        let inv = ray.dir.recip().to_array();
        Self {
            org: ray.origin.to_array(),
            inv,
            neg: inv.map(f32::is_sign_negative),
        }
    }

    /// Entry distance into `bounds` (packed `[min.x, min.y, min.z, max.x, max.y, max.z]` as in the binary BVH's nodes) if the ray overlaps it
    /// within `[0, t_max]`, conservatively.
    #[inline(always)]
    pub(crate) fn hit(&self, bounds: &[f32; 6], t_max: f32) -> Option<f32> {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for axis in 0..3 {
            let n = self.neg[axis] as usize;
            let near = (bounds[axis + 3 * n] - self.org[axis]) * self.inv[axis];
            let far = (bounds[axis + 3 - 3 * n] - self.org[axis]) * self.inv[axis];
            // A NaN arises only as 0 * inf: the ray runs parallel to this axis inside the plane
            // of the slab's face, so it is on the box's boundary and the slab must not cull.
            // `f32::max`/`min` return the non-NaN operand, which leaves the interval alone.
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        (t0 <= t1 * FAR_SCALE).then_some(t0)
    }

    /// Entry and exit distances `(t0, t1)` of `bounds` within `[0, t_max]`, conservatively as
    /// [`SlabRay::hit`] (the exit widened by [`FAR_SCALE`]): for the grids, which walk cells
    /// from the entry to the exit.
    #[inline(always)]
    pub(crate) fn interval(&self, bounds: &[f32; 6], t_max: f32) -> Option<(f32, f32)> {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for axis in 0..3 {
            let n = self.neg[axis] as usize;
            let near = (bounds[axis + 3 * n] - self.org[axis]) * self.inv[axis];
            let far = (bounds[axis + 3 - 3 * n] - self.org[axis]) * self.inv[axis];
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        let t1 = t1 * FAR_SCALE;
        (t0 <= t1).then_some((t0, t1))
    }

    /// Near and far distances of the single slab `[lo, hi]` on `axis`, ordered by the sign of
    /// `1 / dir` (not by comparing them: with a `-0.0` component and the origin on a plane the
    /// two are NaN and ±inf, and a comparison would put the infinity first). The caller folds
    /// them into its interval with `f32::max`/`min`, which drop the NaN as [`SlabRay::hit`] does,
    /// and pads the far side by [`FAR_SCALE`] when comparing. For single-axis hierarchies (IOSP).
    #[inline(always)]
    pub(crate) fn slab(&self, axis: usize, lo: f32, hi: f32) -> (f32, f32) {
        let (near, far) = if self.neg[axis] { (hi, lo) } else { (lo, hi) };
        (
            (near - self.org[axis]) * self.inv[axis],
            (far - self.org[axis]) * self.inv[axis],
        )
    }

    /// True if the direction's component on `axis` has its sign bit set (`-0.0` included): the
    /// ray runs towards lower coordinates, so the upper child is the near one.
    #[inline(always)]
    pub(crate) fn negative(&self, axis: usize) -> bool {
        self.neg[axis]
    }
}

/// A node of a binary tree whose two children are stored side by side: what [`walk_binary`]
/// needs of it.
pub(crate) trait BinaryNode {
    /// `[min.x, min.y, min.z, max.x, max.y, max.z]`.
    fn planes(&self) -> &[f32; 6];
    /// `None` for a leaf, else the index of the first child (the second follows it).
    fn first_child(&self) -> Option<usize>;
}

/// What a leaf visit tells [`walk_binary`].
pub(crate) enum Step {
    /// Nothing closer in this leaf.
    Miss,
    /// A hit at this distance; cull beyond it.
    Closer(f32),
    /// The query has its answer.
    Done,
}

/// Front-to-back walk of a binary tree (root first in `nodes`, depth below `DEPTH`): calls
/// `leaf` on every leaf the ray reaches within the current culling distance, nearer child
/// first, and skips pending subtrees that start beyond it. Boxes tested go to `counter`, which
/// `leaf` also gets.
#[inline(always)]
pub(crate) fn walk_binary<N: BinaryNode, C: Counter, const DEPTH: usize>(
    nodes: &[N],
    ray: &Ray,
    t_max: f32,
    counter: &mut C,
    mut leaf: impl FnMut(&N, f32, &mut C) -> Step,
) {
    let Some(root) = nodes.first() else {
        return;
    };
    let slab = SlabRay::new(ray);
    counter.boxes(1);
    if slab.hit(root.planes(), t_max).is_none() {
        return;
    }
    let mut cull_t = t_max;
    // (node index, entry distance) of far children still to visit.
    let mut stack = [(0u32, 0.0f32); DEPTH];
    let mut sp = 0;
    let mut node = root;
    loop {
        match node.first_child() {
            None => match leaf(node, cull_t, counter) {
                Step::Miss => {}
                Step::Closer(t) => cull_t = t,
                Step::Done => return,
            },
            Some(first) => {
                counter.boxes(2);
                let t_left = slab.hit(nodes[first].planes(), cull_t);
                let t_right = slab.hit(nodes[first + 1].planes(), cull_t);
                let next = match (t_left, t_right) {
                    (Some(tl), Some(tr)) => {
                        let (near, far, far_entry) = if tl <= tr {
                            (first, first + 1, tr)
                        } else {
                            (first + 1, first, tl)
                        };
                        stack[sp] = (far as u32, far_entry);
                        sp += 1;
                        Some(near)
                    }
                    (Some(_), None) => Some(first),
                    (None, Some(_)) => Some(first + 1),
                    (None, None) => None,
                };
                if let Some(next) = next {
                    node = &nodes[next];
                    continue;
                }
            }
        }
        // Pop the nearest pending subtree that can still hold something closer.
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (index, t_entry) = stack[sp];
            if t_entry <= cull_t * FAR_SCALE {
                node = &nodes[index as usize];
                break;
            }
        }
    }
}

/// True if `inner` lies within `outer` (for the `validate` methods).
pub(crate) fn inside(inner: &Aabb, outer: &Aabb) -> bool {
    inner.min.cmpge(outer.min).all() && inner.max.cmple(outer.max).all()
}
