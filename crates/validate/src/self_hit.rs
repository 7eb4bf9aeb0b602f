//! Self-intersection counts: rays that leave a surface and hit it again.
//!
//! A ray leaving a planar triangle can never meet that triangle's plane again, so every hit on
//! the triangle it left is a false one, whatever its `t`. The counts here test the spawned ray
//! against its source triangle directly with the same watertight test every structure uses
//! (the QBVH's SIMD test computes the same bits), so no bounding-box culling can hide a false
//! hit. The binary BVH, for instance, culls a flat floor's box for rays leaving it upwards and
//! never shows the floor's self-hits, while the QBVH, which tests the floor in a leaf shared
//! with other triangles, reported them for 9.7 % of bounce rays on `gen:mixed` before the
//! offset took the triangle's size into account.

use crate::Rng;
use rt_core::{
    frame::Frame,
    glam::{Quat, Vec2, Vec3},
    ray::{shadow_segment, spawn_ray},
    sampling::cosine_hemisphere,
    triangle::{self, intersect_triangle, RayPrecomp},
    Accel, Camera, Ray, Scene,
};

/// How many rays were traced and how many of them hit what they should not have.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SelfHits {
    /// Rays traced.
    pub rays: u64,
    /// Rays that hit the surface they left (or, for shadow rays, were occluded by it).
    pub hits: u64,
    /// Largest `t` of such a hit (0 if none), in units of the ray direction's length.
    pub worst_t: f32,
}

impl SelfHits {
    fn record(&mut self, t: Option<f32>) {
        self.rays += 1;
        if let Some(t) = t {
            self.hits += 1;
            self.worst_t = self.worst_t.max(t);
        }
    }

    /// Fraction of rays that self-intersected.
    pub fn fraction(&self) -> f64 {
        self.hits as f64 / self.rays.max(1) as f64
    }
}

impl std::ops::AddAssign for SelfHits {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.hits += o.hits;
        self.worst_t = self.worst_t.max(o.worst_t);
    }
}

/// The first hit of `ray` on any of `tris` with `t ∈ (0, t_max]`, by the watertight test.
fn hit_any(ray: &Ray, tris: &[[Vec3; 3]], t_max: f32) -> Option<f32> {
    let pre = RayPrecomp::new(ray);
    tris.iter()
        .filter_map(|v| intersect_triangle(&pre, v, t_max))
        .map(|h| h.t)
        .reduce(f32::min)
}

/// A quad `centre ± a ± b` as two triangles sharing the diagonal.
fn quad(centre: Vec3, a: Vec3, b: Vec3) -> [[Vec3; 3]; 2] {
    let (p0, p1, p2, p3) = (
        centre - a - b,
        centre + a - b,
        centre + a + b,
        centre - a + b,
    );
    [[p0, p1, p2], [p0, p2, p3]]
}

/// Planar surfaces of huge triangles (vertex coordinates 10³ to 10⁵), each a quad of two
/// triangles: axis-aligned floors through and beside the origin (the conference room's and
/// `gen:mixed`'s case: an exact coordinate along the normal, so no reconstruction error there),
/// tilted planes near and far from the origin, and a 1:100 sliver pair.
pub fn huge_surfaces() -> Vec<(&'static str, [[Vec3; 3]; 2])> {
    let tilt = Quat::from_euler(rt_core::glam::EulerRot::XYZ, 0.3, 0.7, 0.2);
    vec![
        (
            "floor y=0, 2e4 across",
            quad(Vec3::ZERO, Vec3::X * 1e4, Vec3::Z * 1e4),
        ),
        (
            "floor y=-2.79, 2.7e3 across, off-centre",
            quad(
                Vec3::new(330.0, -2.7924, -190.0),
                Vec3::X * 1350.0,
                Vec3::Z * 860.0,
            ),
        ),
        (
            "floor y=0, 2e5 across (gen:mixed)",
            quad(Vec3::ZERO, Vec3::X * 1e5, Vec3::Z * 1e5),
        ),
        (
            "wall x=1e3, 2e4 across",
            quad(Vec3::X * 1e3, Vec3::Y * 1e4, Vec3::Z * 1e4),
        ),
        (
            "tilted, 2e4 across",
            quad(
                Vec3::new(3.0, 1.0, 2.0),
                tilt * Vec3::X * 1e4,
                tilt * Vec3::Z * 1e4,
            ),
        ),
        (
            "tilted, 3e4 from the origin",
            quad(Vec3::splat(3e4), tilt * Vec3::X * 1e4, tilt * Vec3::Z * 1e4),
        ),
        (
            "tilted 1:100 sliver",
            quad(Vec3::ZERO, tilt * Vec3::X * 1e4, tilt * Vec3::Z * 1e2),
        ),
    ]
}

/// Barycentrics `(b1, b2)` of a point on triangle `v`: uniform over the triangle, or (every
/// other call) of a point within `radius` of the world origin projected onto the plane, when
/// that lies inside, because that is where an offset in ULPs of the point fails.
fn sample_point(rng: &mut Rng, v: &[Vec3; 3], near_origin: bool) -> (f32, f32) {
    if near_origin {
        let n = triangle::geometric_normal(v);
        let x = rng.cube() * 10f32.powf(rng.range(-4.0, 1.0));
        let x = x - n * (n.dot(x - v[0]) / n.length_squared());
        // Barycentrics by areas, in f64 so that choosing the point adds no error of its own.
        let d = |a: Vec3| a.as_dvec3();
        let (a, b, c, x) = (d(v[0]), d(v[1]), d(v[2]), d(x));
        let n = (b - a).cross(c - a);
        let b1 = (x - a).cross(c - a).dot(n) / n.length_squared();
        let b2 = (b - a).cross(x - a).dot(n) / n.length_squared();
        if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 {
            return (b1 as f32, b2 as f32);
        }
    }
    rt_core::sampling::uniform_triangle(Vec2::new(rng.f32(), rng.f32()))
}

