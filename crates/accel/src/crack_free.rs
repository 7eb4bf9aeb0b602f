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
//! box is as small as the floats at its position allow (largest extent at most
//! `f32::EPSILON` times its largest coordinate), when rounding maps it onto itself (box equal
//! to its parent's), or at depth [`MAX_DEPTH`]. A leaf's barycentrics are the mean of its three
//! barycentric vertices.
//!
//! Rounding keeps every midpoint between its endpoints, so a sub-triangle lies in the box of
//! each of its ancestors. And each level's rounding moves a vertex by at most half an ulp per
//! axis, so every point of the exact triangle lies within `MAX_DEPTH / 2` ulps (of the
//! triangle's largest coordinate) of a sub-triangle at every level, whose ancestors are those
//! of the previous level. That drift bound, raised to `2^-17` of the largest coordinate (at
//! least 64 ulps), is the *tolerance* `tol` of the test.
//!
//! A query has three steps:
//!
//! 1. The ray is cut to the stretch where it is within `tol` of the triangle's plane (plane in
//!    `f64`, computed once), intersected with `(0, t_max]`. The triangle's box must be hit
//!    within that stretch by the conservative slab test of the crate's traversals (Ize 2013);
//!    otherwise the triangle is missed. This is what keeps rays passing beside the triangle
//!    cheap: without it a ray running parallel to a tilted triangle at a distance `δ` would hit
//!    every sub-box larger than `δ` along its way.
//! 2. If the ray crosses the plane at a `t` in `(0, t_max]`, the tree is descended along the
//!    boxes that contain the crossing point (widened by `tol`), until a box is smaller than
//!    `tol`. If a leaf is reached, that is the hit: the crossing's `t`, and the leaf's
//!    barycentrics. By the drift bound this always succeeds when the crossing lies in the
//!    (closed) triangle, which is what makes meshes crack-free: a ray through a shared edge or
//!    vertex crosses the plane of each triangle around it at that very point, and is hit by all
//!    of them. No topology is involved.
//! 3. Otherwise (the crossing lies outside the triangle, or the ray runs in or nearly in the
//!    plane, or it crosses the plane behind its origin or beyond `t_max`), the thesis' search:
//!    nearest box first, into every sub-box the ray hits within the stretch, down to the
//!    leaves. The hit is the leaf with the smallest entry distance, at that distance.
//!
//! So a ray hits the triangle if its crossing with the plane lies within about `tol` of the
//! triangle, or if it runs within `tol` of the plane and hits a leaf box (to within the slab
//! test's widening of `2 gamma(3)`, about `3.6e-7` relative to the distance travelled). Only
//! hits at `t` in `(0, t_max]` count, so a ray leaving a surface from an origin within that
//! neighbourhood does not hit it.
//!
//! Triangles with a non-finite vertex or a zero geometric normal (computed in `f64`) are never
//! hit: they cover no area, and a hit on them would have no normal to shade with. Because the
//! boxes and the `f64` plane are scale-free, the test keeps working at coordinates of `1e30` or
//! `1e-30` where both analytic tests give up (their determinants overflow or underflow).
//!
//! # Cost
//!
//! A hit descends about 18 levels (until the boxes are smaller than `tol`, for a triangle whose
//! coordinates are of the order of its size), testing whether four child boxes contain a point
//! at each: some 80 box tests where the analytic tests need one determinant. A miss whose ray
//! crosses the triangle's box within the stretch descends until the sub-boxes no longer hold the
//! crossing (in step 2) or meet the ray (in step 3): few levels for a clear miss, as many as a
//! hit for a near miss. The expensive case is a ray lying (within `tol`) in the triangle's
//! plane and running alongside an edge, just outside: every sub-box larger than its distance `η`
//! to the edge is hit, about `length / η` of them. No allocation: the search uses a fixed
//! stack of [`MAX_DEPTH`] frames (about 3.5 KB) on the call stack.
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
use glam::{DVec2, DVec3, Vec3};
use rt_core::triangle::TriHit;
use rt_core::Ray;

