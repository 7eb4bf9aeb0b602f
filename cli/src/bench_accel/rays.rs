//! The ray sets: generated from the camera and the binary BVH's primary hits, or read from a
//! file; written to files by `--dump-rays`.
//!
//! Every random number is a hash of (seed, set, ray index), so the sets do not depend on the
//! thread count. Secondary rays start where the path integrator's would: at the hit point
//! reconstructed from barycentrics, offset along the geometric normal by its error bound
//! (`rt_core::ray::spawn_ray`, `shadow_segment`).

use anyhow::{bail, Result};
use rayon::prelude::*;
use rt_core::{
    color::luminance,
    frame::Frame,
    glam::{Vec2, Vec3},
    ray::{shadow_segment, spawn_ray},
    sampling::{cosine_hemisphere, uniform_triangle},
    triangle, Accel, Camera, Ray, Scene,
};
use std::path::Path;

/// Bytes per ray in ray files: six little-endian f32.
const RAY_BYTES: usize = 24;

/// How a set is traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// `intersect(ray, ∞)`.
    Closest,
    /// `occluded(ray, 1)`: the direction spans the whole segment.
    Occluded,
}

/// A named set of rays.
#[derive(Debug)]
pub struct RaySet {
    /// `primary`, `incoherent`, `shadow` or `file`.
    pub name: &'static str,
    /// The rays.
    pub rays: Vec<Ray>,
    /// How to trace them.
    pub query: Query,
}

impl RaySet {
    /// Upper end of the query interval.
    pub fn t_max(&self) -> f32 {
        match self.query {
            Query::Closest => f32::INFINITY,
            Query::Occluded => 1.0,
        }
    }
}

/// The three generated sets.
pub struct Generated {
    pub primary: RaySet,
    pub incoherent: RaySet,
    pub shadow: RaySet,
}

/// Where shadow rays go.
pub enum Lights {
    /// Emissive triangles, chosen in proportion to their power (area × luminance × faces):
    /// their indices and the running sum of their powers.
    Emitters { prims: Vec<u32>, cdf: Vec<f64> },
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

