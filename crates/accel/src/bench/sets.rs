//! Generating the ray sets.
//!
//! Secondary rays start where the path integrator's would: at the hit point reconstructed from
//! barycentrics, offset along the geometric normal by its error bound
//! (`rt_core::ray::spawn_ray`, `shadow_segment`).

use super::rng::ray_rng;
use rayon::prelude::*;
use rt_core::{
    color::luminance,
    frame::Frame,
    glam::{Vec2, Vec3},
    ray::{shadow_segment, spawn_ray},
    sampling::{cosine_hemisphere, uniform_sphere, uniform_triangle},
    triangle, Aabb, Accel, Camera, Ray, Scene,
};

/// The generated sets' names, in report order; each is also its file's stem (`NAME.bin`).
pub const SET_NAMES: [&str; 4] = ["primary", "incoherent", "shadow", "uniform"];

/// Set numbers in the random number streams (kept from the first generator, so the older sets
/// are unchanged).
const PRIMARY: u64 = 0;
const INCOHERENT: u64 = 1;
const SHADOW: u64 = 2;
const UNIFORM: u64 = 3;

/// How a set is traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// `intersect(ray, ∞)`.
    Closest,
    /// `occluded(ray, 1)`: the direction spans the whole segment.
    Occluded,
}

impl Query {
    /// The query of the set named `name`: occlusion for `shadow`, closest hit otherwise.
    pub fn of_set(name: &str) -> Self {
        if name == "shadow" {
            Query::Occluded
        } else {
            Query::Closest
        }
    }

    /// Upper end of the query interval.
    pub fn t_max(self) -> f32 {
        match self {
            Query::Closest => f32::INFINITY,
            Query::Occluded => 1.0,
        }
    }
}

/// A named set of rays.
#[derive(Clone, Debug, PartialEq)]
pub struct RaySet {
    /// `primary`, `incoherent`, `shadow`, `uniform` or `file`.
    pub name: &'static str,
    /// The rays.
    pub rays: Vec<Ray>,
    /// How to trace them.
    pub query: Query,
}

impl RaySet {
    /// Upper end of the query interval.
    pub fn t_max(&self) -> f32 {
        self.query.t_max()
    }
}

/// The four generated sets.
#[derive(Clone, Debug)]
pub struct Generated {
    /// One jittered camera ray per pixel.
    pub primary: RaySet,
    /// A cosine-distributed bounce from each primary hit.
    pub incoherent: RaySet,
    /// A segment from each primary hit to a light point (occlusion over (0, 1)).
    pub shadow: RaySet,
    /// As many rays as pixels, from [`uniform`] over the scene's bounds.
    pub uniform: RaySet,
}

impl Generated {
    /// The sets in [`SET_NAMES`] order.
    pub fn sets(&self) -> [&RaySet; 4] {
        [&self.primary, &self.incoherent, &self.shadow, &self.uniform]
    }

    /// The sets by value, in [`SET_NAMES`] order.
    pub fn into_sets(self) -> [RaySet; 4] {
        [self.primary, self.incoherent, self.shadow, self.uniform]
    }
}

/// Where shadow rays go.
#[derive(Clone, Debug)]
pub enum Lights {
    /// Emissive triangles, chosen in proportion to their power (area × luminance × faces):
    /// their indices and the running sum of their powers.
    Emitters {
        /// Triangle indices.
        prims: Vec<u32>,
        /// Running sum of their powers.
        cdf: Vec<f64>,
    },
    /// One point (scenes without emissive triangles).
    Point(Vec3),
}

impl Lights {
    /// The scene's emissive triangles, or the point `fallback` if it has none.
    pub fn of(scene: &Scene, fallback: Vec3) -> Self {
        let mut prims = Vec::new();
        let mut cdf = Vec::new();
        let mut sum = 0.0f64;
        for (i, v) in scene.triangles.iter().enumerate() {
            let m = scene.material_of(i as u32);
            let power = triangle::area(v) * luminance(m.emission) * m.emitting_faces();
            if m.is_emissive() && power > 0.0 && power.is_finite() {
                sum += power as f64;
                prims.push(i as u32);
                cdf.push(sum);
            }
        }
        if prims.is_empty() {
            Lights::Point(fallback)
        } else {
            Lights::Emitters { prims, cdf }
        }
    }

    /// For progress lines.
    pub fn describe(&self) -> String {
        match self {
            Lights::Emitters { prims, .. } => format!("{} emissive triangles", prims.len()),
            Lights::Point(p) => format!(
                "a point light at ({}, {}, {}) (the scene has no emissive triangles)",
                p.x, p.y, p.z
            ),
        }
    }