/// Deepest subdivision level. Leaves are normally reached by level 25 or so (a box of
/// `f32::EPSILON` times the triangle's largest coordinate); the cap only stops sub-triangles that
/// rounding keeps from shrinking, and it bounds the drift (see [`TOLERANCE`]) and the stack.
pub const MAX_DEPTH: usize = 28;

/// The tolerance relative to the triangle's largest coordinate `M` (see the module
/// documentation). `ulp(M) <= M * 2^-23`, so each level moves a vertex by at most `M * 2^-24`
/// per axis, and `MAX_DEPTH` levels by at most `sqrt(3) * MAX_DEPTH * M * 2^-24` in distance.
const TOLERANCE: f64 = 1.0 / (1u64 << 18) as f64;
const _: () = assert!(1.7321 * MAX_DEPTH as f64 / (1u64 << 24) as f64 <= TOLERANCE);

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
    /// `1 / dir`: a zero component of either sign becomes an infinity of that sign.
    inv: [f32; 3],
    /// Sign bit of `inv`, which picks the near plane; the sign bit rather than `< 0` is what
    /// matches `-0.0` to its `-inf`.
    neg: [bool; 3],
    /// Finite origin and finite, non-zero direction; other rays never hit.
    valid: bool,
}

impl SubdivRay {
    /// Precomputes the slab-test constants for `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let inv = ray.dir.recip().to_array();
        Self {
            ray: *ray,
            inv,
            neg: inv.map(f32::is_sign_negative),
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
    fn slab(&self, lo: Vec3, hi: Vec3, t_start: f32, t_end: f32) -> Option<f32> {
        let org = self.ray.origin;
        let mut t0 = t_start;
        let mut t1 = t_end;
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] {
                (hi[axis], lo[axis])
            } else {
                (lo[axis], hi[axis])
            };
            // A NaN is 0 * inf: the ray runs inside the plane of a face, on the box's boundary.
            // `f32::max`/`min` return the other operand then, so the slab does not cull.
            t0 = t0.max((near - org[axis]) * self.inv[axis]);
            t1 = t1.min((far - org[axis]) * self.inv[axis]);
        }
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
    v: [Vec3; 3],
    /// Barycentrics `(b1, b2)` of `v[0]`; `v[1]` is at `anchor + (scale, 0)` and `v[2]` at
    /// `anchor + (0, scale)`. The middle child is point-reflected, so `scale` can be negative.
    anchor: DVec2,
    scale: f64,
    /// Sort keys (entry distances along the ray) and indices of the children to visit, nearest
    /// last.
    key: [f32; 4],
    child: [u8; 4],
    len: u8,
}

impl Frame {
    const EMPTY: Frame = Frame {
        v: [Vec3::ZERO; 3],
        anchor: DVec2::ZERO,
        scale: 0.0,
        key: [0.0; 4],
        child: [0; 4],
        len: 0,
    };

