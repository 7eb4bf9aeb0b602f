//! Distant illumination: a constant colour or an equirectangular (lat-long) map, optionally
//! with a sun disc on top of the map (how the analytic daylight sky of [`sky`] reaches the
//! renderer: tabulated into a map, with its sun as a [`SunDisc`]).
//!
//! Orientation of maps: +y is up. Row 0 of the image is the zenith (+y), the last row the nadir.
//! The centre column looks along -z (where the default camera looks) and `u` increases towards
//! +x, so `u = 0.5 + atan2(d.x, -d.z) / 2π`, `v = θ / π` with `θ = acos(d.y)` (computed as
//! `atan2(√(x² + z²), y)`, which keeps its precision at the poles).
//!
//! A sun disc is smaller than a texel of any map we would store (at 512 × 256 the sun covers
//! 0.45 of a texel at 5° elevation, 0.64 at 45°, 0.9 at 60°), so it is not rasterised into the
//! texels, which would make it a square of the wrong size: it is a uniformly bright cone added
//! to the map's radiance, and sampling picks the cone (uniformly within it) or the texels (by
//! luminance) in proportion to their powers, so the mixture's pdf is proportional to luminance
//! everywhere, as a map's alone is. `radiance`, `sample` and `pdf` all see the same sum, and
//! `sample` evaluates radiance and pdf at its direction exactly as `radiance` and `pdf` do.
//! `cargo run --release -p rt-core --example sky_sampling` measures the choice: the per-sample
//! noise of next-event estimation of a horizontal surface's irradiance equals that of the sun
//! rasterised into its texel (0.35 relative standard deviation at 45° elevation), and beats
//! fixed splits of 0.1, 0.5 and 0.9 (1.9, 0.43, 1.0) except at a low sun, where 0.1 is 13 %
//! better (0.66 against 0.76 at 10°).

pub mod sky;
pub mod sun;

use crate::distribution::ONE_MINUS_EPS;
use crate::frame::Frame;
use crate::stage_time::StageTime;
use crate::{color::luminance, distribution::Distribution2D, Rgb};
use glam::{Mat3, Vec2, Vec3};
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

/// An equirectangular environment map, optionally with a [`SunDisc`] added on top. Its
/// sampling distribution (the importance map) is built the first time something samples the
/// map or asks for a sampling pdf, so a render whose integrator never samples lights never
/// builds it.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: u32,
    height: u32,
    texels: Vec<Rgb>,
    /// Some texel has positive luminance: the map emits and light sampling should see it.
    emits: bool,
    /// A small bright disc added to the texels' radiance and sampled on its own.
    sun: Option<SunDisc>,
    /// World directions to the map's own frame (a rotation; `None`: the identity). Boxed so
    /// that `Environment` stays small.
    rotation: Option<Box<Mat3>>,
    importance: OnceLock<Importance>,
}

/// A disc of uniform radiance on the sphere of directions (a cone around `dir`), such as the
/// sun. Membership is tested with the cross product, `|d × dir|² ≤ sin²r · |d|²` (and
/// `d · dir > 0`), rather than with a cosine: for a disc of 0.27° the cosine at the rim is
/// `1 − 1.1e-5`, which f32 resolves only to about half a per cent of the disc's area, while
/// `sin γ` keeps full relative precision. The test needs no normalised `d`, so `radiance`,
/// `sample` and `pdf` decide membership from the same bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDisc {
    dir: Vec3,
    /// Angular radius in radians.
    radius: f32,
    /// `sin² radius`.
    sin2_radius: f32,
    /// Solid angle, `2π(1 − cos r) = 4π sin²(r/2)`.
    solid_angle: f32,
    radiance: Rgb,
}

impl SunDisc {
    /// A disc around `dir` (normalised here) of angular radius `radius` radians, in (0, π/2],
    /// with uniform `radiance`. Non-finite or negative radiance, a zero direction or a radius
    /// out of range must have been rejected by the caller.
    pub fn new(dir: Vec3, radius: f32, radiance: Rgb) -> Self {
        debug_assert!(
            radius > 0.0 && radius <= std::f32::consts::FRAC_PI_2,
            "{radius}"
        );
        debug_assert!(radiance.is_finite() && radiance.min_element() >= 0.0);
        let r = radius as f64;
        let half = (r / 2.0).sin();
        Self {
            dir: dir.normalize(),
            radius,
            sin2_radius: (r.sin() * r.sin()) as f32,
            solid_angle: (4.0 * std::f64::consts::PI * half * half) as f32,
            radiance,
        }
    }

