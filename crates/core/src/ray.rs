//! Rays and robust ray-origin offsetting.

use glam::Vec3;

/// A ray with origin and direction. The direction need not be normalised; `t` is measured in
/// units of its length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (any non-zero length).
    pub dir: Vec3,
}

impl Ray {
    /// A ray from `origin` along `dir`.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Moves a surface point off its surface along the geometric normal `n`, which must point to the
/// side the new ray leaves towards.
///
/// This is the method of Wächter and Binder ("A Fast and Robust Method for Avoiding
/// Self-Intersection", Ray Tracing Gems, ch. 6): far from the origin the offset is a fixed number
/// of ULPs in integer space, so it scales with the magnitude of the coordinates and there is no
/// scene-scale epsilon to tune; near the origin, where ULPs become tiny, a small absolute offset
/// takes over. It assumes the point was reconstructed from barycentrics (as `rt-core` does), whose
/// error is a few ULPs of the vertex coordinates.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let off = |p: f32, n: f32| -> f32 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let of_i = (INT_SCALE * n) as i32;
        let bits = p.to_bits() as i32;
        let moved = if p < 0.0 { bits - of_i } else { bits + of_i };
        f32::from_bits(moved as u32)
    };
    Vec3::new(off(p.x, n.x), off(p.y, n.y), off(p.z, n.z))
}

/// Fraction by which shadow rays stop short of their target point, so that the light's own
/// surface (offset just like any other) is not reported as an occluder.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// A shadow-ray segment from surface point `p` (normal `n`, any orientation) to a point `q` on
/// another surface with normal `nq`: both ends are offset off their surfaces towards each other.
/// Returns the ray (direction `q' - p'`, so the segment is `t ∈ (0, t_max)`) and `t_max`.
#[inline]
pub fn shadow_segment(p: Vec3, n: Vec3, q: Vec3, nq: Vec3) -> (Ray, f32) {
    let d = q - p;
    let n_out = if n.dot(d) >= 0.0 { n } else { -n };
    let nq_out = if nq.dot(d) <= 0.0 { nq } else { -nq };
    let o = offset_ray_origin(p, n_out);
    let target = offset_ray_origin(q, nq_out);
    (Ray::new(o, target - o), 1.0 - SHADOW_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_normal_side_at_all_scales() {
        for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e6] {
            let p = Vec3::new(0.3, -0.7, 0.5) * scale;
            let n = Vec3::new(0.0, 1.0, 0.0);
            let q = offset_ray_origin(p, n);
            assert!(q.y > p.y, "scale {scale}: {q} vs {p}");
            assert_eq!(q.x, p.x);
            let q = offset_ray_origin(p, -n);
            assert!(q.y < p.y, "scale {scale}");
        }
    }

    #[test]
    fn shadow_segment_points_at_target() {
        let (r, tmax) = shadow_segment(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 2.0, 0.0), -Vec3::Y);
        let end = r.at(tmax);
        assert!((end.y - 2.0).abs() < 1e-3 && end.y < 2.0);
    }
}
