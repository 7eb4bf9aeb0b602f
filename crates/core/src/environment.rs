//! Distant illumination: a constant colour or an equirectangular (lat-long) map.
//!
//! Orientation of maps: +y is up. Row 0 of the image is the zenith (+y), the last row the nadir.
//! The centre column looks along -z (where the default camera looks) and `u` increases towards
//! +x, so `u = 0.5 + atan2(d.x, -d.z) / 2π`, `v = θ / π` with `θ = acos(d.y)` (computed as
//! `atan2(√(x² + z²), y)`, which keeps its precision at the poles).

use crate::stage_time::StageTime;
use crate::{color::luminance, distribution::Distribution2D, Rgb};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Radiance arriving from infinitely far away. Only a map has an importance map: a constant
/// colour is sampled uniformly over the sphere, which is already proportional to it.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(Rgb),
    /// An equirectangular map, importance sampled by luminance.
    Map(EnvMap),
}

/// An equirectangular environment map. Its sampling distribution (the importance map) is built
/// the first time something samples the map or asks for a sampling pdf, so a render whose
/// integrator never samples lights never builds it.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: u32,
    height: u32,
    texels: Vec<Rgb>,
    /// Some texel has positive luminance: the map emits and light sampling should see it.
    emits: bool,
    importance: OnceLock<Importance>,
}

/// The luminance × sinθ distribution of an [`EnvMap`] and how long building it took (for
/// `render --stats`, since it is built inside the render).
#[derive(Clone, Debug)]
pub struct Importance {
    dist: Distribution2D,
    build_time: StageTime,
}

impl Importance {
    fn build(width: u32, height: u32, texels: &[Rgb]) -> Self {
        let start = Instant::now();
        let (w, h) = (width as usize, height as usize);
        // Weight by sinθ: rows near the poles cover less solid angle.
        let weights: Vec<f32> = (0..h)
            .flat_map(|y| {
                let sin_t = (PI * (y as f32 + 0.5) / h as f32).sin();
                (0..w).map(move |x| luminance(texels[y * w + x]).max(0.0) * sin_t)
            })
            .collect();
        let dist = Distribution2D::new(&weights, w, h);
        Self {
            dist,
            build_time: StageTime(start.elapsed()),
        }
    }

    /// Bytes of the distribution.
    pub fn memory_bytes(&self) -> usize {
        self.dist.memory_bytes()
    }

    /// How long building it took.
    pub fn build_time(&self) -> Duration {
        self.build_time.0
    }
}

impl EnvMap {
    /// Builds from row-major linear radiance (already multiplied by any strength). Non-finite and
    /// negative texels must have been rejected by the caller.
    pub fn new(width: u32, height: u32, texels: Vec<Rgb>) -> Self {
        let emits = texels.iter().any(|&t| luminance(t).max(0.0) > 0.0);
        Self {
            width,
            height,
            texels,
            emits,
            importance: OnceLock::new(),
        }
    }

    /// The importance map, built on first use.
    #[inline]
    pub fn importance(&self) -> &Importance {
        self.importance
            .get_or_init(|| Importance::build(self.width, self.height, &self.texels))
    }

    /// The importance map if something has sampled the map, else `None`.
    pub fn importance_if_built(&self) -> Option<&Importance> {
        self.importance.get()
    }

    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Bytes of the texels (length × element size).
    pub fn texel_bytes(&self) -> usize {
        std::mem::size_of_val(self.texels.as_slice())
    }

    fn texel(&self, uv: Vec2) -> Rgb {
        let x = ((uv.x * self.width as f32) as u32).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as u32).min(self.height - 1);
        self.texels[(y * self.width + x) as usize]
    }
}

/// Direction to map coordinates.
#[inline]
pub fn dir_to_uv(d: Vec3) -> Vec2 {
    let d = d.normalize();
    let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
    // θ from atan2 rather than acos(d.y): acos loses precision near the poles (d.y ≈ ±1),
    // where it moved sin θ, and so the pdf, by a few per cent from the sampled direction's.
    let v = d.x.hypot(d.z).atan2(d.y) / PI;
    Vec2::new(u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
}

/// Map coordinates to a unit direction.
#[inline]
pub fn uv_to_dir(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    let s = theta.sin();
    Vec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
}

/// A direction sampled on the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvSample {
    /// Unit direction towards the environment.
    pub dir: Vec3,
    /// Radiance arriving from `dir`.
    pub radiance: Rgb,
    /// Solid-angle pdf.
    pub pdf: f32,
}

impl Environment {
    /// Radiance arriving along direction `-d`, i.e. seen by a ray travelling along `d`.
    #[inline]
    pub fn radiance(&self, d: Vec3) -> Rgb {
        match self {
            Environment::Constant(c) => *c,
            Environment::Map(m) => m.texel(dir_to_uv(d)),
        }
    }