    /// Unit direction of the disc's centre.
    pub fn dir(&self) -> Vec3 {
        self.dir
    }

    /// Radiance of every direction inside the disc.
    pub fn radiance(&self) -> Rgb {
        self.radiance
    }

    /// Solid angle in steradians.
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    /// Angular radius in radians.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// True if direction `d` (of any non-zero length) lies inside the disc.
    #[inline]
    pub fn contains(&self, d: Vec3) -> bool {
        d.dot(self.dir) > 0.0
            && d.cross(self.dir).length_squared() <= self.sin2_radius * d.length_squared()
    }

    /// A direction uniformly distributed over the disc (pdf `1 / solid_angle`). Rounding can put
    /// a direction from the outermost part of the rim just outside; callers evaluate radiance
    /// and pdf at the returned direction, so they stay consistent with it.
    #[inline]
    fn sample(&self, u: Vec2) -> Vec3 {
        // 1 − cos θ is uniform on [0, 1 − cos r]; sin θ from it without forming cos θ, which
        // would cancel.
        let one_minus_cos = u.x * self.solid_angle / (2.0 * PI);
        let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), 1.0 - one_minus_cos);
        Frame::from_normal(self.dir).to_world(local).normalize()
    }

    /// Luminance × solid angle: the disc's share of a map's power.
    fn power(&self) -> f32 {
        luminance(self.radiance).max(0.0) * self.solid_angle
    }
}

/// The luminance × sinθ distribution of an [`EnvMap`], the probability of sampling its sun, and
/// how long building them took (for `render --stats`, since it is built inside the render).
#[derive(Clone, Debug)]
pub struct Importance {
    dist: Distribution2D,
    /// Probability that [`Environment::sample`] samples the sun rather than the texels: the
    /// sun's share of the total power (0 without a sun).
    sun_prob: f32,
    build_time: StageTime,
}

