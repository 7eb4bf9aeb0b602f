//! What SVGF knows about each pixel of a frame besides its light: its class by the roughness of
//! its primary hit (Voorhuis Table in seed 001 §2.1), the albedo its light is demodulated by,
//! and the depth and normal its edge-stopping compares.

use super::params::SvgfParams;
use rayon::prelude::*;
use rt_core::glam::Vec3;
use rt_core::Rgb;
use rt_film::GuideBuffers;

/// Smallest albedo divided by when demodulating (Falcor clamps at 0.001 too): a black surface's
/// light stays finite and its filtered value is multiplied back by (almost) nothing.
pub const MIN_ALBEDO: f32 = 1e-3;

/// How a pixel is treated, by its primary hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// No surface: the environment, passed through.
    Sky,
    /// Roughness at or above the specular limit.
    Diffuse,
    /// Glossy between the glossy and the specular limit: primary motion, clipped history.
    Glossy,
    /// Glossy below the glossy limit: searched by representative rays.
    SharpGlossy,
    /// A pure mirror (every layer a delta lobe): searched by the reflected hit.
    Mirror,
}

impl Class {
    /// Anything but diffuse and sky.
    #[inline]
    pub fn specular(self) -> bool {
        matches!(self, Class::Glossy | Class::SharpGlossy | Class::Mirror)
    }
}

/// Per-pixel features of one frame, flat in row-major order.
#[derive(Clone, Debug)]
pub struct Features {
    pub w: usize,
    pub h: usize,
    pub class: Vec<Class>,
    /// Albedo the light is divided by (mirrors: primary × reflected).
    pub albedo: Vec<Rgb>,
    /// Light a mirror's chain ends in (`ReflectedGuides::emission`): taken out of the direct
    /// light before demodulation and added back after filtering, like primary emission.
    pub reflected_emission: Vec<Rgb>,
    /// Depth edge-stopping compares: view depth, or for a mirror the unfolded depth of what
    /// it reflects.
    pub depth: Vec<f32>,
    /// Largest depth change to a 4-neighbour of the same class group (for `w_z`'s scale).
    pub depth_step: Vec<f32>,
    /// Normal edge-stopping compares (a mirror's reflected normal).
    pub normal: Vec<Vec3>,
    /// Primary view depth and its neighbour step (reprojection tests).
    pub primary_depth: Vec<f32>,
    pub primary_step: Vec<f32>,
    /// Object id.
    pub object: Vec<u32>,
    /// Extra spatial bandwidth of sharp glossy pixels (Voorhuis Eq. 6), 0 where none.
    pub sigma_spatial: Vec<f32>,
}

/// `direct` and `indirect` light without `emitted`, the light a mirror chain ends in, taken
/// from the direct light first and the rest from the indirect (a chain of one mirror reaches
/// its end in one bounce, a longer one in more; per colour channel, never below zero).
pub fn without_emitted(direct: Rgb, indirect: Rgb, emitted: Rgb) -> [Rgb; 2] {
    let rest = (emitted - direct).max(Rgb::ZERO);
    [
        (direct - emitted).max(Rgb::ZERO),
        (indirect - rest).max(Rgb::ZERO),
    ]
}

fn class_of(g: &GuideBuffers, i: usize, p: &SvgfParams) -> Class {
    if !g.has_surface(i) {
        return Class::Sky;
    }
    let r = g.roughness.pixels()[i];
    if r <= 0.0 {
        Class::Mirror
    } else if r < p.glossy_limit {
        Class::SharpGlossy
    } else if r < p.specular_limit {
        Class::Glossy
    } else {
        Class::Diffuse
    }
}

/// Largest |v[i] − v[j]| over the 4-neighbours j with `same(j)`.
fn step_of(w: usize, h: usize, v: &[f32], i: usize, same: impl Fn(usize) -> bool) -> f32 {
    let (x, y) = (i % w, i / w);
    let mut s = 0.0f32;
    let mut look = |j: usize| {
        if same(j) {
            s = s.max((v[i] - v[j]).abs());
        }
    };
    if x > 0 {
        look(i - 1);
    }
    if x + 1 < w {
        look(i + 1);
    }
    if y > 0 {
        look(i - w);
    }
    if y + 1 < h {
        look(i + w);
    }
    s
}

