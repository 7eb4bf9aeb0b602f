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

use crate::Ray;
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
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding of the sheared triangle: swapping kx, ky when looking down -kz.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            org: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
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
    Some(TriHit {
        t,
        b1: v_ * inv,
        b2: w * inv,
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
