//! Crack-free ray–triangle intersection by recursive subdivision (Dammertz 2011, §4.4), kept
//! so that it can be compared with the watertight test the renderer uses.
//!
//! The renderer's default, [`rt_core::triangle::intersect_triangle`] (Woop, Benthin and Wald
//! 2013), already cannot leak rays through the shared edges and vertices of a closed mesh, and
//! costs about as much as Möller–Trumbore. The thesis predates it and solves the same problem
//! differently: the triangle is represented by its bounding box, and boxes are refined until
//! floating point cannot refine them any further. This module implements that method and its
//! two companions so that the three can be measured against the default:
//!
//! - [`intersect_moller_trumbore`]: the plain analytic test of the thesis (§2.3.3), two-sided,
//!   without epsilons. It leaks: rays aimed exactly at shared edges and vertices now and then
//!   miss every triangle around them.
//! - [`intersect_subdivision`]: the subdivision test. Conservative, never leaks, much slower.
//! - [`intersect_hybrid`]: Möller–Trumbore first, and the subdivision test only when it
//!   misses. Keeps the guarantee and pays the subdivision cost only on misses.
//!
//! # The subdivision test
//!
//! A triangle is split into four by its edge midpoints `(a + b) * 0.5`, recursively. The
//! barycentric coordinates of the sub-triangles' vertices are split alongside, in `f64`, where
//! they are exact (dyadic rationals of at most [`MAX_DEPTH`] bits). A node is a leaf when its
//! box is a few ulps wide (largest extent at most `4 * f32::EPSILON` times the triangle's
//! largest coordinate, the precision the vertices are known to), when rounding maps it onto
//! itself (box equal to its parent's), or at depth [`MAX_DEPTH`]. A leaf's barycentrics are the
//! mean of its three barycentric vertices.
//!
//! Rounding keeps every midpoint between its endpoints, so a sub-triangle lies in the box of
//! each of its ancestors. Each level's rounding moves a vertex by at most half an ulp (of the
//! triangle's largest coordinate `M`) per axis, so every point of the exact triangle lies within
//! `MAX_DEPTH / 2` such ulps of a sub-triangle at every level, each a child of the one before.
//! That drift bound, raised to `2^-18 M` (at least 32 ulps), is the *tolerance* `tol` of the
//! test.
//!
//! A query has three steps:
//!
//! 1. The ray is cut to the stretch where it is within `tol` of the triangle's plane (plane in
//!    `f64`, computed once), intersected with `[0, t_max]`, and the triangle's box must be hit
//!    within that stretch by the conservative slab test of the crate's traversals (Ize 2013).
//!    This keeps rays passing beside the triangle cheap: without it, a ray running parallel to
//!    a tilted triangle at a distance `δ` would hit every sub-box larger than `δ` on its way.
//! 2. If the ray crosses the plane at a `t` in `(0, t_max]`, the tree is descended along the
//!    boxes that contain the crossing point widened by `tol`, with backtracking. The first leaf
//!    reached is the hit: the crossing's `t` and the leaf's barycentrics. By the drift bound
//!    this succeeds whenever the crossing lies in the closed triangle, which is what makes
//!    meshes crack-free: a ray through a shared edge or vertex crosses the plane of every
//!    triangle around it at that very point, and hits all of them. No topology is involved.
//!    The children are tried in the order of the crossing's barycentrics (computed in `f64`),
//!    so such a crossing is located in one expansion per level, whatever the triangle's shape.
//! 3. Otherwise (the crossing lies outside the triangle, the ray runs in or nearly in the
//!    plane, or it crosses the plane behind its origin or beyond `t_max`), the thesis' search:
//!    nearest box first, into every sub-box the ray hits within the stretch, down to the leaves.
//!    The hit is the leaf with the smallest entry distance, at that distance.
//!
//! So a ray hits the triangle if it crosses the plane within about `tol` of the triangle, or if
//! it runs within `tol` of the plane through a leaf box (to within the slab test's widening of
//! `2 gamma(3)`, about `3.6e-7` relative to the distance travelled). Only hits at `t` in
//! `(0, t_max]` count, so a ray leaving a surface from an origin within that neighbourhood does
//! not hit it.
//!
//! Triangles with a non-finite vertex or a zero geometric normal (computed in `f64`) are never
//! hit: they cover no area, and a hit on them would have no normal to shade with. Because the
//! boxes and the `f64` plane are scale-free, the test keeps working at coordinates of `1e30` or
//! `1e-30`, where both analytic tests give up (their determinants overflow or underflow).
//!
//! # Cost
//!
//! A hit descends some 20 levels (`log2` of the triangle's size over `4 ulp(M)`), testing four
//! child boxes at each: about 80 box tests where the analytic tests need one determinant,
//! plus the `f64` plane. A miss descends until the sub-boxes no longer hold the crossing (step
//! 2) or meet the ray (step 3): a few levels for a clear miss, as many as a hit for a near miss.
//! Measured per test on the pairs a traversal of a sphere mesh meets (box hit), relative to
//! Möller–Trumbore: about 90x on hits and 4x on misses for subdivision; the hybrid costs the
//! same as Möller–Trumbore on hits and 5x on misses. No allocation: the descents use a fixed
//! stack of [`MAX_DEPTH`] frames (under 3 KB) on the call stack.
//!
//! Two configurations make the number of boxes a ray hits grow with depth: a ray lying (within
//! `tol`) in the plane alongside an edge, just outside it, hits every sub-box larger than its
//! distance `η` to the edge, about `length / η` of them; and a sliver, a triangle with an edge
//! shorter than `tol` (float-degenerate next to its largest coordinate), has `2^k` sub-triangles
//! at level `k` along that edge with coinciding boxes. (Thin triangles in general make the boxes
//! of all sub-triangles near a point overlap it, as many per level as the aspect ratio.) So a
//! query expands at most [`MAX_EXPANSIONS`] nodes, and if that runs out it returns the nearest
//! leaf found so far, or a miss: the one case where the answer depends on a work limit rather
//! than on the geometry. Step 2 locates a crossing inside the triangle in at most
//! [`MAX_DEPTH`] expansions, so the guarantee above does not depend on the limit.
//!
//! The thesis measured whole-renderer frame rates: 3.64 fps with Möller–Trumbore, 0.74 fps with
//! subdivision and 2.24 fps with the hybrid. The `crack_free` integration test of this crate
//! times the tests alone (`--ignored`).
//!
//! ```
//! use rt_accel::crack_free::{intersect_hybrid, intersect_subdivision, SubdivRay};
//! use rt_core::{glam::Vec3, Ray};
//!
//! let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
//! // Exactly through the vertex at the origin.
//! let pre = SubdivRay::new(&Ray::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z));
//! let hit = intersect_subdivision(&pre, &tri, f32::INFINITY).unwrap();
//! assert_eq!(hit.t, 2.0);
//! assert!(hit.b1 < 1e-4 && hit.b2 < 1e-4);
//! assert_eq!(intersect_hybrid(&pre, &tri, 1.5), None);
//! ```

