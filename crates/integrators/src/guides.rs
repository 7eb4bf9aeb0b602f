//! The guide-buffer pass of a sequence frame: one ray through every pixel's centre, its primary
//! hit's features, how that hit moved on screen since the previous frame, and for specular hits
//! what they reflect ([`rt_film::GuideBuffers`]).
//!
//! Motion vectors follow the scene's rigid motion exactly: a hit on an instance is carried back
//! to the previous frame by that instance's transforms (previous ∘ current⁻¹), a static hit
//! stays put, and either is projected with the previous frame's camera. A pixel that sees the
//! environment moves as its direction does. A point behind the previous camera gets a motion
//! that lands far off screen, so no history is fetched for it.
//!
//! Reflected features (Voorhuis 2018 §4.2–4.3): a pure mirror's pixel follows mirror bounces to
//! the first surface that is not a mirror (position, normal, unfolded distance, product of the
//! albedos on the way); a glossy pixel traces its representative ray, the mirror direction, once.
//! Deviation: Voorhuis takes a glossy pixel's depth from the ray its sample happened to take;
//! tracing the mirror direction costs one ray but makes the feature noise-free.

use crate::Ctx;
use rayon::prelude::*;
use rt_core::glam::{Mat4, Vec2, Vec3};
use rt_core::material::Bsdf;
use rt_core::{Camera, Image, Material, Ray, Rgb, Scene};
use rt_film::{GuideBuffers, ReflectedGuides, NO_ID};

/// The previous frame's view, for motion vectors.
#[derive(Clone, Copy, Debug)]
pub struct PreviousView<'a> {
    /// The camera as it was.
    pub camera: &'a Camera,
    /// The scene time it was rendered at (instances are placed at it).
    pub time: f32,
}

/// What the guide pass computes besides the primary features.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuideOptions {
    /// Compute reflected features for pixels whose roughness is below `specular_limit`.
    pub reflected: bool,
    /// Roughness below which a hit counts as specular (Voorhuis: 0.9).
    pub specular_limit: f32,
    /// Most mirror bounces followed to find what a mirror reflects.
    pub max_mirror_bounces: u32,
}

impl Default for GuideOptions {
    fn default() -> Self {
        Self {
            reflected: true,
            specular_limit: 0.9,
            max_mirror_bounces: 4,
        }
    }
}

/// Motion vector that sends a pixel's history fetch off screen (the point was behind the
/// previous camera). Finite, so no NaN or Inf reaches a buffer.
const OFF_SCREEN: f32 = 1.0e7;

/// Layers lighter than this share of a material's weight do not decide its roughness.
const SIGNIFICANT_LAYER: f32 = 0.1;

/// Roughness of material `m` for classifying its pixels, on Beckmann's scale: that of its
/// sharpest layer holding at least a tenth of its weight, a Blinn-Phong lobe of exponent
/// `n = 1024κ + 1` taken as Beckmann `α = √(2 / (n + 2))` (Walter et al. 2007's correspondence);
/// 0 for a delta layer, 1 for a Lambertian one (κ = 0). A coated or layered surface with a
/// visible sharp lobe is thereby glossy, not the blend of its layers' hardness.
pub fn roughness(m: &Material) -> f32 {
    let total: f32 = m.layers.iter().map(|l| l.weight).sum();
    m.layers
        .iter()
        .filter(|l| total > 0.0 && l.weight >= SIGNIFICANT_LAYER * total)
        .map(|l| {
            if l.is_delta() {
                0.0
            } else if l.hardness <= 0.0 {
                1.0
            } else {
                (2.0 / (1024.0 * l.hardness + 3.0)).sqrt().min(1.0)
            }
        })
        .fold(1.0f32, f32::min)
}

/// True if every layer of `m` is a delta lobe (a pure mirror or smooth glass).
fn pure_specular(m: &Material) -> bool {
    !m.layers.is_empty() && m.layers.iter().all(|l| l.is_delta())
}

/// Index of the object (named triangle range) holding triangle `prim`, or [`NO_ID`].
fn object_of(scene: &Scene, prim: u32) -> u32 {
    let k = scene.objects.partition_point(|o| o.first <= prim);
    match k.checked_sub(1) {
        Some(i) if prim - scene.objects[i].first < scene.objects[i].count => i as u32,
        _ => NO_ID,
    }
}

