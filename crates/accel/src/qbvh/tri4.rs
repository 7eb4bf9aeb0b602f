//! Four triangles in structure-of-arrays layout and the watertight test of one ray against all
//! four at once.
//!
//! The QBVH stores its leaves as these packets, swizzled once at build time, so the leaf test
//! loads nine registers and runs the Woop–Benthin–Wald test four lanes wide. Each lane performs
//! exactly the operations of [`rt_core::triangle::intersect_triangle`] in the same order (there
//! is no fused multiply-add on either path), so the SIMD and scalar tests agree bit for bit;
//! lanes whose edge function rounds to zero take the scalar test, which redoes them in double
//! precision.

use glam::Vec3;
use rt_core::ray::gamma;
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::Ray;

/// Four triangles: `v[3 * vertex + axis][lane]`, 144 bytes. Lanes a leaf does not fill repeat
/// its last triangle, which can only tie with a hit already found and so never wins.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct Tri4 {
    pub(crate) v: [[f32; 4]; 9],
}

const _: () = assert!(std::mem::size_of::<Tri4>() == 144);

impl Tri4 {
    /// Packs up to four triangles; missing lanes repeat the last one.
    pub(crate) fn pack(tris: &[[Vec3; 3]]) -> Self {
        debug_assert!((1..=4).contains(&tris.len()));
        let mut v = [[0.0; 4]; 9];
        for lane in 0..4 {
            let t = &tris[lane.min(tris.len() - 1)];
            for (vertex, p) in t.iter().enumerate() {
                for axis in 0..3 {
                    v[3 * vertex + axis][lane] = p[axis];
                }
            }
        }
        Self { v }
    }

    /// The triangle in `lane`.
    #[inline]
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        let p = |vertex: usize| {
            let b = 3 * vertex;
            Vec3::new(self.v[b][lane], self.v[b + 1][lane], self.v[b + 2][lane])
        };
        [p(0), p(1), p(2)]
    }
}

/// Per-ray constants of the four-wide test: the scalar test's shear, plus the permuted origin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayPrecomp4 {
    pub ray: Ray,
    pub scalar: RayPrecomp,
    k: [usize; 3],
    org: [f32; 3],
    shear: [f32; 3],
}

impl RayPrecomp4 {
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        let scalar = RayPrecomp::new(ray);
        let k = scalar.axes();
        Self {
            ray: *ray,
            scalar,
            k,
            org: k.map(|a| ray.origin[a]),
            shear: scalar.shear(),
        }
    }
}

/// Hits of one ray against the four lanes of a packet: a lane mask and each lane's `t`, `b1`,
/// `b2` (meaningful only where the mask is set).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Hits4 {
    pub mask: u32,
    pub t: [f32; 4],
    pub b1: [f32; 4],
    pub b2: [f32; 4],
}

impl Hits4 {
    #[inline(always)]
    fn set_scalar(&mut self, lane: usize, pre: &RayPrecomp, tri: &[Vec3; 3], t_max: f32) {
        self.mask &= !(1 << lane);
        if let Some(h) = intersect_triangle(pre, tri, t_max) {
            self.mask |= 1 << lane;
            self.t[lane] = h.t;
            self.b1[lane] = h.b1;
            self.b2[lane] = h.b2;
        }
    }
}

/// The scalar test on every lane: the portable fallback, and the oracle of the SIMD test.
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "sse2"),
    allow(dead_code) // used by the tests only
)]
#[inline(always)]
pub(crate) fn intersect4_scalar(pre: &RayPrecomp4, p: &Tri4, t_max: f32) -> Hits4 {
    let mut h = Hits4::default();
    for lane in 0..4 {
        h.set_scalar(lane, &pre.scalar, &p.triangle(lane), t_max);
    }
    h
}