use crate::traversal::FAR_SCALE;
use glam::{BVec3A, DVec2, DVec3, Vec3, Vec3A};
use rt_core::triangle::TriHit;
use rt_core::Ray;

/// Deepest subdivision level. Leaves are normally reached well before (a box of four ulps of the
/// triangle's largest coordinate: some 20 levels for a triangle the size of its coordinates);
/// the cap stops sub-triangles that rounding keeps from shrinking, and bounds the drift the
/// tolerance must cover (see the module documentation) and the stack.
pub const MAX_DEPTH: usize = 28;

/// The tolerance relative to the triangle's largest coordinate `M` (see the module
/// documentation). `ulp(M) <= M * 2^-23`, so each level moves a vertex by at most `M * 2^-24`
/// per axis, and `MAX_DEPTH` levels by at most `sqrt(3) * MAX_DEPTH * M * 2^-24` in distance.
const TOLERANCE: f64 = 1.0 / (1u64 << 18) as f64;
const _: () = assert!(1.7321 * MAX_DEPTH as f64 / (1u64 << 24) as f64 <= TOLERANCE);

/// Most nodes one query expands, over steps 2 and 3 (each expansion tests four boxes). A hit
/// expands about 20, a clear miss a few; see the module documentation for the cases that would
/// need more.
pub const MAX_EXPANSIONS: u32 = 2048;

/// Leaf size in units of `f32::EPSILON` times the triangle's largest coordinate, a few ulps:
/// rounding keeps sub-triangles from shrinking much below two ulps, and the vertices are known
/// only to one, so smaller boxes would tell nothing more.
const LEAF_ULPS: f32 = 4.0;

/// Relative allowance for the rounding of `f64` quantities (plane distances, the crossing point)
/// that are exact up to a few `f64` ulps.
const F64_SLACK: f64 = 1.0 / (1u64 << 40) as f64;