impl Importance {
    fn build(width: u32, height: u32, texels: &[Rgb], sun: Option<&SunDisc>) -> Self {
        let start = Instant::now();
        let (w, h) = (width as usize, height as usize);
        // Each texel's weight is the largest luminance of it and its eight neighbours: the
        // bilinear radiance over a texel's area mixes in its neighbours, so a dark texel next
        // to a bright one still emits near their border and must be sampled there (its pdf
        // must not be 0 where the radiance is not). Weight by sinθ: rows near the poles cover
        // less solid angle.
        let lum: Vec<f32> = texels.iter().map(|&t| luminance(t).max(0.0)).collect();
        let at = |x: isize, y: isize| {
            let y = y.clamp(0, h as isize - 1) as usize;
            lum[y * w + x.rem_euclid(w as isize) as usize]
        };
        let weights: Vec<f32> = (0..h)
            .flat_map(|y| {
                let sin_t = (PI * (y as f32 + 0.5) / h as f32).sin();
                let at = &at;
                (0..w).map(move |x| {
                    let (x, y) = (x as isize, y as isize);
                    let mut m = 0.0f32;
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            m = m.max(at(x + dx, y + dy));
                        }
                    }
                    m * sin_t
                })
            })
            .collect();
        let dist = Distribution2D::new(&weights, w, h);
        // The mean of luminance × sinθ over [0,1)² (the texels', not the widened weights');
        // dω = 2π² sinθ du dv turns it into the texels' power. Splitting samples by power
        // makes the mixture's pdf follow luminance as a map's alone does.
        let mean: f64 = (0..h)
            .map(|y| {
                let sin_t = (PI * (y as f32 + 0.5) / h as f32).sin() as f64;
                lum[y * w..(y + 1) * w]
                    .iter()
                    .map(|&l| l as f64)
                    .sum::<f64>()
                    * sin_t
            })
            .sum::<f64>()
            / (w * h) as f64;
        let map_power = (mean * 2.0 * std::f64::consts::PI.powi(2)) as f32;
        let sun_prob = match sun {
            Some(s) if s.power() > 0.0 => s.power() / (s.power() + map_power),
            _ => 0.0,
        };
        Self {
            dist,
            sun_prob,
            build_time: StageTime(start.elapsed()),
        }
    }

    /// Probability that a sample goes to the sun disc rather than the texels.
    pub fn sun_probability(&self) -> f32 {
        self.sun_prob
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
            sun: None,
            rotation: None,
            importance: OnceLock::new(),
        }
    }

    /// The same map turned by `to_map`, the rotation taking world directions into the
    /// map's frame (where [`dir_to_uv`] applies). The sun disc, if any, stays in the world.
    pub fn rotated(mut self, to_map: Mat3) -> Self {
        self.rotation = (to_map != Mat3::IDENTITY).then(|| Box::new(to_map));
        self
    }

    /// World direction `d` in the map's frame.
    #[inline]
    fn to_map(&self, d: Vec3) -> Vec3 {
        match &self.rotation {
            Some(r) => **r * d,
            None => d,
        }
    }

    /// A direction of the map's frame in the world.
    #[inline]
    fn in_world(&self, d: Vec3) -> Vec3 {
        match &self.rotation {
            Some(r) => r.transpose() * d,
            None => d,
        }
    }

    /// Map coordinates of world direction `d`.
    #[inline]
    fn uv(&self, d: Vec3) -> Vec2 {
        dir_to_uv(self.to_map(d))
    }

    /// The same map with `sun` added on top of the texels.
    pub fn with_sun(mut self, sun: SunDisc) -> Self {
        self.sun = Some(sun);
        self.importance = OnceLock::new();
        self
    }

    /// The sun disc, if the map has one.
    pub fn sun(&self) -> Option<&SunDisc> {
        self.sun.as_ref()
    }

    /// The importance map, built on first use.
    #[inline]
    pub fn importance(&self) -> &Importance {
        self.importance.get_or_init(|| {
            Importance::build(self.width, self.height, &self.texels, self.sun.as_ref())
        })
    }

    /// The importance map if something has sampled the map, else `None`.
    pub fn importance_if_built(&self) -> Option<&Importance> {
        self.importance.get()
    }

    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The texels, row-major from the zenith row, without the sun.
    pub fn texels(&self) -> &[Rgb] {
        &self.texels
    }

    /// Bytes of the texels (length × element size).
    pub fn texel_bytes(&self) -> usize {
        std::mem::size_of_val(self.texels.as_slice())
    }

    /// The map's radiance at `uv`, interpolated bilinearly between texel centres (as
    /// Mitsuba's `envmap` does): wrapping around in `u`, held at the first and last rows'
    /// centres in `v`.
    #[inline]
    fn texel(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * self.width as f32 - 0.5;
        let y = (uv.y * self.height as f32 - 0.5).clamp(0.0, (h - 1) as f32);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i0, j0) = (x0 as i64, y0 as i64);
        let at = |i: i64, j: i64| self.texels[(j.min(h - 1) * w + i.rem_euclid(w)) as usize];
        let top = at(i0, j0) * (1.0 - fx) + at(i0 + 1, j0) * fx;
        let bottom = at(i0, j0 + 1) * (1.0 - fx) + at(i0 + 1, j0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The sun's radiance along direction `d` (zero outside the disc or without a sun).
    #[inline]
    fn sun_radiance(&self, d: Vec3) -> Rgb {
        match &self.sun {
            Some(s) if s.contains(d) => s.radiance,
            _ => Rgb::ZERO,
        }
    }

    /// Solid-angle pdf of the mixture at direction `d`, given the texels' pdf there.
    #[inline]
    fn mixture_pdf(&self, imp: &Importance, d: Vec3, map_pdf: f32) -> f32 {
        match &self.sun {
            None => map_pdf,
            Some(s) => {
                let p = imp.sun_prob;
                let sun = if s.contains(d) {
                    p / s.solid_angle
                } else {
                    0.0
                };
                (1.0 - p) * map_pdf + sun
            }
        }
    }

    /// Solid-angle pdf with which the texels' distribution alone gives direction `d` (in the
    /// map's frame).
    #[inline]
    fn map_pdf(imp: &Importance, d: Vec3) -> f32 {
        let uv = dir_to_uv(d);
        let sin_t = (uv.y * PI).sin();
        if sin_t <= 0.0 {
            return 0.0;
        }
        imp.dist.pdf(uv) / (2.0 * PI * PI * sin_t)
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
            Environment::Map(m) => m.texel(m.uv(d)) + m.sun_radiance(d),
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
            Environment::Map(m) => !m.emits && m.sun.as_ref().is_none_or(|s| s.power() <= 0.0),
        }
    }

    /// Samples an incident direction: uniformly over the sphere for a constant colour, by
    /// luminance for a map (its sun, if any, uniformly within the disc, chosen in proportion
    /// to its power).
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
                let imp = m.importance();
                let Some(sun) = &m.sun else {
                    let (uv, pdf_uv) = imp.dist.sample(u);
                    let sin_t = (uv.y * PI).sin();
                    if pdf_uv <= 0.0 || sin_t <= 0.0 {
                        return None;
                    }
                    let dir = m.in_world(uv_to_dir(uv));
                    return Some(EnvSample {
                        dir,
                        // At the direction, as `radiance` computes it: the interpolated
                        // radiance is continuous, so `uv` and the direction's own uv (which
                        // differ by rounding) would give different bits.
                        radiance: m.texel(m.uv(dir)),
                        pdf: pdf_uv / (2.0 * PI * PI * sin_t),
                    });
                };
                let p = imp.sun_prob;
                let dir = if u.x < p {
                    sun.sample(Vec2::new(u.x / p, u.y))
                } else {
                    let u = Vec2::new(((u.x - p) / (1.0 - p)).min(ONE_MINUS_EPS), u.y);
                    let (uv, pdf_uv) = imp.dist.sample(u);
                    if pdf_uv <= 0.0 {
                        return None;
                    }
                    m.in_world(uv_to_dir(uv))
                };
                // Radiance and pdf at the direction itself, computed as `radiance` and `pdf`
                // compute them: a direction from one texel can round into its neighbour, whose
                // pdf differs by the sky's gradient (up to 12 % at 128 × 64 near the sun).
                let pdf = m.mixture_pdf(imp, dir, EnvMap::map_pdf(imp, m.to_map(dir)));
                if pdf <= 0.0 {
                    return None;
                }
                Some(EnvSample {
                    dir,
                    radiance: m.texel(m.uv(dir)) + m.sun_radiance(dir),
                    pdf,
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
                let imp = m.importance();
                m.mixture_pdf(imp, d, EnvMap::map_pdf(imp, m.to_map(d)))
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
                sun,
                rotation,
                importance: _,
            }) => {
                out(b"map");
                width.content_hash(out);
                height.content_hash(out);
                texels.content_hash(out);
                sun.content_hash(out);
                // Only a rotated map adds to the hash (older hashes still match).
                if let Some(r) = rotation {
                    r.to_cols_array().content_hash(out);
                }
            }
        }
    }
}