/// A direction on the side of unit normal `n` given by `side`, with `cos θ ≥ min_cos`: cosine
/// distributed, and every third one pushed towards grazing.
fn leaving_direction(rng: &mut Rng, n: Vec3, side: f32, min_cos: f32) -> Vec3 {
    let n = n * side;
    loop {
        let mut local = cosine_hemisphere(Vec2::new(rng.f32(), rng.f32()));
        if rng.f32() < 1.0 / 3.0 {
            local.z *= 1e-2;
        }
        let w = Frame::from_normal(n).to_world(local.normalize());
        if w.dot(n) >= min_cos {
            return w;
        }
    }
}

/// Smallest cosine between a test ray and the surface it leaves. Below about 10⁻⁴ the
/// direction's own rounding decides which side of a huge plane it is on.
pub const MIN_COS: f32 = 1e-4;

/// Rays from random points of [`huge_surfaces`] (half of them near the world origin) in random
/// directions leaving the surface on either side: how many hit either triangle of the quad
/// they left.
pub fn huge_triangles(rays_per_surface: usize, seed: u64) -> Vec<(&'static str, SelfHits)> {
    huge_surfaces()
        .into_iter()
        .enumerate()
        .map(|(k, (name, tris))| {
            let mut rng = Rng::new(seed ^ (k as u64) << 32);
            let mut stats = SelfHits::default();
            for i in 0..rays_per_surface {
                let v = &tris[i % 2];
                let (b1, b2) = sample_point(&mut rng, v, i % 4 < 2);
                let (p, p_error) = triangle::point_with_error(v, b1, b2);
                let n = triangle::geometric_normal(v).normalize();
                let side = if rng.f32() < 0.5 { 1.0 } else { -1.0 };
                let w = leaving_direction(&mut rng, n, side, MIN_COS);
                let ray = spawn_ray(p, p_error, n, w);
                stats.record(hit_any(&ray, &tris, f32::INFINITY));
            }
            (name, stats)
        })
        .collect()
}

/// Shadow rays between two random points of one plane made of huge triangles (each end on
/// either triangle, its normal given either orientation): how many the plane occludes.
pub fn plane_shadow_rays(rays_per_surface: usize, seed: u64) -> Vec<(&'static str, SelfHits)> {
    huge_surfaces()
        .into_iter()
        .enumerate()
        .map(|(k, (name, tris))| {
            let mut rng = Rng::new(seed ^ 0x5a5a ^ (k as u64) << 32);
            let mut stats = SelfHits::default();
            for i in 0..rays_per_surface {
                let (va, vb) = (&tris[i % 2], &tris[(i / 2) % 2]);
                let (a1, a2) = sample_point(&mut rng, va, i % 8 < 4);
                let (c1, c2) = sample_point(&mut rng, vb, i % 3 == 0);
                let (p, pe) = triangle::point_with_error(va, a1, a2);
                let (q, qe) = triangle::point_with_error(vb, c1, c2);
                let sign = |r: &mut Rng| if r.f32() < 0.5 { 1.0 } else { -1.0 };
                let n = triangle::geometric_normal(va).normalize() * sign(&mut rng);
                let nq = triangle::geometric_normal(vb).normalize() * sign(&mut rng);
                if (q - p).length() <= 0.0 {
                    continue;
                }
                let (ray, t_max) = shadow_segment(p, pe, n, q, qe, nq);
                stats.record(hit_any(&ray, &tris, t_max));
            }
            (name, stats)
        })
        .collect()
}

/// Bounce rays of a scene: one camera ray through every pixel of a `width × height` image
/// (jittered), and from each first hit `per_hit` cosine-distributed rays leaving the surface on
/// the side the camera sees, spawned as the path tracer spawns them. Counts the rays that hit
/// their source triangle (tested directly) or whose closest hit in `accel` is that triangle.
pub fn bounce_rays(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    (width, height): (u32, u32),
    per_hit: u32,
    seed: u64,
) -> SelfHits {
    use rayon::prelude::*;
    let sx = camera.width as f32 / width as f32;
    let sy = camera.height as f32 / height as f32;
    (0..height)
        .into_par_iter()
        .map(|y| {
            let mut rng = Rng::new(seed ^ ((y as u64) << 20));
            let mut stats = SelfHits::default();
            for x in 0..width {
                let film = Vec2::new((x as f32 + rng.f32()) * sx, (y as f32 + rng.f32()) * sy);
                let primary = camera.generate_ray(film, Vec2::splat(0.5));
                let Some(hit) = accel.intersect(&primary, f32::INFINITY) else {
                    continue;
                };
                let si = scene.surface(&hit, 0.0);
                let n = if si.ng.dot(primary.dir) < 0.0 {
                    si.ng
                } else {
                    -si.ng
                };
                let source = &scene.triangles[hit.prim as usize];
                for _ in 0..per_hit {
                    let w = leaving_direction(&mut rng, n, 1.0, MIN_COS);
                    let ray = spawn_ray(si.p, si.p_error, si.ng, w);
                    let direct = hit_any(&ray, std::slice::from_ref(source), f32::INFINITY);
                    let via_accel = accel
                        .intersect(&ray, f32::INFINITY)
                        .filter(|h| h.prim == hit.prim)
                        .map(|h| h.t);
                    stats.record(direct.or(via_accel));
                }
            }
            stats
        })
        .reduce(SelfHits::default, |mut a, b| {
            a += b;
            a
        })
}