/// Möller–Trumbore, as in the thesis: both faces, no epsilon, `t ∈ (0, t_max]`.
///
/// A zero or non-finite determinant (degenerate triangle, ray parallel to it, overflow at huge
/// coordinates, underflow at tiny ones) is a miss, and NaNs fail every comparison, so NaN
/// inputs miss too. Rays through shared edges and vertices can miss all triangles around them.
#[inline]
pub fn intersect_moller_trumbore(ray: &Ray, tri: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri[0];
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = ray.dir.dot(q) * inv;
    if !(b2 >= 0.0 && b1 + b2 <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv;
    // `t_max` may be infinite, so finiteness is checked separately.
    if !(t > 0.0 && t <= t_max && t.is_finite()) {
        return None;
    }
    Some(TriHit { t, b1, b2 })
}

/// Per-ray constants of the subdivision test.
#[derive(Clone, Copy, Debug)]
pub struct SubdivRay {
    ray: Ray,
    org: Vec3A,
    /// `1 / dir`: a zero component of either sign becomes an infinity of that sign.
    inv: Vec3A,
    /// Sign bit of `inv`, which picks the near plane; the sign bit rather than `< 0` is what
    /// matches `-0.0` to its `-inf`.
    neg: BVec3A,
    /// Finite origin and finite, non-zero direction; other rays never hit.
    valid: bool,
}

impl SubdivRay {
    /// Precomputes the slab-test constants for `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let inv = Vec3A::from(ray.dir).recip();
        let [x, y, z] = inv.to_array().map(f32::is_sign_negative);
        Self {
            ray: *ray,
            org: ray.origin.into(),
            inv,
            neg: BVec3A::new(x, y, z),
            valid: ray.origin.is_finite() && ray.dir.is_finite() && ray.dir != Vec3::ZERO,
        }
    }

    /// The ray.
    #[inline]
    pub fn ray(&self) -> &Ray {
        &self.ray
    }

    /// Entry distance into the box `[lo, hi]` if the ray overlaps it within `[t_start, t_end]`,
    /// conservatively (see [`FAR_SCALE`]).
    #[inline(always)]
    fn slab(&self, lo: Vec3A, hi: Vec3A, t_start: f32, t_end: f32) -> Option<f32> {
        let a = (lo - self.org) * self.inv;
        let b = (hi - self.org) * self.inv;
        let near = Vec3A::select(self.neg, b, a);
        let far = Vec3A::select(self.neg, a, b);
        // A NaN is 0 * inf: the ray runs inside the plane of a face, on the box's boundary, so
        // that slab must not cull. (The SIMD min and max would not reliably skip a NaN.)
        let near = Vec3A::select(near.is_nan_mask(), Vec3A::NEG_INFINITY, near);
        let far = Vec3A::select(far.is_nan_mask(), Vec3A::INFINITY, far);
        let t0 = near.max_element().max(t_start);
        let t1 = far.min_element().min(t_end);
        (t0 <= t1 * FAR_SCALE).then_some(t0)
    }
}

/// Work done by one subdivision query, from [`intersect_subdivision_counted`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SubdivStats {
    /// Box tests: slab tests against the ray, and the tests whether a box holds the crossing.
    pub boxes_tested: u32,
    /// Nodes whose children were tested.
    pub nodes_expanded: u32,
    /// Leaves reached.
    pub leaves: u32,
    /// Deepest level reached (the root is level 0).
    pub max_level: u32,
    /// The search along the ray (step 3 of the module documentation) ran.
    pub ray_search: bool,
    /// The query ran out of its work budget ([`MAX_EXPANSIONS`]).
    pub gave_up: bool,
}

/// The subdivision test (thesis §4.4): conservative, for `t ∈ (0, t_max]`. See the
/// [module documentation](self) for what counts as a hit, how the distance and barycentrics are
/// chosen, and the cost.
#[inline]
pub fn intersect_subdivision(pre: &SubdivRay, tri: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    subdivide::<false>(pre, tri, t_max, &mut SubdivStats::default())
}

/// [`intersect_subdivision`], also reporting the work it did.
pub fn intersect_subdivision_counted(
    pre: &SubdivRay,
    tri: &[Vec3; 3],
    t_max: f32,
    stats: &mut SubdivStats,
) -> Option<TriHit> {
    subdivide::<true>(pre, tri, t_max, stats)
}

/// The thesis' hybrid: Möller–Trumbore, and the subdivision test only if it misses. As
/// crack-free as [`intersect_subdivision`]; a hit costs one Möller–Trumbore test, a miss one of
/// each.
#[inline]
pub fn intersect_hybrid(pre: &SubdivRay, tri: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    intersect_moller_trumbore(&pre.ray, tri, t_max)
        .or_else(|| intersect_subdivision(pre, tri, t_max))
}

/// One level of a descent: a node, and those of its children still to visit.
#[derive(Clone, Copy)]
struct Frame {
    /// The node's vertices; children are rebuilt from them, which is cheaper than storing them.
    v: [Vec3A; 3],
    /// Barycentrics `(b1, b2)` of `v[0]`; `v[1]` is at `anchor + (scale, 0)` and `v[2]` at
    /// `anchor + (0, scale)`. The middle child is point-reflected, so `scale` can be negative.
    anchor: DVec2,
    scale: f64,
    /// Sort keys and indices of the children to visit, smallest key last. The key is how far
    /// the crossing's barycentrics lie outside the child in step 2, its entry distance along the
    /// ray in step 3.
    key: [f32; 4],
    child: [u8; 4],
    len: u8,
}