impl crate::content_hash::ContentHash for SunDisc {
    /// The disc as the renderer reads it; `sin2_radius` and the solid angle follow from the radius.
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let SunDisc {
            dir,
            radius,
            sin2_radius: _,
            solid_angle: _,
            radiance,
        } = self;
        dir.content_hash(out);
        radius.content_hash(out);
        radiance.content_hash(out);
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

    /// One bright texel among black ones.
    fn one_bright_texel() -> Environment {
        let (w, h) = (8u32, 4u32);
        let mut texels = vec![Rgb::ZERO; (w * h) as usize];
        texels[(w + 3) as usize] = Rgb::splat(4.0);
        Environment::Map(EnvMap::new(w, h, texels))
    }

    #[test]
    fn radiance_is_interpolated_between_texel_centres() {
        let env = one_bright_texel();
        let centre = Vec2::new(3.5 / 8.0, 1.5 / 4.0);
        let at = |uv: Vec2| env.radiance(uv_to_dir(uv)).x;
        assert!((at(centre) - 4.0).abs() < 1e-4, "{}", at(centre));
        // Halfway to the next centre in u, a quarter of the way in v: bilinear weights.
        let half = at(centre + Vec2::new(0.5 / 8.0, 0.0));
        let quarter = at(centre + Vec2::new(0.0, 0.25 / 4.0));
        assert!(
            (half - 2.0).abs() < 1e-3 && (quarter - 3.0).abs() < 1e-3,
            "{half} {quarter}"
        );
        // Wraps around in u: a bright texel in column 0 lights the seam from column 7's side.
        let mut texels = vec![Rgb::ZERO; 32];
        texels[8] = Rgb::ONE;
        let seam = Environment::Map(EnvMap::new(8, 4, texels));
        let l = seam.radiance(uv_to_dir(Vec2::new(0.999, 1.5 / 4.0))).x;
        assert!((l - 0.492).abs() < 1e-3, "{l}");
    }