    /// For the progress line.
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

/// Deterministic random numbers for one ray: SplitMix64 seeded by (seed, set, index).
struct Rng(u64);

impl Rng {
    fn new(seed: u64, set: u64, index: u64) -> Self {
        let mut r = Rng(seed ^ set.wrapping_mul(0xd6e8_feb8_6659_fd93));
        r.0 ^= r
            .next()
            .wrapping_add(index.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        r
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn f32(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }
}

/// Generates the three sets on the current rayon pool. Primary: one ray per pixel of
/// `camera`, jittered uniformly within the pixel. For each primary hit of `reference`:
/// incoherent, a cosine-distributed direction about the geometric normal on the side the
/// primary ray came from; shadow, the segment to a point sampled on `lights`, skipped when the
/// light is behind the surface as seen by the primary ray (an opaque surface would not cast it).
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
            let mut rng = Rng::new(seed, 0, k);
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
            let si = scene.surface(hit.as_ref()?);
            let n = facing(si.ng, ray.dir);
            let mut rng = Rng::new(seed, 1, k as u64);
            let wi = Frame::from_normal(n).to_world(cosine_hemisphere(rng.vec2()));
            Some(spawn_ray(si.p, si.p_error, n, wi))
        })
        .collect();
    let shadow: Vec<Ray> = hits
        .par_iter()
        .zip(&primary)
        .enumerate()
        .filter_map(|(k, (hit, ray))| {
            let si = scene.surface(hit.as_ref()?);
            let mut rng = Rng::new(seed, 2, k as u64);
            let (q, q_error, nq) = lights.sample(scene, rng.f32(), rng.vec2());
            if facing(si.ng, ray.dir).dot(q - si.p) <= 0.0 {
                return None;
            }
            let (r, t_max) = shadow_segment(si.p, si.p_error, si.ng, q, q_error, nq);
            // Fold the shadow epsilon into the direction, so the query is exactly (0, 1).
            Some(Ray::new(r.origin, r.dir * t_max))
        })
        .collect();
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

/// Reads `--ray-file`: six little-endian f32 per ray, every value finite, no zero direction.
pub fn read_file(path: &Path, occlusion: bool) -> Result<RaySet> {
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    if bytes.is_empty() {
        bail!("{}: the ray file is empty", path.display());
    }
    if bytes.len() % RAY_BYTES != 0 {
        bail!(
            "{}: file size {} bytes is not a multiple of {RAY_BYTES} (six little-endian f32 per \
             ray: origin xyz, direction xyz)",
            path.display(),
            bytes.len()
        );
    }
    let mut rays = Vec::with_capacity(bytes.len() / RAY_BYTES);
    for (i, rec) in bytes.chunks_exact(RAY_BYTES).enumerate() {
        let f: Vec<f32> = rec
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
            .collect();
        if f.iter().any(|x| !x.is_finite()) {
            bail!("{}: ray {i} has a non-finite value: {f:?}", path.display());
        }
        let dir = Vec3::new(f[3], f[4], f[5]);
        if dir == Vec3::ZERO {
            bail!("{}: ray {i} has a zero direction", path.display());
        }
        rays.push(Ray::new(Vec3::new(f[0], f[1], f[2]), dir));
    }
    Ok(RaySet {
        name: "file",
        rays,
        query: if occlusion {
            Query::Occluded
        } else {
            Query::Closest
        },
    })
}

/// Writes DIR/primary.bin, DIR/incoherent.bin and DIR/shadow.bin (creating DIR).
pub fn dump(dir: &Path, sets: &Generated) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    for set in [&sets.primary, &sets.incoherent, &sets.shadow] {
        let path = dir.join(format!("{}.bin", set.name));
        let mut bytes = Vec::with_capacity(set.rays.len() * RAY_BYTES);
        for r in &set.rays {
            for x in r.origin.to_array().into_iter().chain(r.dir.to_array()) {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        std::fs::write(&path, bytes)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_files_round_trip_and_reject_bad_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let rays = vec![
            Ray::new(Vec3::new(0.5, -1.0, 2.0), Vec3::new(0.0, 0.0, -1.0)),
            Ray::new(Vec3::new(1e-7, 3e5, -0.0), Vec3::new(0.3, -0.2, 0.1)),
        ];
        let set = |rays: Vec<Ray>, name| RaySet {
            name,
            rays,
            query: Query::Closest,
        };
        let generated = Generated {
            primary: set(rays.clone(), "primary"),
            incoherent: set(Vec::new(), "incoherent"),
            shadow: set(rays[..1].to_vec(), "shadow"),
        };
        dump(dir.path(), &generated).unwrap();
        let back = read_file(&dir.path().join("primary.bin"), false).unwrap();
        assert_eq!(back.rays, rays);
        assert_eq!(back.query, Query::Closest);
        let shadow = read_file(&dir.path().join("shadow.bin"), true).unwrap();
        assert_eq!((shadow.rays.len(), shadow.query), (1, Query::Occluded));
        let err = read_file(&dir.path().join("incoherent.bin"), false).unwrap_err();
        assert!(err.to_string().contains("empty"), "{err}");
        let odd = dir.path().join("odd.bin");
        std::fs::write(&odd, [0u8; 25]).unwrap();
        let err = read_file(&odd, false).unwrap_err().to_string();
        assert!(
            err.contains("odd.bin") && err.contains("multiple of 24"),
            "{err}"
        );
        let mut nan = vec![0u8; 24];
        nan[20..24].copy_from_slice(&f32::NAN.to_le_bytes());
        std::fs::write(&odd, &nan).unwrap();
        assert!(read_file(&odd, false)
            .unwrap_err()
            .to_string()
            .contains("ray 0"));
    }

    #[test]
    fn random_numbers_are_a_function_of_seed_set_and_index() {
        let a: Vec<f32> = (0..4).map(|_| Rng::new(1, 2, 3).f32()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        let mut r = Rng::new(1, 2, 3);
        let first = r.f32();
        assert_ne!(first, r.f32());
        assert_ne!(Rng::new(1, 2, 4).f32(), first);
        assert_ne!(Rng::new(1, 3, 3).f32(), first);
        assert_ne!(Rng::new(2, 2, 3).f32(), first);
    }
}
