//! Watertight ray–triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013).
//!
//! The ray is sheared and scaled so that it points along +z; the triangle's vertices are
//! transformed the same way and the three 2D edge functions are evaluated. Because every edge
//! function depends only on the two vertices of its edge (not on the triangle), two triangles
//! sharing an edge compute bit-identical values for it, so a ray through the edge hits at least
//! one of them. When an edge function rounds to exactly zero it is recomputed in double
//! precision, which decides the sign consistently. Valid for coordinates of magnitude up to about
//! 1e12 relative to the ray origin (beyond, the scaled distance `t·det` overflows f32). This is what makes closed meshes crack-free;
//! Möller–Trumbore, which the thesis used, is not.

use crate::{ray::gamma, Ray};
use glam::Vec3;

/// Per-ray constants of the watertight test: the axis permutation and the shear.
#[derive(Clone, Copy, Debug)]
pub struct RayPrecomp {
    /// Ray origin.
    pub org: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

/// A ray–triangle intersection: distance and the barycentric weights of vertices 1 and 2
/// (vertex 0 has weight `1 - b1 - b2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    /// Ray parameter.
    pub t: f32,
    /// Weight of vertex 1.
    pub b1: f32,
    /// Weight of vertex 2.
    pub b2: f32,
}

impl RayPrecomp {
    /// Precomputes the shear for `ray`. The direction must be non-zero and finite.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir.to_array();
        let a = ray.dir.abs();
        // Written with selects on a plain array (not `Vec3` indexing, whose bounds checks
        // and branches made this a hundred instructions): every traversal that reaches a leaf
        // pays for it once per ray.
        let kz: usize = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let next = |k: usize| if k == 2 { 0 } else { k + 1 };
        let (kx, ky) = (next(kz), next(next(kz)));
        let dz = d[kz];
        // Keep the winding of the sheared triangle: swapping kx, ky when looking down -kz.
        let (kx, ky) = if dz < 0.0 { (ky, kx) } else { (kx, ky) };
        Self {
            org: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / dz,
            sy: d[ky] / dz,
            sz: 1.0 / dz,
        }
    }

    /// The axis permutation `[kx, ky, kz]`: `kz` is the dominant axis of the direction.
    #[inline]
    pub fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    /// The shear `[sx, sy, sz]` (`sz = 1 / d[kz]`), for SIMD versions of the test that must
    /// compute exactly what [`intersect_triangle`] does.
    #[inline]
    pub fn shear(&self) -> [f32; 3] {
        [self.sx, self.sy, self.sz]
    }
}