    /// Light sampling alone estimates the map's integral ∫ L dω, which needs a pdf that is
    /// positive wherever the interpolated radiance is: around a bright texel that is also the
    /// edges of its black neighbours.
    #[test]
    fn sampling_alone_integrates_the_interpolated_map() {
        let env = one_bright_texel();
        // The integral by a fine midpoint rule over (u, v): dω = 2π² sinθ du dv.
        let n = 1024;
        let mut exact = 0.0f64;
        for j in 0..n / 2 {
            for i in 0..n {
                let uv = Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    (j as f32 + 0.5) / (n / 2) as f32,
                );
                let sin_t = (PI * uv.y).sin() as f64;
                exact += env.radiance(uv_to_dir(uv)).x as f64 * sin_t;
            }
        }
        exact *= 2.0 * std::f64::consts::PI.powi(2) / (n * n / 2) as f64;
        let estimate = |env: &Environment| {
            let mut rng = crate::rng::SplitMix64::new(7);
            let m = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..m {
                let x = env
                    .sample(rng.vec2())
                    .map_or(0.0, |s| (s.radiance.x / s.pdf) as f64);
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / m as f64;
            (mean, ((sum2 / m as f64 - mean * mean) / m as f64).sqrt())
        };
        let (mean, se) = estimate(&env);
        assert!(
            (mean - exact).abs() < 4.0 * se + 1e-3 * exact,
            "{mean} ± {se} vs {exact}"
        );
        // Control: sampling only the bright texel itself (its neighbours' pdf 0) misses the
        // radiance that spills onto them.
        let Environment::Map(m) = &env else {
            unreachable!()
        };
        let narrow = {
            let (w, h) = (m.width as usize, m.height as usize);
            let weights: Vec<f32> = (0..w * h)
                .map(|i| luminance(m.texels[i]) * (PI * ((i / w) as f32 + 0.5) / h as f32).sin())
                .collect();
            let mut narrow = m.clone();
            let imp = Importance {
                dist: Distribution2D::new(&weights, w, h),
                sun_prob: 0.0,
                build_time: StageTime::default(),
            };
            narrow.importance = OnceLock::from(imp);
            Environment::Map(narrow)
        };
        let (biased, se) = estimate(&narrow);
        assert!(exact - biased > 10.0 * se, "{biased} ± {se} vs {exact}");
    }

    #[test]
    fn a_rotated_map_is_the_map_seen_through_the_rotation() {
        let (w, h) = (16u32, 8u32);
        let texels: Vec<Rgb> = (0..w * h)
            .map(|i| Rgb::splat(1.0 + (i % 7) as f32))
            .collect();
        let r = Mat3::from_rotation_y(1.1) * Mat3::from_rotation_x(0.4);
        let plain = Environment::Map(EnvMap::new(w, h, texels.clone()));
        let turned = Environment::Map(EnvMap::new(w, h, texels).rotated(r));
        for i in 0..64 {
            let u = Vec2::new(
                (i as f32 * 0.618_034 + 0.05) % 1.0,
                (i as f32 * 0.414_214 + 0.1) % 1.0,
            );
            let d = crate::sampling::uniform_sphere(u);
            // Looked up in the map's frame; the pdf is the plain map's at the turned direction.
            assert_eq!(turned.radiance(d), plain.radiance(r * d));
            assert!((turned.pdf(d) - plain.pdf(r * d)).abs() <= 1e-4 * plain.pdf(r * d));
            // Samples come back in the world, with their own pdf and radiance.
            let s = turned.sample(u).unwrap();
            assert!((turned.pdf(s.dir) - s.pdf).abs() <= 2e-3 * s.pdf);
            assert_eq!(s.radiance, turned.radiance(s.dir));
        }
        // Control: the unrotated map disagrees somewhere.
        let differs = (0..64).any(|i| {
            let d = crate::sampling::uniform_sphere(Vec2::new(i as f32 / 64.0, 0.37));
            turned.radiance(d) != plain.radiance(d)
        });
        assert!(differs);
    }