/// [`intersect4_scalar`] with SSE2.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[allow(unsafe_code)]
#[inline(always)]
pub(crate) fn intersect4_sse(pre: &RayPrecomp4, p: &Tri4, t_max: f32) -> Hits4 {
    use std::arch::x86_64::*;
    let mut h = Hits4::default();
    let [kx, ky, kz] = pre.k;
    // SAFETY: the `cfg` guarantees SSE and SSE2 for the whole build, which is all these
    // intrinsics need. `_mm_load_ps` reads the 16-byte rows of `p.v`, which start at multiples
    // of 16 bytes in a 16-byte-aligned `Tri4`; the stores write whole local `[f32; 4]`s.
    let (zero_edge, sign_ok) = unsafe {
        let load = |vertex: usize, axis: usize| _mm_load_ps(p.v[3 * vertex + axis].as_ptr());
        let (ox, oy, oz) = (
            _mm_set1_ps(pre.org[0]),
            _mm_set1_ps(pre.org[1]),
            _mm_set1_ps(pre.org[2]),
        );
        let (sx, sy, sz) = (
            _mm_set1_ps(pre.shear[0]),
            _mm_set1_ps(pre.shear[1]),
            _mm_set1_ps(pre.shear[2]),
        );
        // Vertex relative to the origin, sheared: (x - sx z, y - sy z) and z.
        let rel = |vertex: usize| {
            let x = _mm_sub_ps(load(vertex, kx), ox);
            let y = _mm_sub_ps(load(vertex, ky), oy);
            let z = _mm_sub_ps(load(vertex, kz), oz);
            (
                _mm_sub_ps(x, _mm_mul_ps(sx, z)),
                _mm_sub_ps(y, _mm_mul_ps(sy, z)),
                z,
            )
        };
        let (ax, ay, az) = rel(0);
        let (bx, by, bz) = rel(1);
        let (cx, cy, cz) = rel(2);
        let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        let zero = _mm_setzero_ps();
        let zero_edge = _mm_movemask_ps(_mm_or_ps(
            _mm_cmpeq_ps(u, zero),
            _mm_or_ps(_mm_cmpeq_ps(v, zero), _mm_cmpeq_ps(w, zero)),
        )) as u32;
        let any_neg = _mm_or_ps(
            _mm_cmplt_ps(u, zero),
            _mm_or_ps(_mm_cmplt_ps(v, zero), _mm_cmplt_ps(w, zero)),
        );
        let any_pos = _mm_or_ps(
            _mm_cmpgt_ps(u, zero),
            _mm_or_ps(_mm_cmpgt_ps(v, zero), _mm_cmpgt_ps(w, zero)),
        );
        let mut ok = _mm_andnot_ps(
            _mm_and_ps(any_neg, any_pos),
            _mm_castsi128_ps(_mm_set1_epi32(-1)),
        );
        let det = _mm_add_ps(_mm_add_ps(u, v), w);
        // det != 0 and finite: |det| < inf (false for NaN too).
        let abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFF_FFFF));
        let abs_det = _mm_and_ps(det, abs_mask);
        ok = _mm_and_ps(ok, _mm_cmpneq_ps(det, zero));
        ok = _mm_and_ps(ok, _mm_cmplt_ps(abs_det, _mm_set1_ps(f32::INFINITY)));
        let (zs_a, zs_b, zs_c) = (_mm_mul_ps(sz, az), _mm_mul_ps(sz, bz), _mm_mul_ps(sz, cz));
        let t_scaled = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(u, zs_a), _mm_mul_ps(v, zs_b)),
            _mm_mul_ps(w, zs_c),
        );
        // ts = t_scaled with det's sign flipped away; must be > 0 (false for NaN).
        let sign = _mm_andnot_ps(abs_mask, det);
        let ts = _mm_xor_ps(t_scaled, sign);
        ok = _mm_and_ps(ok, _mm_cmpgt_ps(ts, zero));
        let inv = _mm_div_ps(_mm_set1_ps(1.0), det);
        let t = _mm_mul_ps(t_scaled, inv);
        let inf = _mm_set1_ps(f32::INFINITY);
        ok = _mm_and_ps(ok, _mm_cmpgt_ps(t, zero));
        ok = _mm_and_ps(ok, _mm_cmple_ps(t, _mm_set1_ps(t_max)));
        // Finite `t` and `1 / det`, as the scalar test requires.
        ok = _mm_and_ps(ok, _mm_cmplt_ps(t, inf));
        ok = _mm_and_ps(ok, _mm_cmplt_ps(_mm_and_ps(inv, abs_mask), inf));
        // `t` above its rounding error bound: `t_error_bound`, operation for operation.
        let abs = |x: __m128| _mm_and_ps(x, abs_mask);
        let max3 = |a: __m128, b: __m128, c: __m128| _mm_max_ps(_mm_max_ps(abs(a), abs(b)), abs(c));
        let (max_x, max_y) = (max3(ax, bx, cx), max3(ay, by, cy));
        let (max_z, max_e) = (max3(zs_a, zs_b, zs_c), max3(u, v, w));
        let g = |n: u32| _mm_set1_ps(gamma(n));
        let delta_z = _mm_mul_ps(g(3), max_z);
        let delta_x = _mm_mul_ps(g(5), _mm_add_ps(max_x, max_z));
        let delta_y = _mm_mul_ps(g(5), _mm_add_ps(max_y, max_z));
        let delta_e = _mm_mul_ps(
            _mm_set1_ps(2.0),
            _mm_add_ps(
                _mm_add_ps(
                    _mm_mul_ps(_mm_mul_ps(g(2), max_x), max_y),
                    _mm_mul_ps(delta_y, max_x),
                ),
                _mm_mul_ps(delta_x, max_y),
            ),
        );
        let delta_t = _mm_mul_ps(
            _mm_mul_ps(
                _mm_set1_ps(3.0),
                _mm_add_ps(
                    _mm_add_ps(
                        _mm_mul_ps(_mm_mul_ps(g(3), max_e), max_z),
                        _mm_mul_ps(delta_e, max_z),
                    ),
                    _mm_mul_ps(delta_z, max_e),
                ),
            ),
            abs(inv),
        );
        ok = _mm_and_ps(ok, _mm_cmpgt_ps(t, delta_t));
        _mm_storeu_ps(h.t.as_mut_ptr(), t);
        _mm_storeu_ps(h.b1.as_mut_ptr(), _mm_mul_ps(v, inv));
        _mm_storeu_ps(h.b2.as_mut_ptr(), _mm_mul_ps(w, inv));
        (zero_edge, _mm_movemask_ps(ok) as u32)
    };
    h.mask = sign_ok;
    if zero_edge != 0 {
        for lane in 0..4 {
            if zero_edge & (1 << lane) != 0 {
                h.set_scalar(lane, &pre.scalar, &p.triangle(lane), t_max);
            }
        }
    }
    h
}