impl Frame {
    const EMPTY: Frame = Frame {
        v: [Vec3A::ZERO; 3],
        anchor: DVec2::ZERO,
        scale: 0.0,
        key: [0.0; 4],
        child: [0; 4],
        len: 0,
    };

    /// The node's edge midpoints `[m01, m12, m20]`.
    #[inline(always)]
    fn midpoints(&self) -> [Vec3A; 3] {
        let v = &self.v;
        [mid(v[0], v[1]), mid(v[1], v[2]), mid(v[2], v[0])]
    }

    /// Child `i` of this node, given its midpoints `m`: vertices, barycentric anchor and scale.
    #[inline(always)]
    fn child(&self, m: &[Vec3A; 3], i: u8) -> ([Vec3A; 3], DVec2, f64) {
        let v = &self.v;
        let h = self.scale * 0.5;
        let a = self.anchor;
        // The three corners, then the middle triangle; child vertex `k` sits at the child's
        // barycentric vertex `k`.
        match i {
            0 => ([v[0], m[0], m[2]], a, h),
            1 => ([m[0], v[1], m[1]], a + DVec2::new(h, 0.0), h),
            2 => ([m[2], m[1], v[2]], a + DVec2::new(0.0, h), h),
            _ => ([m[1], m[2], m[0]], a + DVec2::splat(h), -h),
        }
    }

    /// Makes this frame node `v` with the children that pass `test` (given their box and
    /// barycentric anchor and scale, it returns a sort key), smallest key last. Returns false if
    /// none passes.
    #[inline(always)]
    fn expand<const COUNT: bool>(
        &mut self,
        v: &[Vec3A; 3],
        anchor: DVec2,
        scale: f64,
        stats: &mut SubdivStats,
        mut test: impl FnMut(Vec3A, Vec3A, DVec2, f64) -> Option<f32>,
    ) -> bool {
        self.v = *v;
        self.anchor = anchor;
        self.scale = scale;
        let m = self.midpoints();
        let mut len = 0usize;
        for i in 0..4u8 {
            let (c, a, h) = self.child(&m, i);
            let (lo, hi) = bounds(&c);
            let Some(key) = test(lo, hi, a, h) else {
                continue;
            };
            // Insertion into the short list, kept in decreasing order so the best pops first.
            let mut j = len;
            while j > 0 && self.key[j - 1] < key {
                self.key[j] = self.key[j - 1];
                self.child[j] = self.child[j - 1];
                j -= 1;
            }
            self.key[j] = key;
            self.child[j] = i;
            len += 1;
        }
        if COUNT {
            stats.boxes_tested += 4;
            stats.nodes_expanded += 1;
        }
        self.len = len as u8;
        len > 0
    }

    /// Takes the next child to visit: its sort key, vertices, box, barycentric anchor and scale.
    #[inline(always)]
    fn pop(&mut self) -> (f32, [Vec3A; 3], Vec3A, Vec3A, DVec2, f64) {
        self.len -= 1;
        let k = self.len as usize;
        let (v, anchor, scale) = self.child(&self.midpoints(), self.child[k]);
        let (lo, hi) = bounds(&v);
        (self.key[k], v, lo, hi, anchor, scale)
    }
}

/// Midpoint of `a` and `b`. Both formulas are commutative, so triangles sharing an edge split it
/// identically, and rounding keeps the result between `a` and `b`. The second one, exact halving
/// first, is only needed where the sum overflows.
#[inline(always)]
fn mid(a: Vec3A, b: Vec3A) -> Vec3A {
    let m = (a + b) * 0.5;
    // Written out: glam's `is_finite` is not always inlined, and this runs four times per box.
    if m.abs().cmplt(Vec3A::INFINITY).all() {
        m
    } else {
        a * 0.5 + b * 0.5
    }
}

/// Bounds of a triangle. Its vertices are finite, so the SIMD min and max are exact.
#[inline(always)]
fn bounds(v: &[Vec3A; 3]) -> (Vec3A, Vec3A) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

/// Whether the child popped from `parent` at level `depth`, with box `[lo, hi]`, is a leaf.
///
/// `leaf_size` is [`LEAF_ULPS`] ulps of the triangle's largest coordinate, not of the box's own:
/// boxes near a coordinate plane could keep shrinking where floats are denser, for up to 150
/// levels at the origin, without telling anything more about the triangle. A box equal to its
/// parent's is a sub-triangle that rounding maps onto itself (vertices a few ulps apart), which
/// would otherwise recurse, branching, down to `MAX_DEPTH`.
#[inline(always)]
fn stops(parent: &Frame, depth: usize, lo: Vec3A, hi: Vec3A, leaf_size: f32) -> bool {
    (hi - lo).max_element() <= leaf_size || depth == MAX_DEPTH || (lo, hi) == bounds(&parent.v)
}

#[inline(always)]
fn overlaps(lo: Vec3A, hi: Vec3A, p_lo: Vec3A, p_hi: Vec3A) -> bool {
    (lo.cmple(p_hi) & hi.cmpge(p_lo)).all()
}

