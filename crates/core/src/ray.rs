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
    /// When the ray is traced, as a fraction of the scene's shutter interval
    /// (`Scene::shutter`): 0 is the scene's current time (the shutter opening), 1 its closing.
    /// Only motion blur draws other values; structures that interpolate moving instances
    /// ([`crate::Accel::interpolates_motion`]) place them at this time, and rays spawned at a
    /// hit keep it ([`crate::scene::SurfaceHit::time`]).
    pub time: f32,
}

impl Ray {
    /// A ray from `origin` along `dir` at the shutter's opening (time 0).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            time: 0.0,
        }
    }

    /// The same ray at shutter time `time` (see [`Ray::time`]).
    #[inline]
    pub fn at_time(self, time: f32) -> Self {
        Self { time, ..self }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Higham's `γ(n) = n·u / (1 − n·u)` with `u = 2⁻²⁴`: a bound on the relative error that `n`
/// chained f32 roundings can accumulate (Pharr et al., "Managing rounding error", PBRT §6.8).
#[inline]
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// Where a ray leaving surface point `p` must start so that it cannot hit the surface it
/// leaves: `p` moved along the geometric normal `n` (unit, either orientation) to the side of
/// the direction `w`, by `d = dot(|n|, p_error)`, then one more ULP away from the surface per
/// axis so that rounding the sum cannot pull it back (PBRT-v4's `OffsetRayOrigin`).
///
/// `p_error` is a per-axis bound on how far the ray queries may misplace `p` relative to its
/// triangle: [`crate::triangle::point_with_error`] gives it for points reconstructed from
/// barycentrics. The offset therefore scales with the triangle the point lies on, not with the
/// point's own coordinates: a point near the origin on a triangle 10⁴ across needs an offset
/// of 10⁴ ULPs of 1, where an offset in ULPs of the point (Wächter and Binder, Ray Tracing
/// Gems ch. 6, used here before) gave 10⁻⁵ and let bounce rays re-hit the floor they left.
#[inline]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let po = p + offset;
    Vec3::new(
        ulp_toward(po.x, offset.x),
        ulp_toward(po.y, offset.y),
        ulp_toward(po.z, offset.z),
    )
}

/// `x.next_up()` if `o > 0`, `x.next_down()` if `o < 0`, else `x` (for finite `x`; infinite
/// and NaN `x` stay as they are), without branches: the sign of an offset component is a coin
/// flip per ray, and branching on it was mispredicted often enough to cost 5 % of a path. Steps
/// are on the bits: one more in magnitude when `x` and `o` have the same sign, one less when
/// not, and the smallest subnormal of `o`'s sign from a zero.
#[inline]
fn ulp_toward(x: f32, o: f32) -> f32 {
    let (bits, o_bits) = (x.to_bits(), o.to_bits());
    let away = (bits ^ o_bits) >> 31 == 0;
    let stepped = if away {
        bits.wrapping_add(1)
    } else {
        bits.wrapping_sub(1)
    };
    let stepped = if x == 0.0 {
        (o_bits & 0x8000_0000) | 1
    } else {
        stepped
    };
    if o.abs() > 0.0 && x.is_finite() {
        f32::from_bits(stepped)
    } else {
        x
    }
}

/// A ray leaving surface point `p` (error bound `p_error`, geometric normal `n`) along `w`.
#[inline]
pub fn spawn_ray(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, p_error, n, w), w)
}

/// Fraction by which shadow rays stop short of their target point. The target is offset off
/// its surface like the origin, but the ray query itself rounds `t`; stopping a relative 10⁻⁴
/// short keeps the light's own triangle from being reported as an occluder (PBRT's
/// `ShadowEpsilon`).
pub const SHADOW_EPSILON: f32 = 1e-4;