/// One pixel's features.
#[derive(Clone, Copy, Default)]
struct Texel {
    depth: f32,
    position: Vec3,
    normal: Vec3,
    albedo: Rgb,
    emission: Rgb,
    motion: Vec2,
    previous_depth: f32,
    object: u32,
    instance: u32,
    roughness: f32,
    r_position: Vec3,
    r_normal: Vec3,
    r_distance: f32,
    r_albedo: Rgb,
    r_direction: Vec3,
    r_emission: Rgb,
}

/// A surface hit along a guide ray: where, facing which way, what it reflects.
struct Surface {
    t: f32,
    si: rt_core::scene::SurfaceHit,
    normal: Vec3,
    albedo: Rgb,
}

fn trace(ctx: &Ctx<'_>, ray: &Ray) -> Option<Surface> {
    let hit = ctx.accel.intersect(ray, f32::INFINITY)?;
    let scene = ctx.scene;
    let si = scene.surface(&hit, ray.time);
    let material = &scene.materials[si.material as usize];
    let wo = -ray.dir.normalize();
    let tint = scene.tint(material, si.uv);
    let albedo = Bsdf::new(material, tint, si.ns, si.ng, wo).albedo();
    let normal = if si.ns.dot(wo) < 0.0 { -si.ns } else { si.ns };
    Some(Surface {
        t: hit.t * ray.dir.length(),
        si,
        normal,
        albedo,
    })
}

#[inline]
fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    (d - 2.0 * d.dot(n) * n).normalize_or_zero()
}

/// Renders the guide buffers of the scene as it is now (`ctx.scene.time`), with motion relative
/// to `previous` (zero motion without one). The result does not depend on the thread count.
pub fn render_guides(
    ctx: &Ctx<'_>,
    previous: Option<&PreviousView<'_>>,
    options: &GuideOptions,
) -> GuideBuffers {
    let camera = ctx.camera;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let scene = ctx.scene;
    // Per instance: previous placement ∘ current placement⁻¹, carrying a world point on the
    // instance to where it was.
    let back: Vec<Mat4> = match previous {
        Some(p) => scene
            .instances
            .iter()
            .map(|i| i.matrix_at(p.time) * i.transform.m.inverse())
            .collect(),
        None => Vec::new(),
    };
    let texels: Vec<Texel> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let back = &back;
            (0..w).map(move |x| pixel(ctx, previous, back, options, x, y))
        })
        .collect();
    let reflected = options.reflected.then(|| ReflectedGuides {
        position: plane(&texels, w, h, |t| t.r_position),
        normal: plane(&texels, w, h, |t| t.r_normal),
        distance: plane(&texels, w, h, |t| t.r_distance),
        albedo: plane(&texels, w, h, |t| t.r_albedo),
        direction: plane(&texels, w, h, |t| t.r_direction),
        emission: plane(&texels, w, h, |t| t.r_emission),
    });
    GuideBuffers {
        depth: plane(&texels, w, h, |t| t.depth),
        position: plane(&texels, w, h, |t| t.position),
        normal: plane(&texels, w, h, |t| t.normal),
        albedo: plane(&texels, w, h, |t| t.albedo),
        emission: plane(&texels, w, h, |t| t.emission),
        motion: plane(&texels, w, h, |t| t.motion),
        previous_depth: plane(&texels, w, h, |t| t.previous_depth),
        object: plane(&texels, w, h, |t| t.object),
        instance: plane(&texels, w, h, |t| t.instance),
        roughness: plane(&texels, w, h, |t| t.roughness),
        reflected,
    }
}

/// One feature of every texel as an image.
fn plane<T>(texels: &[Texel], w: usize, h: usize, f: impl Fn(&Texel) -> T) -> Image<T> {
    Image::from_fn(w, h, |x, y| f(&texels[y * w + x]))
}

/// Screen motion of a point now at raster position `now` that was at world point `before`.
fn motion_to(previous: Option<&PreviousView<'_>>, now: Vec2, before: Vec3) -> Vec2 {
    match previous {
        None => Vec2::ZERO,
        Some(p) => match p.camera.project(before) {
            Some(q) if q.is_finite() => now - q,
            _ => Vec2::splat(OFF_SCREEN),
        },
    }
}