#[inline(always)]
fn barycentrics(t: f32, anchor: DVec2, scale: f64) -> TriHit {
    let b = anchor + DVec2::splat(scale / 3.0);
    TriHit {
        t,
        b1: b.x as f32,
        b2: b.y as f32,
    }
}

/// Step 2: descends along the boxes that overlap `[p_lo, p_hi]`, the crossing point widened by
/// the tolerance, down to a leaf, and returns the first leaf's barycentric anchor and scale.
///
/// The boxes decide; `bp`, the crossing's barycentrics computed in `f64`, only orders the
/// children: the one whose barycentric triangle holds `bp` (or is nearest to it) first. By the
/// drift bound that child's box always overlaps, so a crossing inside the triangle is located
/// without backtracking, one expansion per level, whatever the triangle's shape. (Ordered by the
/// boxes alone, the descent into a thin triangle wanders: the boxes of all sub-triangles within
/// a box size of the crossing overlap it, as many per level as the triangle's aspect ratio.)
#[inline(always)]
fn locate<const COUNT: bool>(
    stack: &mut [Frame; MAX_DEPTH],
    tri: &[Vec3A; 3],
    (bp, p_lo, p_hi): (DVec2, Vec3A, Vec3A),
    leaf_size: f32,
    budget: &mut u32,
    stats: &mut SubdivStats,
) -> Option<(DVec2, f64)> {
    let (lo, hi) = bounds(tri);
    if COUNT {
        stats.boxes_tested += 1;
    }
    if !overlaps(lo, hi, p_lo, p_hi) {
        return None;
    }
    if (hi - lo).max_element() <= leaf_size {
        if COUNT {
            stats.leaves += 1;
        }
        return Some((DVec2::ZERO, 1.0));
    }
    let test = |lo, hi, anchor: DVec2, scale: f64| {
        // How far `bp` lies outside the child's barycentric triangle, in units of its size.
        let uv = (bp - anchor) / scale;
        let outside = (-uv.x).max(-uv.y).max(uv.x + uv.y - 1.0).max(0.0);
        overlaps(lo, hi, p_lo, p_hi).then_some(outside as f32)
    };
    *budget -= 1;
    if !stack[0].expand::<COUNT>(tri, DVec2::ZERO, 1.0, stats, test) {
        return None;
    }
    let mut depth = 1usize;
    while depth > 0 {
        let f = &mut stack[depth - 1];
        if f.len == 0 {
            depth -= 1;
            continue;
        }
        let (_, v, lo, hi, anchor, scale) = f.pop();
        if COUNT {
            stats.max_level = stats.max_level.max(depth as u32);
        }
        if stops(f, depth, lo, hi, leaf_size) {
            if COUNT {
                stats.leaves += 1;
            }
            return Some((anchor, scale));
        }
        if *budget == 0 {
            if COUNT {
                stats.gave_up = true;
            }
            return None;
        }
        *budget -= 1;
        if stack[depth].expand::<COUNT>(&v, anchor, scale, stats, test) {
            depth += 1;
        }
    }
    None
}

/// Step 3: the thesis' search, nearest box first, for the leaf with the smallest entry distance
/// within `[t_start, t_end]`; `root_t0` is the triangle box's entry distance.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn search<const COUNT: bool>(
    pre: &SubdivRay,
    stack: &mut [Frame; MAX_DEPTH],
    tri: &[Vec3A; 3],
    (t_start, t_end): (f32, f32),
    root_t0: f32,
    leaf_size: f32,
    budget: &mut u32,
    stats: &mut SubdivStats,
) -> Option<TriHit> {
    let mut best: Option<TriHit> = None;
    // Hits at distance 0 (the origin inside a leaf box) do not count.
    let take = |best: &mut Option<TriHit>, t: f32, anchor: DVec2, scale: f64| {
        if t > 0.0 && best.is_none_or(|b| t < b.t) {
            *best = Some(barycentrics(t, anchor, scale));
        }
    };
    let (lo, hi) = bounds(tri);
    if (hi - lo).max_element() <= leaf_size {
        if COUNT {
            stats.leaves += 1;
        }
        take(&mut best, root_t0, DVec2::ZERO, 1.0);
        return best;
    }
    if *budget == 0 {
        if COUNT {
            stats.gave_up = true;
        }
        return None;
    }
    *budget -= 1;
    let test = |lo, hi, _, _| pre.slab(lo, hi, t_start, t_end);
    if !stack[0].expand::<COUNT>(tri, DVec2::ZERO, 1.0, stats, test) {
        return None;
    }
    let mut depth = 1usize;
    while depth > 0 {
        let f = &mut stack[depth - 1];
        if f.len == 0 {
            depth -= 1;
            continue;
        }
        let best_t = best.map_or(f32::INFINITY, |b| b.t);
        // Children are sorted, so the rest of the frame is no nearer either.
        if f.key[f.len as usize - 1] >= best_t {
            f.len = 0;
            depth -= 1;
            continue;
        }
        let (t0, v, lo, hi, anchor, scale) = f.pop();
        if COUNT {
            stats.max_level = stats.max_level.max(depth as u32);
        }
        if stops(f, depth, lo, hi, leaf_size) {
            if COUNT {
                stats.leaves += 1;
            }
            take(&mut best, t0, anchor, scale);
            continue;
        }
        if *budget == 0 {
            if COUNT {
                stats.gave_up = true;
            }
            break;
        }
        *budget -= 1;
        let t_end = t_end.min(best_t);
        let test = |lo, hi, _, _| pre.slab(lo, hi, t_start, t_end);
        if stack[depth].expand::<COUNT>(&v, anchor, scale, stats, test) {
            depth += 1;
        }
    }
    best
}