    /// Child `i` of this node: vertices, barycentric anchor and scale.
    #[inline(always)]
    fn child(&self, i: u8) -> ([Vec3; 3], DVec2, f64) {
        let v = &self.v;
        let m = [mid(v[0], v[1]), mid(v[1], v[2]), mid(v[2], v[0])];
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

    /// Makes this frame node `v` with the children that pass `test` (given their vertices and
    /// box, it returns a sort key), smallest key last. Returns false if none passes.
    #[inline(always)]
    fn expand<const COUNT: bool>(
        &mut self,
        v: &[Vec3; 3],
        anchor: DVec2,
        scale: f64,
        stats: &mut SubdivStats,
        mut test: impl FnMut(&[Vec3; 3], Vec3, Vec3) -> Option<f32>,
    ) -> bool {
        self.v = *v;
        self.anchor = anchor;
        self.scale = scale;
        let mut len = 0usize;
        for i in 0..4u8 {
            let c = self.child(i).0;
            let (lo, hi) = bounds(&c);
            let Some(key) = test(&c, lo, hi) else {
                continue;
            };
            // Insertion into the short list, kept in decreasing order so the nearest pops first.
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
}

/// Midpoint of `a` and `b`. Both formulas are commutative, so triangles sharing an edge split it
/// identically, and rounding keeps the result between `a` and `b`. The second one, exact halving
/// first, is only needed where the sum overflows.
#[inline(always)]
fn mid(a: Vec3, b: Vec3) -> Vec3 {
    let m = (a + b) * 0.5;
    if m.is_finite() {
        m
    } else {
        a * 0.5 + b * 0.5
    }
}

#[inline(always)]
fn bounds(v: &[Vec3; 3]) -> (Vec3, Vec3) {
    (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
}

/// Whether the child popped from `parent` at level `depth`, with box `[lo, hi]`, is a leaf.
///
/// `leaf_size` is `f32::EPSILON` times the triangle's largest coordinate: the vertices are known
/// only to that precision, so smaller boxes tell nothing more. (Boxes near a coordinate plane
/// could keep shrinking where floats are denser, for up to 150 levels at the origin.) A box
/// equal to its parent's is a sub-triangle that rounding maps onto itself (vertices a few ulps
/// apart), which would otherwise recurse, branching, down to `MAX_DEPTH`.
#[inline(always)]
fn stops(parent: &Frame, depth: usize, lo: Vec3, hi: Vec3, leaf_size: f32) -> bool {
    (hi - lo).max_element() <= leaf_size || depth == MAX_DEPTH || (lo, hi) == bounds(&parent.v)
}

#[inline(always)]
fn overlaps(lo: Vec3, hi: Vec3, p_lo: Vec3, p_hi: Vec3) -> bool {
    lo.cmple(p_hi).all() && hi.cmpge(p_lo).all()
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

/// Step 2: descends along the boxes that overlap `[p_lo, p_hi]` (the crossing point `p` widened
/// by the tolerance), the sub-triangle whose centroid is nearest to `p` first, down to a leaf.
/// Returns the first leaf's barycentric anchor and scale.
///
/// Below the tolerance every child overlaps, and the ordering is what keeps following `p`. (Box
/// centres would not do: a corner child and the middle one share their box.)
#[inline(always)]
fn locate<const COUNT: bool>(
    stack: &mut [Frame; MAX_DEPTH],
    tri: &[Vec3; 3],
    (p, p_lo, p_hi): (Vec3, Vec3, Vec3),
    leaf_size: f32,
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
    let test = |v: &[Vec3; 3], lo: Vec3, hi: Vec3| {
        overlaps(lo, hi, p_lo, p_hi)
            .then(|| ((v[0] + v[1] + v[2]) * (1.0 / 3.0) - p).length_squared())
    };
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
        f.len -= 1;
        let (v, anchor, scale) = f.child(f.child[f.len as usize]);
        let (lo, hi) = bounds(&v);
        if COUNT {
            stats.max_level = stats.max_level.max(depth as u32);
        }
        if stops(f, depth, lo, hi, leaf_size) {
            if COUNT {
                stats.leaves += 1;
            }
            return Some((anchor, scale));
        }
        if stack[depth].expand::<COUNT>(&v, anchor, scale, stats, test) {
            depth += 1;
        }
    }
    None
}

/// Step 3: the thesis' search, nearest box first, for the leaf with the smallest entry distance
/// within `[t_start, t_end]`; `root_t0` is the triangle box's entry distance.
#[inline(always)]
fn search<const COUNT: bool>(
    pre: &SubdivRay,
    stack: &mut [Frame; MAX_DEPTH],
    tri: &[Vec3; 3],
    (t_start, t_end): (f32, f32),
    root_t0: f32,
    leaf_size: f32,
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
    let test = |_: &[Vec3; 3], lo, hi| pre.slab(lo, hi, t_start, t_end);
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
        f.len -= 1;
        let k = f.len as usize;
        let t0 = f.key[k];
        let best_t = best.map_or(f32::INFINITY, |b| b.t);
        // Children are sorted, so the rest of the frame is no nearer either.
        if t0 >= best_t {
            f.len = 0;
            depth -= 1;
            continue;
        }
        let (v, anchor, scale) = f.child(f.child[k]);
        let (lo, hi) = bounds(&v);
        if COUNT && stats.boxes_tested > 2_000_000 { panic!("BUDGET"); }
        if COUNT && stats.boxes_tested > 1_999_000 { eprintln!("DBG depth {depth} t0 {t0} lo {lo:?} hi {hi:?} ext {:?} leaf_size {leaf_size} parent {:?}", hi - lo, bounds(&f.v)); }
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
        let t_end = t_end.min(best_t);
        let test = |_: &[Vec3; 3], lo, hi| pre.slab(lo, hi, t_start, t_end);
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
    // Written so that a NaN `t_max` is rejected too.
    if !pre.valid || !(t_max > 0.0) {
        return None;
    }
    // Non-finite vertices would give NaN box bounds, which the slab test treats as unbounded.
    if !(tri[0].is_finite() && tri[1].is_finite() && tri[2].is_finite()) {
        return None;
    }
    // The plane in f64: products of f32 differences neither overflow nor underflow there, so
    // the normal is exactly zero only for (nearly exactly) collinear vertices, at any scale.
    let a = tri[0].as_dvec3();
    let n = (tri[1].as_dvec3() - a).cross(tri[2].as_dvec3() - a);
    if n == DVec3::ZERO {
        return None;
    }
    let n = n / n.length();
    let (o, d) = (pre.ray.origin.as_dvec3(), pre.ray.dir.as_dvec3());
    // Signed distance from the plane along the ray: s0 + s1 t.
    let (s0, s1) = (n.dot(o - a), n.dot(d));
    let (lo, hi) = bounds(tri);
    let big = lo.abs().max(hi.abs()).max_element();
    let leaf_size = big * f32::EPSILON;
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
    if !(t_start <= t_end) {
        return None;
    }
    if COUNT {
        stats.boxes_tested += 1;
    }
    let root_t0 = pre.slab(lo, hi, t_start, t_end)?;

    let mut stack = [Frame::EMPTY; MAX_DEPTH];
    // Step 2, if the ray crosses the plane (not parallel, within range).
    let t64 = -s0 / s1;
    let t = t64 as f32;
    if t > 0.0 && t <= t_max && t.is_finite() {
        let travel = d * t64;
        let p = o + travel;
        let tol = tol + (o.abs() + travel.abs()).max_element() * F64_SLACK;
        let near_p = (p.as_vec3(), (p - tol).as_vec3(), (p + tol).as_vec3());
        if let Some((anchor, scale)) = locate::<COUNT>(&mut stack, tri, near_p, leaf_size, stats) {
            return Some(barycentrics(t, anchor, scale));
        }
    }
    // Step 3.
    if COUNT {
        stats.ray_search = true;
    }
    if COUNT { eprintln!("DBG start search {:?} {:?} {} stretch {} {} s0 {s0} s1 {s1} tol {tol}", pre.ray, tri, t_max, t_start, t_end); }
    let stretch = (t_start, t_end);
    search::<COUNT>(pre, &mut stack, tri, stretch, root_t0, leaf_size, stats)
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
        // Just outside, by far more than the resolution.
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
    fn a_hit_descends_along_the_crossing_to_the_tolerance() {
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
            assert!((20..=26).contains(&stats.max_level), "{stats:?}");
            assert!(stats.boxes_tested <= 4 * 26 + 2, "{stats:?}");
        }
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
        assert!(mid(tri[0], tri[0]).is_finite());
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