fn pixel(
    ctx: &Ctx<'_>,
    previous: Option<&PreviousView<'_>>,
    back: &[Mat4],
    options: &GuideOptions,
    x: usize,
    y: usize,
) -> Texel {
    let scene = ctx.scene;
    let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
    let ray = ctx.camera.generate_ray(centre, Vec2::ZERO);
    let mut t = Texel {
        object: NO_ID,
        instance: NO_ID,
        roughness: 1.0,
        ..Texel::default()
    };
    let Some(s) = trace(ctx, &ray) else {
        t.emission = scene.environment.radiance(ray.dir.normalize());
        // A direction at infinity moves only with the camera's turning.
        let dir = ray.dir.normalize();
        let before = previous.map_or(Vec3::ZERO, |p| p.camera.position + dir);
        t.motion = motion_to(previous, centre, before);
        return t;
    };
    let material = &scene.materials[s.si.material as usize];
    let wo = -ray.dir.normalize();
    t.depth = (s.si.p - ctx.camera.position)
        .dot(ctx.camera.forward)
        .max(f32::MIN_POSITIVE);
    t.position = s.si.p;
    t.normal = s.normal;
    t.albedo = s.albedo;
    t.emission = material.emitted(s.si.ng, wo);
    t.object = object_of(scene, s.si.prim);
    t.instance = s.si.instance.unwrap_or(NO_ID);
    t.roughness = roughness(material);
    let before = match s.si.instance {
        Some(i) if !back.is_empty() => back[i as usize].transform_point3(s.si.p),
        _ => s.si.p,
    };
    t.motion = motion_to(previous, centre, before);
    t.previous_depth = match previous {
        Some(p) => (before - p.camera.position).dot(p.camera.forward).max(0.0),
        None => t.depth,
    };
    if options.reflected && t.roughness < options.specular_limit {
        reflected(
            ctx,
            options,
            &s,
            ray.dir.normalize(),
            pure_specular(material),
            &mut t,
        );
    }
    t
}

/// Fills the reflected features of specular hit `s`, seen along `d`.
fn reflected(
    ctx: &Ctx<'_>,
    options: &GuideOptions,
    s: &Surface,
    d: Vec3,
    mirror: bool,
    t: &mut Texel,
) {
    let dir = reflect(d, s.normal);
    t.r_direction = dir;
    let mut ray = s.si.spawn_ray(dir);
    let mut albedo = if mirror { s.albedo } else { Rgb::ONE };
    let mut distance = 0.0f32;
    for _ in 0..options.max_mirror_bounces.max(1) {
        let Some(hit) = trace(ctx, &ray) else {
            // The reflection escapes: nothing to reproject by.
            t.r_albedo = albedo;
            if mirror {
                t.r_emission = albedo * ctx.scene.environment.radiance(ray.dir.normalize());
            }
            return;
        };
        distance += hit.t;
        let m = &ctx.scene.materials[hit.si.material as usize];
        if mirror && pure_specular(m) {
            albedo *= hit.albedo;
            ray = hit.si.spawn_ray(reflect(ray.dir.normalize(), hit.normal));
            continue;
        }
        t.r_position = hit.si.p;
        t.r_normal = hit.normal;
        t.r_distance = distance;
        t.r_albedo = albedo * hit.albedo;
        if mirror {
            t.r_emission = albedo * m.emitted(hit.si.ng, -ray.dir.normalize());
        }
        return;
    }
    t.r_albedo = albedo;
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Layer;

    #[test]
    fn roughness_is_that_of_the_sharpest_significant_layer() {
        let white = Rgb::splat(0.8);
        assert_eq!(roughness(&Material::diffuse("d", white)), 1.0);
        assert_eq!(roughness(&Material::mirror("m", white)), 0.0);
        // A glossy lobe of hardness 0.3 over a diffuse base: Beckmann ≈ 0.08, not the blend.
        let mut floor = Material::diffuse("f", white);
        floor.layers = vec![Layer::new(0.4, white, 0.3), Layer::new(0.6, white, 0.0)];
        let r = roughness(&floor);
        assert!((r - (2.0f32 / 310.2).sqrt()).abs() < 1e-4, "{r}");
        // A lobe with 5 % of the weight does not decide.
        floor.layers = vec![Layer::new(0.05, white, 1.0), Layer::new(0.95, white, 0.0)];
        assert_eq!(roughness(&floor), 1.0);
    }
}