/// Intersects a ray with triangle `v` for `t ∈ (0, t_max]`. Both faces are hit (culling is a
/// material question, not a geometric one). Degenerate (zero-area) triangles are never hit.
#[inline]
pub fn intersect_triangle(pre: &RayPrecomp, v: &[Vec3; 3], t_max: f32) -> Option<TriHit> {
    let a = v[0] - pre.org;
    let b = v[1] - pre.org;
    let c = v[2] - pre.org;
    let (kx, ky, kz) = (pre.kx, pre.ky, pre.kz);
    let ax = a[kx] - pre.sx * a[kz];
    let ay = a[ky] - pre.sy * a[kz];
    let bx = b[kx] - pre.sx * b[kz];
    let by = b[ky] - pre.sy * b[kz];
    let cx = c[kx] - pre.sx * c[kz];
    let cy = c[ky] - pre.sy * c[kz];
    let mut u = cx * by - cy * bx;
    let mut v_ = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v_ == 0.0 || w == 0.0 {
        let (ax, ay, bx, by, cx, cy) = (
            ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
        );
        u = (cx * by - cy * bx) as f32;
        v_ = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || v_ < 0.0 || w < 0.0) && (u > 0.0 || v_ > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v_ + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let az = pre.sz * a[kz];
    let bz = pre.sz * b[kz];
    let cz = pre.sz * c[kz];
    let t_scaled = u * az + v_ * bz + w * cz;
    // Sign test before dividing (cheap rejection of hits behind the origin), then the range test
    // on t itself: comparing `t_scaled` with `t_max·det` instead would overflow or underflow at
    // extreme coordinate scales. Written so that NaN fails both tests.
    let ts = if det < 0.0 { -t_scaled } else { t_scaled };
    if ts.is_nan() || ts <= 0.0 {
        return None;
    }
    // A denormal `det` (triangles around 1e-20 and smaller) makes `1 / det` overflow, and the
    // product can overflow too: neither is a usable hit, even for an unbounded ray.
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if t.is_nan() || t <= 0.0 || t > t_max || t.is_infinite() || inv.is_infinite() {
        return None;
    }
    // A NaN bound rejects (the SIMD kernels hand such lanes to this test). A hit within the
    // bound is decided again in double precision: rejecting it outright, as PBRT does, lets a
    // ray that starts in a concave corner pass through the adjacent wall (`t` 4.06e-6 against
    // a bound of 4.32e-6 on `render stress --only bad/closed-box --seed 5`).
    let bound = t_error_bound([ax, bx, cx], [ay, by, cy], [az, bz, cz], [u, v_, w], inv);
    if bound.is_nan() {
        return None;
    }
    if t <= bound {
        // Also the better hit: the bound says `t` itself may be off by more than `t`, and the
        // barycentrics by as much (slivers).
        return t_in_f64(pre, v, bound).filter(|h| h.t <= t_max);
    }
    Some(TriHit {
        t,
        b1: v_ * inv,
        b2: w * inv,
    })
}

/// A bound on the rounding error of the `t` that [`intersect_triangle`] computes, from the
/// sheared vertices, the edge functions and `1 / det` (Pharr et al., PBRT-v3 §3.9.6): a hit at
/// `t` no larger than this may lie behind the origin, and is decided again in double precision
/// (`t_in_f64`). That matters for rays that start close to a huge triangle (a blade of grass
/// on a floor 10⁵ across): the error of `t` grows with the triangle's size, not with the
/// distance to it. SIMD versions of the test compute it with
/// the same operations in the same order, so they agree bit for bit. The `max` operands are
/// absolute values of finite numbers here (non-finite `det` or `t` were rejected before).
#[inline(always)]
pub fn t_error_bound(x: [f32; 3], y: [f32; 3], z: [f32; 3], e: [f32; 3], inv_det: f32) -> f32 {
    let max3 = |v: [f32; 3]| v[0].abs().max(v[1].abs()).max(v[2].abs());
    let (max_x, max_y, max_z, max_e) = (max3(x), max3(y), max3(z), max3(e));
    let delta_z = gamma(3) * max_z;
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs()
}

/// The hit on `v` with its distance (along the sheared ray, to the plane) and barycentrics
/// computed in double precision, if the plane lies ahead of the origin: for a hit whose
/// single-precision `t` is within its error `bound`.
/// The ray and the vertices are the same `f32` values; in `f64` the vertices relative to the
/// origin are exact and every later rounding is 2⁻²⁹ of the `f32` one, so the error of this `t`
/// is the `f32` bound scaled by 2⁻²⁹ to first order (2⁻²⁶ below leaves a factor of 8). This
/// tells a true hit a few ULPs ahead (the adjacent wall of a corner the ray starts in) from a
/// hit on the surface the ray leaves, whose plane the origin offset
/// ([`crate::ray::offset_ray_origin`]) puts behind the origin by far more than 2⁻²⁶ of the
/// bound. The inside test stays the `f32` edge functions' (watertight between neighbours); only
/// the distance to the plane is computed here, and it does not depend on where in the plane
/// the ray meets it.
#[cold]
#[inline(never)]
fn t_in_f64(pre: &RayPrecomp, v: &[Vec3; 3], bound: f32) -> Option<TriHit> {
    let (kx, ky, kz) = (pre.kx, pre.ky, pre.kz);
    let (sx, sy, sz) = (pre.sx as f64, pre.sy as f64, pre.sz as f64);
    let rel = |p: Vec3| {
        let d = [
            p.x as f64 - pre.org.x as f64,
            p.y as f64 - pre.org.y as f64,
            p.z as f64 - pre.org.z as f64,
        ];
        (d[kx] - sx * d[kz], d[ky] - sy * d[kz], sz * d[kz])
    };
    let (ax, ay, az) = rel(v[0]);
    let (bx, by, bz) = rel(v[1]);
    let (cx, cy, cz) = rel(v[2]);
    let u = cx * by - cy * bx;
    let w_v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let inv = 1.0 / (u + w_v + w);
    let t = (u * az + w_v * bz + w * cz) * inv;
    let t32 = t as f32;
    if !(t > bound as f64 * (-26f64).exp2() && t32 > 0.0 && t32.is_finite()) {
        return None;
    }
    // The `f32` edge functions said inside; these may put the point a rounding error outside.
    let (b1, b2) = ((w_v * inv).max(0.0), (w * inv).max(0.0));
    let sum = (b1 + b2).max(1.0);
    Some(TriHit {
        t: t32,
        b1: (b1 / sum) as f32,
        b2: (b2 / sum) as f32,
    })
}

/// Unnormalised geometric normal `(v1 - v0) × (v2 - v0)`: it faces the side from which the
/// vertices appear counter-clockwise (the front face).
#[inline]
pub fn geometric_normal(v: &[Vec3; 3]) -> Vec3 {
    (v[1] - v[0]).cross(v[2] - v[0])
}

/// Triangle area.
#[inline]
pub fn area(v: &[Vec3; 3]) -> f32 {
    0.5 * geometric_normal(v).length()
}

/// Point from barycentric weights. Reconstructing the hit point this way rather than as
/// `o + t·d` keeps its error within a few ULPs of the vertices, which the origin offset relies on.
#[inline]
pub fn point_at(v: &[Vec3; 3], b1: f32, b2: f32) -> Vec3 {
    v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2
}

/// Largest conditioning factor `κ` (see [`point_with_error`]) the error bound uses: a triangle
/// thinner than about 1:10⁴ gets the offset of one of that aspect ratio. Its intersections are
/// noise at that level anyway (the limitation noted in `docs/architecture.md`), and an uncapped
/// `κ` would send rays from nearly degenerate triangles arbitrarily far.
pub const MAX_CONDITIONING: f32 = 1e4;

/// [`point_at`] and a per-axis bound on how far ray queries may misplace the point relative to
/// the triangle: the `p_error` that [`crate::ray::offset_ray_origin`] offsets by. Two errors add
/// up, both proportional to the *vertices'* magnitudes rather than the point's:
///
/// 1. **Reconstruction** (PBRT §6.8.5, adapted to how [`point_at`] computes): `b0 = (1 − b1) − b2`
///    is off by at most `γ(2)·(|1 − b1| + |b2|)` in absolute terms (not relative to `b0`, which
///    may be tiny), and the three products and two sums add `γ(3)·Σ|bᵢ·vᵢ|`. Both fit in
///    `γ(7)·((|1 − b1| + |b2|)·|v0| + |b1·v1| + |b2·v2|)`, the margin covering the rounding of
///    the bound itself.
/// 2. **Where the neighbours' planes are.** The two triangles of a flat quad are coplanar
///    only up to the rounding of their vertices, which a sliver turns into a tilt: a shadow
///    segment between two points of a 1:100 quad 10⁴ long, offset by the reconstruction error
///    alone, crossed the other triangle's plane for 2 % of segments (`self-hit/plane-shadow-rays`,
///    `render stress --long`). The margin is `γ(8)·(1 + min(κ, 10⁴))` times the triangle's
///    extent seen from the point *on each axis*, `maxᵢ |vᵢ − p|` per component, with
///    `κ = L² / |(v1 − v0) × (v2 − v0)|` and `L` the largest of those extents (about 1 on
///    well-shaped triangles, large on slivers). Per axis, so that an axis-aligned floor, whose
///    vertices share their coordinate along the normal, gets no lift at all: with one margin
///    for all axes, rays left a floor 2·10⁵ across 0.1 above it, over the 0.06–0.1 tall grass
///    of `gen:mixed`, and the path tracer and BDPT disagreed there by 2 % (both were off, by
///    1.5 % and 4 %, against the same scene with the floor in small cells). The test's own
///    error in `t`, which this margin used to cover for rays leaving the triangle, is now
///    handled by the test itself: a hit within its error bound is decided in double precision
///    ([`intersect_triangle`]), which puts the plane a ray leaves behind it. The constant is
///    measured, not proven: no self-hit among the stress suite's self-hit cases
///    (`self-hit/` in `crates/validate/src/stress/mod.rs`, run by `tests/tests/stress.rs` and
///    `render stress`; 1.6·10⁷ rays per seed with `--long`) and the property tests in
///    `crates/core/tests/properties.rs`.
///
/// The point returned is the one at `(b1, b2)` moved, if it is closer than twice its error
/// bound to an edge, that far into the triangle (see the comment in the body), so that an
/// origin offset from it stays on the inner side of the neighbouring triangles' planes too.
#[inline]
pub fn point_with_error(v: &[Vec3; 3], b1: f32, b2: f32) -> (Vec3, Vec3) {
    let twice_area = geometric_normal(v).length();
    let (p, err) = point_and_bound(v, b1, b2, twice_area);
    // Pull the point in from the edges by twice its error bound (which also covers the normal
    // offset, `dot(|n|, err) ≤ |err|`): reconstructed near an edge, it may otherwise lie beyond
    // the plane of the neighbouring triangle, and a ray offset along this triangle's own normal
    // stays beyond it. Far from the origin that lets rays escape closed meshes at their edges
    // (a box 200 across at 10⁵: the error is 6 ULPs of 10⁵, 0.05). The point moves by at most
    // a few error bounds, within its own uncertainty; shading keeps the original barycentrics.
    let b = [1.0 - b1 - b2, b1, b2];
    if clear_of_edges(v, b, err, twice_area) {
        return (p, err);
    }
    let e = 2.0 * err.length();
    let edge = [
        (v[2] - v[1]).length(),
        (v[0] - v[2]).length(),
        (v[1] - v[0]).length(),
    ];
    // Barycentric weight of vertex i at distance e from the opposite edge: e / altitude.
    let b_min = edge.map(|l| e * l / twice_area);
    let room = 1.0 - (b_min[0] + b_min[1] + b_min[2]);
    // Without an interior point that far from every edge (a sliver about as thin as the
    // error, or a degenerate triangle), leave the point where it is.
    if room.is_nan() || room <= 0.0 || b.iter().zip(&b_min).all(|(b, m)| b >= m) {
        return (p, err);
    }
    // Move to the nearest point of the inset triangle {bᵢ ≥ b_minᵢ} (similar to this one, its
    // edges `e` inside). The nearest point in space, not in barycentric terms: on a sliver one
    // barycentric step along the long edges is metres, and an earlier rescaling of the weights
    // moved hits on a 2000 × 25 fan triangle by up to 20 units (shadows vanished).
    let corner = |i: usize| {
        let mut c = b_min;
        c[i] += room;
        point_at(v, c[1], c[2]) - v[0]
    };
    let w = closest_on_triangle(p - v[0], [corner(0), corner(1), corner(2)]);
    // An inset triangle that rounds to a degenerate one (tiny triangles far out) has no face.
    if !w.iter().all(|w| w.is_finite()) {
        return (p, err);
    }
    let pulled = [0, 1, 2].map(|i| b_min[i] + room * w[i]);
    let (q, q_err) = point_and_bound(v, pulled[1], pulled[2], twice_area);
    // Near a sharp corner the inset triangle starts `e / sin(angle / 2)` away (45 units at the
    // centre of that fan). Like a sliver too thin for any inset, such a corner keeps its point:
    // moving it further than a few error bounds would shift shadows visibly. `3e` still covers
    // the 45° corners of split rectangles (2.6e).
    if (q - p).length() > 3.0 * e {
        return (p, err);
    }
    (q, q_err)
}

/// Barycentric weights of the point of triangle `t` nearest to `p` (Ericson, *Real-Time
/// Collision Detection*, §5.1.5), by Voronoi regions so that no division by a tiny area occurs
/// outside the face region.
fn closest_on_triangle(p: Vec3, t: [Vec3; 3]) -> [f32; 3] {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let s = d1 / (d1 - d3);
        return [1.0 - s, s, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let s = d2 / (d2 - d6);
        return [1.0 - s, 0.0, s];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - s, s];
    }
    let denom = 1.0 / (va + vb + vc);
    let (s, u) = (vb * denom, vc * denom);
    [1.0 - s - u, s, u]
}