#[inline(always)]
fn subdivide<const COUNT: bool>(
    pre: &SubdivRay,
    tri: &[Vec3; 3],
    t_max: f32,
    stats: &mut SubdivStats,
) -> Option<TriHit> {
    if !pre.valid || t_max.is_nan() || t_max <= 0.0 {
        return None;
    }
    // Non-finite vertices would give NaN box bounds, which the slab test treats as unbounded.
    if !(tri[0].is_finite() && tri[1].is_finite() && tri[2].is_finite()) {
        return None;
    }
    // The plane in f64: products of f32 differences neither overflow nor underflow there, so
    // the normal is exactly zero only for (nearly exactly) collinear vertices, at any scale.
    let a = tri[0].as_dvec3();
    let (e1, e2) = (tri[1].as_dvec3() - a, tri[2].as_dvec3() - a);
    let normal = e1.cross(e2);
    if normal == DVec3::ZERO {
        return None;
    }
    let n = normal / normal.length();
    let (o, d) = (pre.ray.origin.as_dvec3(), pre.ray.dir.as_dvec3());
    // Signed distance from the plane along the ray: s0 + s1 t.
    let (s0, s1) = (n.dot(o - a), n.dot(d));
    let tri = tri.map(Vec3A::from);
    let (lo, hi) = bounds(&tri);
    let big = lo.abs().max(hi.abs()).max_element();
    let leaf_size = big * LEAF_ULPS * f32::EPSILON;
    let tol = big as f64 * TOLERANCE + (o - a).abs().max_element() * F64_SLACK;

    // Step 1: the stretch of the ray within `tol` of the plane, widened by 2^-20 relative,
    // far beyond the rounding of its ends to f32.
    let (near, far) = if s1 == 0.0 {
        if s0.abs() > tol {
            return None;
        }
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        let (ta, tb) = ((-tol - s0) / s1, (tol - s0) / s1);
        (ta.min(tb), ta.max(tb))
    };
    let widen = 1.0 / (1u64 << 20) as f64;
    let t_start = ((near - near.abs() * widen) as f32).max(0.0);
    let t_end = ((far + far.abs() * widen) as f32).min(t_max);
    // `f32::max` and `min` drop NaN, so neither end is NaN here.
    if t_start > t_end {
        return None;
    }
    if COUNT {
        stats.boxes_tested += 1;
    }
    let root_t0 = pre.slab(lo, hi, t_start, t_end)?;

    let mut stack = [Frame::EMPTY; MAX_DEPTH];
    let mut budget = MAX_EXPANSIONS;
    // Step 2, if the ray crosses the plane (not parallel, within range).
    let t64 = -s0 / s1;
    let t = t64 as f32;
    if t > 0.0 && t <= t_max && t.is_finite() {
        let travel = d * t64;
        let p = o + travel;
        let tol = tol + (o.abs() + travel.abs()).max_element() * F64_SLACK;
        let q = (p - a).cross(normal) / normal.length_squared();
        let bp = DVec2::new(-q.dot(e2), q.dot(e1));
        let near_p = (bp, (p - tol).as_vec3a(), (p + tol).as_vec3a());
        let found = locate::<COUNT>(&mut stack, &tri, near_p, leaf_size, &mut budget, stats);
        if let Some((anchor, scale)) = found {
            return Some(barycentrics(t, anchor, scale));
        }
    }
    // Step 3.
    if COUNT {
        stats.ray_search = true;
    }
    let stretch = (t_start, t_end);
    search::<COUNT>(
        pre,
        &mut stack,
        &tri,
        stretch,
        root_t0,
        leaf_size,
        &mut budget,
        stats,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::triangle::{geometric_normal, intersect_triangle, RayPrecomp};

    fn ray(o: Vec3, d: Vec3) -> Ray {
        Ray::new(o, d)
    }

    fn all(r: &Ray, tri: &[Vec3; 3], t_max: f32) -> [Option<TriHit>; 3] {
        let pre = SubdivRay::new(r);
        [
            intersect_moller_trumbore(r, tri, t_max),
            intersect_subdivision(&pre, tri, t_max),
            intersect_hybrid(&pre, tri, t_max),
        ]
    }

    #[test]
    fn interior_hit_matches_the_watertight_test() {
        let tri = [
            Vec3::new(-1.0, -0.5, 0.3),
            Vec3::new(1.2, -0.4, -0.2),
            Vec3::new(0.1, 1.1, 0.1),
        ];
        let r = ray(Vec3::new(0.1, 0.05, 3.0), Vec3::new(0.02, -0.03, -1.0));
        let want = intersect_triangle(&RayPrecomp::new(&r), &tri, f32::INFINITY).unwrap();
        for got in all(&r, &tri, f32::INFINITY) {
            let got = got.unwrap();
            assert!((got.t - want.t).abs() <= 1e-6 * want.t, "{got:?} {want:?}");
            assert!((got.b1 - want.b1).abs() < 1e-4 && (got.b2 - want.b2).abs() < 1e-4);
        }
    }

    #[test]
    fn misses_outside_behind_and_beyond_t_max() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(
            all(
                &ray(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z),
                &tri,
                f32::INFINITY
            ),
            [None; 3]
        );
        let r = ray(Vec3::new(0.2, 0.2, 1.0), Vec3::Z);
        assert_eq!(all(&r, &tri, f32::INFINITY), [None; 3]);
        let r = ray(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        assert_eq!(all(&r, &tri, 0.5), [None; 3]);
        for h in all(&r, &tri, 1.0) {
            assert_eq!(h.unwrap().t, 1.0);
        }
        for t_max in [0.0, -1.0, f32::NAN] {
            assert_eq!(all(&r, &tri, t_max), [None; 3]);
        }
    }

    #[test]
    fn corners_and_edges_are_hit_with_their_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let pre = |p: Vec3| SubdivRay::new(&ray(p + Vec3::Z, -Vec3::Z));
        for (p, b1, b2) in [
            (Vec3::ZERO, 0.0, 0.0),
            (Vec3::X, 1.0, 0.0),
            (Vec3::Y, 0.0, 1.0),
            (Vec3::new(0.5, 0.5, 0.0), 0.5, 0.5),
            (Vec3::new(0.3, 0.0, 0.0), 0.3, 0.0),
        ] {
            let h = intersect_subdivision(&pre(p), &tri, f32::INFINITY).unwrap();
            assert_eq!(h.t, 1.0);
            assert!(
                (h.b1 - b1).abs() < 1e-6 && (h.b2 - b2).abs() < 1e-6,
                "{p} {h:?}"
            );
        }
        // Just outside the hypotenuse, by twice the tolerance (2^-18 of the largest coordinate).
        let h = intersect_subdivision(&pre(Vec3::new(0.5, 0.5 + 1e-5, 0.0)), &tri, 9.0);
        assert_eq!(h, None);
    }

    #[test]
    fn a_ray_in_the_plane_hits_where_it_enters() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let r = ray(Vec3::new(-1.0, 0.25, 0.0), Vec3::X);
        let h = intersect_subdivision(&SubdivRay::new(&r), &tri, f32::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6, "{h:?}");
        assert!(h.b1 < 1e-6 && (h.b2 - 0.25).abs() < 1e-6, "{h:?}");
        assert_eq!(intersect_moller_trumbore(&r, &tri, f32::INFINITY), None);
    }

    #[test]
    fn a_hit_is_located_with_one_expansion_per_level() {
        // Also at the coordinate origin, where boxes could otherwise shrink for 150 levels.
        let tri = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::Y,
        ];
        for shift in [
            Vec3::ZERO,
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(0.5, 0.5, 0.0),
        ] {
            let tri = tri.map(|v| v + shift);
            let pre = SubdivRay::new(&ray(shift + Vec3::Z, -Vec3::Z));
            let mut stats = SubdivStats::default();
            let h = intersect_subdivision_counted(&pre, &tri, f32::INFINITY, &mut stats).unwrap();
            assert_eq!(h.t, 1.0);
            assert!(stats.leaves == 1 && !stats.ray_search, "{stats:?}");
            assert!((18..=24).contains(&stats.max_level), "{stats:?}");
            assert_eq!(stats.nodes_expanded, stats.max_level, "{stats:?}");
        }
    }

    #[test]
    fn a_sliver_stays_within_the_work_budget() {
        // The edge from vertex 0 to vertex 2 (4.6e14 long) is far below the tolerance of the
        // 1e22 coordinates (4e16): along it the boxes of 2^k sub-triangles coincide at level k.
        // The ray starts at vertex 2 and travels 1e13 in all, within the tolerance of everything,
        // so it meets all those boxes, at distance 0, which does not count.
        let tri = [
            Vec3::new(4.378412e14, 1.3269688e14, 1.3979266e13),
            Vec3::new(-5.259099e21, -1.1118132e22, -1.0709677e22),
            Vec3::new(2.4114581e-26, -4.8741438e-26, 5.0173662e-28),
        ];
        let r = ray(
            Vec3::new(-1.4386701e-6, -2.216287e-7, 1.2449331e-6),
            Vec3::new(1.282635e-18, -7.480505e-19, 1.0922081e-19),
        );
        let mut stats = SubdivStats::default();
        let h = intersect_subdivision_counted(&SubdivRay::new(&r), &tri, 1e31, &mut stats);
        assert!(h.is_none_or(|h| h.t > 0.0 && h.t <= 1e31), "{h:?}");
        assert!(
            stats.gave_up && stats.nodes_expanded == MAX_EXPANSIONS,
            "{stats:?}"
        );
    }

    #[test]
    fn a_ray_parallel_to_the_triangle_beside_it_is_culled_at_once() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let n = geometric_normal(&tri).normalize();
        // 1e-4 above the plane, inside the box, parallel to the plane.
        let r = ray(
            Vec3::new(0.0, 0.5, 0.5) + n * 1e-4,
            Vec3::new(1.0, -1.0, 0.0),
        );
        let mut stats = SubdivStats::default();
        let h = intersect_subdivision_counted(&SubdivRay::new(&r), &tri, f32::INFINITY, &mut stats);
        assert_eq!((h, stats.boxes_tested), (None, 0));
    }

    #[test]
    fn triangles_a_few_ulps_wide_end_quickly() {
        // Rounding can map such a sub-triangle onto itself; the search must not branch on it.
        let u = f32::EPSILON;
        let mut worst = SubdivStats::default();
        let mut searched = 0;
        for k in 0..4096u32 {
            let c = |s: u32| 1.0 + ((k >> s) & 3) as f32 * u;
            let tri = [
                Vec3::new(c(0), c(2), 1.0),
                Vec3::new(c(4), 1.0, c(6)),
                Vec3::new(1.0, c(8), c(10)),
            ];
            let centre = (tri[0] + tri[1] + tri[2]) / 3.0;
            // Beside the triangle too, so that the search along the ray runs (its leaves are
            // the float-sized ones; the crossing's descent stops at the tolerance).
            for side in [0.0, 8.0 * u, 30.0 * u] {
                for d in [Vec3::ONE, Vec3::new(1.0, -0.5, 0.25), -Vec3::Z] {
                    let pre = SubdivRay::new(&ray(centre + Vec3::new(side, -side, 0.0) - d, d));
                    let mut stats = SubdivStats::default();
                    intersect_subdivision_counted(&pre, &tri, f32::INFINITY, &mut stats);
                    searched += usize::from(stats.ray_search);
                    if stats.boxes_tested > worst.boxes_tested {
                        worst = stats;
                    }
                }
            }
        }
        assert!(searched > 500, "{searched}");
        assert!(worst.boxes_tested < 1000, "{worst:?}");
    }

    #[test]
    fn midpoints_near_the_float_limit_do_not_overflow() {
        let big = f32::MAX * 0.75;
        let tri = [
            Vec3::new(big, big, 0.0),
            Vec3::new(big, -big, 0.0),
            Vec3::new(-big, big, 0.0),
        ];
        assert!(mid(tri[0].into(), tri[0].into()).is_finite());
        let r = ray(Vec3::new(big * 0.5, big * 0.5, 1.0), -Vec3::Z);
        let h = intersect_subdivision(&SubdivRay::new(&r), &tri, f32::INFINITY).unwrap();
        assert_eq!(h.t, 1.0);
        assert!(h.b1.is_finite() && h.b2.is_finite());
    }

    #[test]
    fn invalid_rays_and_degenerate_triangles_miss() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for (o, d) in [
            (Vec3::splat(0.2), Vec3::ZERO),
            (Vec3::splat(0.2), Vec3::new(0.0, -0.0, 0.0)),
            (Vec3::new(0.2, 0.2, f32::NAN), -Vec3::Z),
            (
                Vec3::new(0.2, 0.2, 1.0),
                Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
            ),
        ] {
            let r = ray(o, d);
            assert_eq!(all(&r, &tri, f32::INFINITY), [None; 3], "{r:?}");
        }
        let r = ray(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        for tri in [
            [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            [Vec3::ZERO, Vec3::X, Vec3::X],
            [Vec3::new(0.5, 0.0, 0.0); 3],
            [Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 1.0, 0.0)],
            [Vec3::ZERO, Vec3::X, Vec3::new(f32::INFINITY, 1.0, 0.0)],
        ] {
            assert_eq!(all(&r, &tri, f32::INFINITY), [None; 3], "{tri:?}");
        }
    }

    #[test]
    fn the_stack_frame_is_small() {
        assert!(std::mem::size_of::<[Frame; MAX_DEPTH]>() <= 4096);
    }
}
