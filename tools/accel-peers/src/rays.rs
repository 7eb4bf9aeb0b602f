//! Ray files (six little-endian f32 per ray: origin xyz, direction xyz) and the fallback
//! generator used until `render bench-accel --dump-rays` exists.
//!
//! `primary.bin` and `incoherent.bin` are closest-hit queries over (0, ∞); `shadow.bin` holds
//! occlusion queries over (0, 1) (direction = target − origin).

use anyhow::{Context, Result};
use rayon::prelude::*;
use rt_core::glam::Vec3;
use rt_core::{ray::offset_ray_origin, triangle::point_with_error};
use rt_core::Ray;
use std::path::Path;

/// The ray sets, in report order: name and whether it is an occlusion (shadow) set.
pub const SETS: [(&str, bool); 3] = [("primary", false), ("incoherent", false), ("shadow", true)];

/// The query range's end for a set.
pub fn t_max(shadow: bool) -> f32 {
    if shadow {
        1.0
    } else {
        f32::INFINITY
    }
}

/// Reads a ray file.
pub fn read(path: &Path) -> Result<Vec<Ray>> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    anyhow::ensure!(
        bytes.len() % 24 == 0,
        "{}: size {} is not a multiple of 24 bytes (six f32 per ray)",
        path.display(),
        bytes.len()
    );
    let f = |c: &[u8]| f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    Ok(bytes
        .chunks_exact(24)
        .map(|r| {
            let v: Vec<f32> = r.chunks_exact(4).map(f).collect();
            Ray::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
        })
        .collect())
}

/// Writes a ray file.
pub fn write(path: &Path, rays: &[Ray]) -> Result<()> {
    let mut out = Vec::with_capacity(rays.len() * 24);
    for r in rays {
        for x in r.origin.to_array().into_iter().chain(r.dir.to_array()) {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    std::fs::write(path, out).with_context(|| format!("cannot write {}", path.display()))
}

/// Where the generator's camera and light go.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// Looking at the whole mesh from outside its bounds (scanned objects: bunny, dragon).
    Outside,
    /// Standing inside, between the middle of the bounds and what is behind it along the long
    /// horizontal axis, looking down that axis (rooms: conference, Sibenik, kitchen); the light
    /// under the ceiling.
    Inside,
}

/// The generator's settings.
#[derive(Clone, Copy, Debug)]
pub struct GenOptions {
    /// Image width in pixels (one primary ray through each pixel's centre).
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera placement.
    pub view: View,
    /// Camera position and target overriding the view's (same light).
    pub eye: Option<(Vec3, Vec3)>,
    /// Incoherent and shadow rays per primary hit.
    pub per_hit: u32,
    /// Random seed of the bounce directions and light points.
    pub seed: u64,
}

/// SplitMix64: one independent stream per ray index.
struct Rng(u64);

impl Rng {
    fn new(seed: u64, index: u64) -> Self {
        Rng(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15))
    }
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Forward, right and up of a camera looking along `dir` with +y up.
fn camera_frame(dir: Vec3) -> (Vec3, Vec3, Vec3) {
    let forward = dir.normalize();
    let right = forward.cross(Vec3::Y).normalize();
    (forward, right, right.cross(forward))
}

/// Distance from the box centre, along `back`, at which the whole box is in the frame.
fn fit_distance(lo: Vec3, hi: Vec3, back: Vec3, vfov: f32, aspect: f32) -> f32 {
    let (forward, right, up) = camera_frame(-back);
    let (centre, tan) = ((lo + hi) * 0.5, (vfov * 0.5).tan());
    (0..8)
        .map(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            // The corner must satisfy |x| <= tan·aspect·depth and |y| <= tan·depth, where
            // depth = distance + (corner along forward).
            let z = c.dot(forward);
            (c.dot(right).abs() / (tan * aspect)).max(c.dot(up).abs() / tan) - z
        })
        .fold(0.0, f32::max)
}