/// A shadow-ray segment from surface point `p` (error bound `p_error`, normal `n`, any
/// orientation) to a point `q` on another surface (`q_error`, normal `nq`). Both ends are
/// offset off their surfaces; the target is offset towards the *offset* origin, so two points
/// of one plane (where `n · (q − p)` is rounding noise) are moved to the same side of it and the
/// segment does not cross it. Returns the ray (direction `q' − p'`, so the segment is
/// `t ∈ (0, t_max)`) and `t_max`.
#[inline]
pub fn shadow_segment(
    p: Vec3,
    p_error: Vec3,
    n: Vec3,
    q: Vec3,
    q_error: Vec3,
    nq: Vec3,
) -> (Ray, f32) {
    let o = offset_ray_origin(p, p_error, n, q - p);
    let target = offset_ray_origin(q, q_error, nq, o - q);
    (Ray::new(o, target - o), 1.0 - SHADOW_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_bounds_chained_roundings() {
        assert_eq!(gamma(0), 0.0);
        assert!(gamma(1) > f32::EPSILON * 0.5 && gamma(1) < f32::EPSILON);
        assert!(gamma(7) > 7.0 * gamma(1) && gamma(7) < 7.001 * gamma(1));
    }

    #[test]
    fn ulp_toward_is_next_up_or_next_down() {
        let xs = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MAX,
            -f32::MAX,
            3.7e-12,
            -8.1e20,
        ];
        for x in xs {
            for o in [1e-3f32, -1e-3, 0.0, -0.0, f32::NAN] {
                let want = if o > 0.0 {
                    x.next_up()
                } else if o < 0.0 {
                    x.next_down()
                } else {
                    x
                };
                assert_eq!(ulp_toward(x, o).to_bits(), want.to_bits(), "{x:e} {o}");
            }
        }
        for x in [f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(ulp_toward(x, 1.0), x);
            assert_eq!(ulp_toward(x, -1.0), x);
        }
        assert!(ulp_toward(f32::NAN, 1.0).is_nan());
    }

    #[test]
    fn offset_moves_to_the_side_of_the_direction_at_all_scales() {
        for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e6] {
            let p = Vec3::new(0.3, -0.7, 0.5) * scale;
            let err = Vec3::splat(gamma(7) * scale);
            let n = Vec3::new(0.0, 1.0, 0.0);
            let q = offset_ray_origin(p, err, n, Vec3::new(0.2, 0.5, 0.1));
            assert!(q.y - p.y >= err.y, "scale {scale}: {q} vs {p}");
            assert_eq!(q.x, p.x);
            // The normal's orientation does not matter, the direction does.
            let q2 = offset_ray_origin(p, err, -n, Vec3::new(0.2, 0.5, 0.1));
            assert_eq!(q, q2);
            let q = offset_ray_origin(p, err, n, -Vec3::Y);
            assert!(p.y - q.y >= err.y, "scale {scale}");
        }
    }

    #[test]
    fn only_axes_with_an_offset_take_the_extra_ulp() {
        // A zero bound (a point known exactly) leaves the point alone; any non-zero bound, however
        // small, moves it by at least one ULP on the axes the normal has.
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(offset_ray_origin(p, Vec3::ZERO, Vec3::Y, Vec3::Y), p);
        let q = offset_ray_origin(p, Vec3::splat(1e-30), Vec3::Y, Vec3::Y);
        assert_eq!(q.y, 2.0f32.next_up());
    }

    #[test]
    fn shadow_segment_points_at_target() {
        let e = Vec3::splat(1e-6);
        let (r, tmax) = shadow_segment(
            Vec3::ZERO,
            e,
            Vec3::Y,
            Vec3::new(0.0, 2.0, 0.0),
            e,
            -Vec3::Y,
        );
        assert!(r.origin.y > 0.0);
        let end = r.at(tmax);
        assert!((end.y - 2.0).abs() < 1e-3 && end.y < 2.0);
    }

    #[test]
    fn shadow_segment_between_points_of_one_plane_stays_on_one_side() {
        // n · (q − p) is zero here: both ends must still go to the same side.
        let e = Vec3::splat(1e-3);
        let p = Vec3::new(-5.0, 0.0, 1.0);
        let q = Vec3::new(7.0, 0.0, -2.0);
        for n in [Vec3::Y, -Vec3::Y] {
            for nq in [Vec3::Y, -Vec3::Y] {
                let (r, t_max) = shadow_segment(p, e, n, q, e, nq);
                let end = r.at(t_max);
                assert!(r.origin.y * end.y > 0.0, "{n} {nq}: {r:?} ends at {end}");
            }
        }
    }
}