    #[test]
    fn sun_disc_membership_is_exact_at_the_rim_for_any_length() {
        let r = 0.2667f32.to_radians();
        let dir = Vec3::new(0.3, 0.8, -0.5).normalize();
        let sun = SunDisc::new(dir * 7.0, r, Rgb::ONE);
        assert!((sun.dir().length() - 1.0).abs() < 1e-6);
        let omega = 2.0 * std::f64::consts::PI * (1.0 - (r as f64).cos());
        assert!((sun.solid_angle() as f64 / omega - 1.0).abs() < 1e-6);
        let frame = Frame::from_normal(sun.dir());
        let at = |angle: f32, phi: f32| {
            frame.to_world(Vec3::new(
                angle.sin() * phi.cos(),
                angle.sin() * phi.sin(),
                angle.cos(),
            ))
        };
        for phi in [0.0f32, 1.0, 2.5, 4.0] {
            for len in [1.0f32, 3.0, 0.2] {
                assert!(sun.contains(at(0.999 * r, phi) * len), "{phi} {len}");
                assert!(!sun.contains(at(1.001 * r, phi) * len), "{phi} {len}");
            }
        }
        assert!(!sun.contains(-sun.dir()));
        // Samples land inside (rounding allowing) with radiance and pdf from the same test.
        let env = Environment::Map(EnvMap::new(4, 2, vec![Rgb::splat(1e-3); 8]).with_sun(sun));
        let p = env.map().unwrap().importance().sun_probability();
        let mut inside = 0;
        for i in 0..1000 {
            let u = Vec2::new(p * (i as f32 + 0.5) / 1000.0, (i as f32 * 0.618_034) % 1.0);
            let s = env.sample(u).unwrap();
            inside += usize::from(sun.contains(s.dir));
            assert_eq!(s.pdf, env.pdf(s.dir));
        }
        assert!(inside >= 999, "{inside}");
    }

    #[test]
    fn sun_share_of_samples_is_its_share_of_power() {
        let (w, h) = (16u32, 8u32);
        let texels: Vec<Rgb> = (0..w * h)
            .map(|i| Rgb::new(0.2, 0.5, 1.0) * (1 + i % 5) as f32)
            .collect();
        // Power of the texels: Σ luminance × solid angle of the texel.
        let map_power: f64 = (0..h)
            .map(|y| {
                let (t0, t1) = (PI * y as f32 / h as f32, PI * (y + 1) as f32 / h as f32);
                let omega = 2.0 * PI / w as f32 * (t0.cos() - t1.cos());
                (0..w)
                    .map(|x| (luminance(texels[(y * w + x) as usize]) * omega) as f64)
                    .sum::<f64>()
            })
            .sum();
        let sun = SunDisc::new(Vec3::new(0.0, 1.0, 1.0), 0.01, Rgb::splat(3e4));
        let sun_power = 3e4 * sun.solid_angle() as f64;
        let map = EnvMap::new(w, h, texels).with_sun(sun);
        let p = map.importance().sun_probability() as f64;
        let expected = sun_power / (sun_power + map_power);
        // sinθ at the row centre against the exact band area: a few 1e-3 at 8 rows.
        assert!((p / expected - 1.0).abs() < 5e-3, "{p} vs {expected}");
        let env = Environment::Map(map);
        assert!(!env.is_black());
        // A black map with a black sun is black; a black map with a sun is not.
        let black = EnvMap::new(2, 2, vec![Rgb::ZERO; 4]);
        assert!(Environment::Map(black.clone()).is_black());
        assert!(!Environment::Map(black.clone().with_sun(sun)).is_black());
        let dark_sun = SunDisc::new(Vec3::Y, 0.01, Rgb::ZERO);
        assert!(Environment::Map(black.with_sun(dark_sun)).is_black());
    }
}