/// True if every barycentric weight clearly exceeds its `b_min` in [`point_with_error`], decided
/// without square roots (squared, with a relative margin of 10⁻⁵ that is far above the few ULPs
/// by which the two forms may round apart). Almost every point is clear; the rest take the exact
/// test, so the result is bit for bit the one of the exact test alone.
#[inline]
fn clear_of_edges(v: &[Vec3; 3], b: [f32; 3], err: Vec3, twice_area: f32) -> bool {
    let e2 = 4.0 * err.length_squared() * (1.0 + 1e-5);
    let edge2 = [
        (v[2] - v[1]).length_squared(),
        (v[0] - v[2]).length_squared(),
        (v[1] - v[0]).length_squared(),
    ];
    (0..3).all(|i| {
        let lhs = b[i] * twice_area;
        b[i] >= 0.0 && lhs * lhs >= e2 * edge2[i]
    })
}

/// [`point_at`] and its error bound (the two parts of [`point_with_error`]'s documentation);
/// `twice_area` is `|(v1 − v0) × (v2 − v0)|`.
#[inline]
fn point_and_bound(v: &[Vec3; 3], b1: f32, b2: f32, twice_area: f32) -> (Vec3, Vec3) {
    let p = point_at(v, b1, b2);
    let reconstruction =
        ((1.0 - b1).abs() + b2.abs()) * v[0].abs() + b1.abs() * v[1].abs() + b2.abs() * v[2].abs();
    let extent = (v[0] - p).abs().max((v[1] - p).abs()).max((v[2] - p).abs());
    let l = extent.max_element();
    // Zero area gives κ = ∞, or NaN from 0/0, which `f32::min` also turns into the cap.
    let kappa = (l * l / twice_area).min(MAX_CONDITIONING);
    let test = gamma(8) * (1.0 + kappa) * extent;
    (p, gamma(7) * reconstruction + test)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(o: Vec3, d: Vec3, tri: &[Vec3; 3]) -> Option<TriHit> {
        intersect_triangle(&RayPrecomp::new(&Ray::new(o, d)), tri, f32::INFINITY)
    }

    #[test]
    fn hits_both_faces_and_reports_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let h = hit(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z, &tri).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!((h.b1 - 0.25).abs() < 1e-6 && (h.b2 - 0.5).abs() < 1e-6);
        let h = hit(Vec3::new(0.25, 0.5, -2.0), Vec3::Z, &tri).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
    }

    /// The wall ahead of a ray that starts in a concave corner: a bounce ray of
    /// `render stress --only bad/closed-box --seed 5` leaving the wall x = −1 of the box
    /// [−1, 1]³ at 2.3·10⁻⁶ from the wall z = −1 and heading through it.
    fn corner() -> ([Vec3; 3], Vec3, Vec3) {
        let tri = [
            Vec3::new(-1.0, 0.333_333_37, -1.0),
            Vec3::new(-0.666_666_6, 0.666_666_6, -1.0),
            Vec3::new(-1.0, 0.666_666_6, -1.0),
        ];
        let o = Vec3::new(-0.999_999_2, 0.336_885_27, -0.999_997_74);
        (tri, o, Vec3::new(0.822_854_2, 0.110_302_76, -0.557_444_4))
    }

    #[test]
    fn a_hit_within_the_error_bound_is_decided_in_double_precision() {
        let (tri, o, d) = corner();
        let pre = RayPrecomp::new(&Ray::new(o, d));
        // The single-precision bound cannot tell this `t` from zero (PBRT rejects the hit and
        // the ray leaves the box through the wall)...
        let rel = |p: Vec3| {
            let a = p - pre.org;
            (
                a[pre.kx] - pre.sx * a[pre.kz],
                a[pre.ky] - pre.sy * a[pre.kz],
                pre.sz * a[pre.kz],
            )
        };
        let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = tri.map(rel);
        let (u, v, w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
        let inv = 1.0 / (u + v + w);
        let t = (u * az + v * bz + w * cz) * inv;
        let bound = t_error_bound([ax, bx, cx], [ay, by, cy], [az, bz, cz], [u, v, w], inv);
        assert!(t > 0.0 && t <= bound, "t {t}, bound {bound}");
        // ...and it is a hit, at the distance to the plane.
        let h = intersect_triangle(&pre, &tri, f32::INFINITY).expect("the wall ahead");
        let want = (o.z + 1.0) / -d.z;
        assert!((h.t - want).abs() < 1e-6 * want, "{} against {want}", h.t);
        // Controls, from the same point: moving away from the wall (its plane 4·10⁻⁶ behind)
        // and starting in the wall's plane itself (the surface a ray leaves) are no hits.
        assert!(hit(o, d * Vec3::new(1.0, 1.0, -1.0), &tri).is_none());
        for z in [1.0f32, -1.0] {
            let on_plane = Vec3::new(o.x, o.y, -1.0);
            assert!(hit(on_plane, d * Vec3::new(1.0, 1.0, z), &tri).is_none());
        }
    }

    #[test]
    fn misses_outside_behind_and_beyond_tmax() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(hit(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z, &tri).is_none());
        assert!(hit(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, &tri).is_none());
        let pre = RayPrecomp::new(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z));
        assert!(intersect_triangle(&pre, &tri, 0.5).is_none());
        assert!(intersect_triangle(&pre, &tri, 1.0).is_some());
    }

    #[test]
    fn tiny_triangles_never_give_infinite_hits() {
        for scale in [1e-18f32, 1e-20, 1e-22, 1e-25] {
            let tri = [Vec3::ZERO, Vec3::X * scale, Vec3::Y * scale];
            let o = Vec3::new(0.25, 0.25, 1.0) * scale;
            if let Some(h) = hit(o, -Vec3::Z, &tri) {
                assert!(
                    h.t.is_finite() && h.b1.is_finite() && h.b2.is_finite(),
                    "{h:?}"
                );
            }
        }
    }

    #[test]
    fn degenerate_triangles_are_never_hit() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert!(hit(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z, &tri).is_none());
        let tri = [Vec3::ONE; 3];
        assert!(hit(Vec3::new(1.0, 1.0, 2.0), -Vec3::Z, &tri).is_none());
    }

    #[test]
    fn points_near_an_edge_are_pulled_in_by_their_error() {
        // A wall of a box 200 across, 10⁵ from the origin; a hit right on its top edge.
        let t = Vec3::new(6e4, 4.8e4, -6.4e4);
        let v = [
            t + Vec3::new(-100.0, -100.0, 100.0),
            t + Vec3::new(100.0, -100.0, 100.0),
            t + Vec3::new(100.0, 100.0, 100.0),
        ];
        // b0 = 0: on the edge v1–v2 (x = t.x + 100).
        let (p, err) = point_with_error(&v, 0.4, 0.6);
        assert!(err.max_element() > 0.01, "{err}");
        assert!(p.x <= t.x + 100.0 - err.length(), "{p} {err}");
        assert!((p.y - (t.y + 20.0)).abs() < 10.0 * err.length(), "{p}");
        // Away from the edges nothing moves.
        assert_eq!(point_with_error(&v, 0.3, 0.3).0, point_at(&v, 0.3, 0.3));
        // Degenerate and needle triangles keep their point and get a finite bound.
        for v in [
            [Vec3::ONE; 3],
            [Vec3::ZERO, Vec3::X, Vec3::X * (1.0 + 1e-7)],
        ] {
            let (p, err) = point_with_error(&v, 0.0, 0.5);
            assert_eq!(p, point_at(&v, 0.0, 0.5));
            assert!(err.is_finite(), "{err}");
        }
    }

    #[test]
    fn pulled_points_move_by_their_error_not_along_slivers() {
        // One triangle of a 512-sliver fan 2000 in radius (2000 × 25): a hit on a long edge moves
        // off that edge by a few error bounds and no further along it.
        let r = 2000.0f32;
        let a = std::f32::consts::TAU / 512.0;
        let v = [
            Vec3::ZERO,
            Vec3::new(r, 0.0, 0.0),
            Vec3::new(r * a.cos(), 0.0, r * a.sin()),
        ];
        for (b1, b2) in [(0.5, 0.0), (0.0, 0.5), (0.05, 0.0), (0.9, 0.0), (0.3, 0.7)] {
            let (p, err) = point_with_error(&v, b1, b2);
            let q = point_at(&v, b1, b2);
            let moved = (p - q).length();
            assert!(
                moved <= 6.0 * err.length() + 1e-3,
                "({b1}, {b2}) moved {moved}, err {err}"
            );
            assert!(moved > 0.0, "({b1}, {b2}) on an edge was not pulled in");
        }
        // Within 45 units of the sharp corner no point is far enough from both long edges: the
        // point stays (it was pulled out to the inset triangle's corner, 45 units away).
        assert_eq!(point_with_error(&v, 1e-4, 1e-4).0, point_at(&v, 1e-4, 1e-4));
    }

    #[test]
    fn shared_edge_is_hit_by_one_of_two_triangles() {
        // Two triangles share the diagonal of the unit square; rays exactly on it hit one.
        let a = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        let b = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        for i in 1..100 {
            let s = i as f32 / 100.0;
            let o = Vec3::new(s, s, 0.0);
            let d = Vec3::new(0.013, -0.021, -1.0);
            let o = o - d; // the ray passes through (s, s, 0)
            assert!(
                hit(o, d, &a).is_some() || hit(o, d, &b).is_some(),
                "gap at {s}"
            );
        }
    }
}