    /// The map, if this is one (only a map has an importance map).
    pub fn map(&self) -> Option<&EnvMap> {
        match self {
            Environment::Constant(_) => None,
            Environment::Map(m) => Some(m),
        }
    }

    /// True if the environment emits nothing (so it need not be sampled).
    pub fn is_black(&self) -> bool {
        match self {
            Environment::Constant(c) => c.max_element() <= 0.0,
            Environment::Map(m) => !m.emits,
        }
    }

    /// Samples an incident direction: uniformly over the sphere for a constant colour, by
    /// luminance for a map.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<EnvSample> {
        match self {
            Environment::Constant(c) => {
                let dir = crate::sampling::uniform_sphere(u);
                Some(EnvSample {
                    dir,
                    radiance: *c,
                    pdf: crate::sampling::UNIFORM_SPHERE_PDF,
                })
            }
            Environment::Map(m) => {
                let (uv, pdf_uv) = m.importance().dist.sample(u);
                let sin_t = (uv.y * PI).sin();
                if pdf_uv <= 0.0 || sin_t <= 0.0 {
                    return None;
                }
                Some(EnvSample {
                    dir: uv_to_dir(uv),
                    radiance: m.texel(uv),
                    pdf: pdf_uv / (2.0 * PI * PI * sin_t),
                })
            }
        }
    }

    /// Solid-angle pdf with which [`Environment::sample`] returns direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            Environment::Constant(_) => crate::sampling::UNIFORM_SPHERE_PDF,
            Environment::Map(m) => {
                let uv = dir_to_uv(d);
                let sin_t = (uv.y * PI).sin();
                if sin_t <= 0.0 {
                    return 0.0;
                }
                m.importance().dist.pdf(uv) / (2.0 * PI * PI * sin_t)
            }
        }
    }
}

impl crate::content_hash::ContentHash for Environment {
    /// The radiance; the importance map follows from it and its build time is a measurement.
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        match self {
            Environment::Constant(c) => {
                out(b"constant");
                c.content_hash(out);
            }
            Environment::Map(EnvMap {
                width,
                height,
                texels,
                emits: _,
                importance: _,
            }) => {
                out(b"map");
                width.content_hash(out);
                height.content_hash(out);
                texels.content_hash(out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_mapping_round_trips_and_is_oriented_as_documented() {
        assert!((uv_to_dir(Vec2::new(0.5, 0.5)) - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        assert!(uv_to_dir(Vec2::new(0.75, 0.5)).x > 0.99);
        assert!(uv_to_dir(Vec2::new(0.3, 0.0)).y > 0.99);
        for d in [Vec3::new(0.3, 0.5, -0.2), Vec3::new(-0.8, -0.1, 0.4)] {
            let d = d.normalize();
            assert!((uv_to_dir(dir_to_uv(d)) - d).length() < 1e-5);
        }
    }

    #[test]
    fn map_sampling_pdf_is_consistent_and_integrates_to_one() {
        let (w, h) = (16u32, 8u32);
        let texels = (0..w * h)
            .map(|i| Rgb::splat(1.0 + (i % 7) as f32))
            .collect();
        let env = Environment::Map(EnvMap::new(w, h, texels));
        let map = env.map().unwrap();
        assert_eq!(map.size(), (16, 8));
        assert_eq!(map.texel_bytes(), 16 * 8 * 12);
        // Eight rows of 16 bins (16 weights + 17 cdf entries each) and an 8-bin marginal.
        let rows = 8 * std::mem::size_of::<crate::distribution::Distribution1D>();
        assert_eq!(map.importance().memory_bytes(), rows + 8 * 33 * 4 + 17 * 4);
        assert!(Environment::Constant(Rgb::ONE).map().is_none());
        for i in 0..64 {
            let u = Vec2::new(
                (i as f32 * 0.618_034 + 0.05) % 1.0,
                (i as f32 * 0.414_214 + 0.1) % 1.0,
            );
            let s = env.sample(u).unwrap();
            let p = env.pdf(s.dir);
            assert!((p - s.pdf).abs() <= 2e-3 * s.pdf, "{p} vs {}", s.pdf);
        }
        // ∫ pdf dω = 1 by a uniform-sphere estimate with a fixed stratified set.
        let n = 256;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += env.pdf(crate::sampling::uniform_sphere(u))
                    / crate::sampling::UNIFORM_SPHERE_PDF;
            }
        }
        let mean = sum / (n * n) as f32;
        assert!((mean - 1.0).abs() < 0.02, "{mean}");
    }
}