/// Primary camera rays through every pixel; `per_hit` cosine-distributed bounces from every
/// primary hit (about the geometric normal on the side the camera sees); as many shadow rays
/// from every primary hit whose visible side faces the light, to random points of a small
/// square light.
/// Hits are found with our binary BVH. Returns the primary, incoherent and shadow sets.
pub fn generate(tris: &[[Vec3; 3]], opts: &GenOptions) -> Result<[Vec<Ray>; 3]> {
    let reference = "bvh"
        .parse::<rt_accel::AccelSpec>()
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .build(tris);
    let (lo, hi) = crate::mesh::bounds(tris);
    let (centre, ext) = ((lo + hi) * 0.5, hi - lo);
    let (w, h) = (opts.width, opts.height);
    let aspect = w as f32 / h as f32;
    let radius = ext.length() * 0.5;
    let (eye, target, vfov, light, light_size) = match opts.view {
        View::Outside => {
            let vfov = 40f32.to_radians();
            let back = Vec3::new(0.3, 0.25, 1.0).normalize();
            let eye = centre + back * fit_distance(lo, hi, back, vfov, aspect);
            let light = centre + Vec3::new(0.5, 2.0, 1.0) * radius;
            (eye, centre, vfov, light, radius * 0.1)
        }
        View::Inside => {
            // From the middle of the bounds at 60 % height, back off along the long horizontal
            // axis towards whatever is behind (70 % of the free distance), looking forward and
            // a little down; the light is under the ceiling in the middle.
            let ax = if ext.x >= ext.z { Vec3::X } else { Vec3::Z };
            let mid = Vec3::new(centre.x, lo.y + 0.6 * ext.y, centre.z);
            let behind = reference
                .intersect(&Ray::new(mid, -ax), f32::INFINITY)
                .map_or(0.5 * ext.dot(ax), |h| h.t);
            let eye = mid - ax * (0.7 * behind);
            let target = Vec3::new(centre.x, lo.y + 0.3 * ext.y, centre.z) + ax * (0.5 * behind);
            let light = Vec3::new(centre.x, lo.y + 0.9 * ext.y, centre.z);
            (eye, target, 60f32.to_radians(), light, ext.length() * 0.05)
        }
    };
    let (eye, target) = opts.eye.unwrap_or((eye, target));
    let (forward, right, up) = camera_frame(target - eye);
    let tan = (vfov * 0.5).tan();
    let primary: Vec<Ray> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let sx = (2.0 * x / w as f32 - 1.0) * tan * aspect;
            let sy = (1.0 - 2.0 * y / h as f32) * tan;
            Ray::new(eye, (forward + right * sx + up * sy).normalize())
        })
        .collect();
    // For each primary hit, `per_hit` times: (incoherent ray, shadow ray if the light is in
    // front of the visible side).
    let secondary: Vec<(Ray, Option<Ray>)> = primary
        .par_iter()
        .enumerate()
        .flat_map_iter(|(i, ray)| {
            let mut out = Vec::new();
            let Some(hit) = reference.intersect(ray, f32::INFINITY) else {
                return out;
            };
            let tri = &tris[hit.prim as usize];
            let (p, p_error) = point_with_error(tri, hit.b1, hit.b2);
            let [v0, v1, v2] = *tri;
            let mut n = (v1 - v0).cross(v2 - v0).normalize();
            if !n.is_finite() {
                return out;
            }
            if n.dot(ray.dir) > 0.0 {
                n = -n;
            }
            let mut rng = Rng::new(opts.seed, i as u64);
            // Every ray of this hit leaves to the side of n, so one offset origin serves all.
            let o = offset_ray_origin(p, p_error, n, n);
            let (t, b) = n.any_orthonormal_pair();
            for _ in 0..opts.per_hit {
                // Cosine-distributed about n (Malley: a uniform disc point lifted up).
                let (r, phi) = (
                    rng.next_f32().sqrt(),
                    std::f32::consts::TAU * rng.next_f32(),
                );
                let d =
                    t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - r * r).max(0.0).sqrt();
                let q =
                    light + Vec3::new(rng.next_f32() - 0.5, 0.0, rng.next_f32() - 0.5) * light_size;
                let shadow = (n.dot(q - p) > 0.0).then(|| Ray::new(o, q - o));
                out.push((Ray::new(o, d), shadow));
            }
            out
        })
        .collect();
    let incoherent = secondary.iter().map(|s| s.0).collect();
    let shadow = secondary.iter().filter_map(|s| s.1).collect();
    Ok([primary, incoherent, shadow])
}