impl Features {
    /// The features of `g` under `p`.
    pub fn new(g: &GuideBuffers, p: &SvgfParams) -> Self {
        let (w, h) = g.size();
        let n = w * h;
        let reflect = p.reflections == super::params::Reflections::Reproject;
        let class: Vec<Class> = (0..n).into_par_iter().map(|i| class_of(g, i, p)).collect();
        let refl = g.reflected.as_ref();
        let mirror_features = |i: usize| {
            reflect
                && class[i] == Class::Mirror
                && refl.is_some_and(|r| r.distance.pixels()[i] > 0.0)
        };
        let albedo = (0..n)
            .into_par_iter()
            .map(|i| match (class[i], refl) {
                (Class::Mirror, Some(r)) if reflect => r.albedo.pixels()[i],
                _ => g.albedo.pixels()[i],
            })
            .collect();
        let reflected_emission = (0..n)
            .into_par_iter()
            .map(|i| match (class[i], refl) {
                (Class::Mirror, Some(r)) if reflect => r.emission.pixels()[i],
                _ => Rgb::ZERO,
            })
            .collect();
        let depth: Vec<f32> = (0..n)
            .into_par_iter()
            .map(|i| match refl {
                Some(r) if mirror_features(i) => g.depth.pixels()[i] + r.distance.pixels()[i],
                _ => g.depth.pixels()[i],
            })
            .collect();
        let normal = (0..n)
            .into_par_iter()
            .map(|i| match refl {
                Some(r) if mirror_features(i) => r.normal.pixels()[i],
                _ => g.normal.pixels()[i],
            })
            .collect();
        let mirror_group = |i: usize| class[i] == Class::Mirror;
        let depth_step = (0..n)
            .into_par_iter()
            .map(|i| {
                step_of(w, h, &depth, i, |j| {
                    class[j] != Class::Sky && mirror_group(j) == mirror_group(i)
                })
            })
            .collect();
        let primary_depth = g.depth.pixels().to_vec();
        let primary_step = (0..n)
            .into_par_iter()
            .map(|i| step_of(w, h, &primary_depth, i, |j| class[j] != Class::Sky))
            .collect();
        // A pixel's footprint grows as the image shrinks; measured in pixels of the thesis'
        // 1280-wide frames, ω means the same at any resolution.
        let per_thesis_pixel = w as f32 / THESIS_WIDTH;
        let sigma_spatial = match refl {
            Some(r) if reflect => (0..n)
                .into_par_iter()
                .map(|i| {
                    if class[i] != Class::SharpGlossy || r.distance.pixels()[i] <= 0.0 {
                        return 0.0;
                    }
                    footprint(g, r, w, h, i, &class)
                        .map_or(0.0, |f| (-f * per_thesis_pixel / p.omega).exp())
                })
                .collect(),
            _ => vec![0.0; n],
        };
        Self {
            w,
            h,
            class,
            albedo,
            reflected_emission,
            depth,
            depth_step,
            normal,
            primary_depth,
            primary_step,
            object: g.object.pixels().to_vec(),
            sigma_spatial,
        }
    }
}

/// Width of the frames ω = 0.5 was chosen for (Voorhuis renders at 1280×720).
const THESIS_WIDTH: f32 = 1280.0;

/// The world-space footprint of a sharp glossy pixel's reflection, as if it were a mirror:
/// the mean distance from its approximate hit (Voorhuis Eq. 4) to its right and lower
/// neighbours' (a finite-difference stand-in for Igehy's ray differentials, seed 001 §2.4).
fn footprint(
    g: &GuideBuffers,
    r: &rt_film::ReflectedGuides,
    w: usize,
    h: usize,
    i: usize,
    class: &[Class],
) -> Option<f32> {
    let hit = |j: usize| {
        (r.distance.pixels()[j] > 0.0 && class[j].specular())
            .then(|| g.position.pixels()[j] + r.direction.pixels()[j] * r.distance.pixels()[j])
    };
    let here = hit(i)?;
    let (x, y) = (i % w, i / w);
    let across = if x + 1 < w { hit(i + 1) } else { hit(i - 1) };
    let down = if y + 1 < h { hit(i + w) } else { hit(i - w) };
    let (sum, count) = [across, down]
        .into_iter()
        .flatten()
        .fold((0.0f32, 0u32), |(s, c), q| (s + (q - here).length(), c + 1));
    (count > 0).then(|| sum / count as f32)
}