/// The four-wide test used by traversal: SSE2 on x86_64 (part of its baseline), scalar elsewhere.
#[inline(always)]
pub(crate) fn intersect4(pre: &RayPrecomp4, p: &Tri4, t_max: f32) -> Hits4 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        intersect4_sse(pre, p, t_max)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        intersect4_scalar(pre, p, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lanes of a packet agree bit for bit with the scalar test, including rays along edges and
    /// through vertices (where an edge function is zero) and degenerate triangles.
    #[test]
    fn simd_and_scalar_agree() {
        let mut s = 0x9E37_79B9u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            // Few distinct values, so rays often pass exactly through edges and vertices.
            (s % 9) as f32 * 0.5 - 2.0
        };
        let mut hits = 0;
        for _ in 0..50_000 {
            let tris: Vec<[Vec3; 3]> = (0..4)
                .map(|_| [(); 3].map(|_| Vec3::new(rnd(), rnd(), rnd())))
                .collect();
            let p = Tri4::pack(&tris);
            let mut d = Vec3::new(rnd(), rnd(), rnd());
            if d == Vec3::ZERO {
                d = Vec3::Z;
            }
            let ray = Ray::new(Vec3::new(rnd(), rnd(), rnd()) * 1.5, d);
            let pre = RayPrecomp4::new(&ray);
            for t_max in [f32::INFINITY, 1.0] {
                let want = intersect4_scalar(&pre, &p, t_max);
                for (lane, tri) in tris.iter().enumerate() {
                    let h = intersect_triangle(&pre.scalar, tri, t_max);
                    assert_eq!(h.is_some(), want.mask & (1 << lane) != 0);
                }
                #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
                {
                    let got = intersect4_sse(&pre, &p, t_max);
                    assert_eq!(got.mask, want.mask, "{tris:?} {ray:?}");
                    for lane in 0..4 {
                        if want.mask & (1 << lane) != 0 {
                            hits += 1;
                            assert_eq!(got.t[lane].to_bits(), want.t[lane].to_bits());
                            assert_eq!(got.b1[lane].to_bits(), want.b1[lane].to_bits());
                            assert_eq!(got.b2[lane].to_bits(), want.b2[lane].to_bits());
                        }
                    }
                }
            }
        }
        #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
        assert!(hits > 1000, "{hits}");
    }

    #[test]
    fn pack_repeats_the_last_triangle() {
        let a = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let b = [Vec3::Z, Vec3::ONE, Vec3::NEG_ONE];
        let p = Tri4::pack(&[a, b]);
        assert_eq!(p.triangle(0), a);
        assert_eq!([p.triangle(1), p.triangle(2), p.triangle(3)], [b; 3]);
    }
}