    /// A point on a light, its error bound and its normal (zero error and normal for the point
    /// light, which needs no offset).
    fn sample(&self, scene: &Scene, u_sel: f32, u: Vec2) -> (Vec3, Vec3, Vec3) {
        match self {
            Lights::Point(p) => (*p, Vec3::ZERO, Vec3::ZERO),
            Lights::Emitters { prims, cdf } => {
                let total = *cdf.last().expect("at least one emitter");
                let target = u_sel as f64 * total;
                let k = cdf.partition_point(|&c| c <= target).min(prims.len() - 1);
                let v = &scene.triangles[prims[k] as usize];
                let (b1, b2) = uniform_triangle(u);
                let n = triangle::geometric_normal(v).normalize_or_zero();
                let (p, p_error) = triangle::point_with_error(v, b1, b2);
                (p, p_error, n)
            }
        }
    }
}

/// `count` rays with origins uniform in `bounds` and unit directions uniform on the sphere,
/// closest-hit queries; a function of (`seed`, ray index) only.
pub fn uniform(bounds: &Aabb, count: usize, seed: u64) -> RaySet {
    let rays = (0..count as u64)
        .into_par_iter()
        .map(|k| {
            let mut rng = ray_rng(seed, UNIFORM, k);
            let u = Vec3::new(rng.f32(), rng.f32(), rng.f32());
            // lerp, clamped so that rounding cannot leave the box.
            let origin = (bounds.min + (bounds.max - bounds.min) * u).clamp(bounds.min, bounds.max);
            Ray::new(origin, uniform_sphere(rng.vec2()))
        })
        .collect();
    RaySet {
        name: "uniform",
        rays,
        query: Query::Closest,
    }
}

/// Generates the four sets on the current rayon pool. Primary: one ray per pixel of `camera`,
/// jittered uniformly within the pixel. For each primary hit of `reference`: incoherent, a
/// cosine-distributed direction about the geometric normal on the side the primary ray came
/// from; shadow, the segment to a point sampled on `lights`, skipped when the light is behind
/// the surface as seen by the primary ray (an opaque surface would not cast it). Uniform: as
/// many rays as pixels from [`uniform`] over the bounds of the scene's triangles.
pub fn generate(
    scene: &Scene,
    camera: &Camera,
    reference: &dyn Accel,
    lights: &Lights,
    seed: u64,
) -> Generated {
    let w = camera.width as u64;
    let n = w * camera.height as u64;
    let primary: Vec<Ray> = (0..n)
        .into_par_iter()
        .map(|k| {
            let mut rng = ray_rng(seed, PRIMARY, k);
            let pixel = Vec2::new((k % w) as f32, (k / w) as f32);
            let film = pixel + rng.vec2();
            camera.generate_ray(film, rng.vec2())
        })
        .collect();
    let hits: Vec<_> = primary
        .par_iter()
        .map(|r| reference.intersect(r, f32::INFINITY))
        .collect();
    let incoherent: Vec<Ray> = hits
        .par_iter()
        .zip(&primary)
        .enumerate()
        .filter_map(|(k, (hit, ray))| {
            let si = scene.surface(hit.as_ref()?, 0.0);
            let n = facing(si.ng, ray.dir);
            let mut rng = ray_rng(seed, INCOHERENT, k as u64);
            let wi = Frame::from_normal(n).to_world(cosine_hemisphere(rng.vec2()));
            Some(spawn_ray(si.p, si.p_error, n, wi))
        })
        .collect();
    let shadow: Vec<Ray> = hits
        .par_iter()
        .zip(&primary)
        .enumerate()
        .filter_map(|(k, (hit, ray))| {
            let si = scene.surface(hit.as_ref()?, 0.0);
            let mut rng = ray_rng(seed, SHADOW, k as u64);
            let (q, q_error, nq) = lights.sample(scene, rng.f32(), rng.vec2());
            if facing(si.ng, ray.dir).dot(q - si.p) <= 0.0 {
                return None;
            }
            let (r, t_max) = shadow_segment(si.p, si.p_error, si.ng, q, q_error, nq);
            // Fold the shadow epsilon into the direction, so the query is exactly (0, 1).
            Some(Ray::new(r.origin, r.dir * t_max))
        })
        .collect();
    let bounds = Aabb::from_points(scene.triangles.iter().flatten());
    Generated {
        primary: RaySet {
            name: "primary",
            rays: primary,
            query: Query::Closest,
        },
        incoherent: RaySet {
            name: "incoherent",
            rays: incoherent,
            query: Query::Closest,
        },
        shadow: RaySet {
            name: "shadow",
            rays: shadow,
            query: Query::Occluded,
        },
        uniform: uniform(&bounds, n as usize, seed),
    }
}

/// The geometric normal `ng` turned towards the side that `dir` arrives from.
fn facing(ng: Vec3, dir: Vec3) -> Vec3 {
    if ng.dot(dir) < 0.0 {
        ng
    } else {
        -ng
    }
}
