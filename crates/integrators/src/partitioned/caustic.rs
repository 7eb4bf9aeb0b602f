//! The caustic histogram of the partitioned renderer (Dammertz 2011, §6.3.2): the pass's eye
//! vertices are the bins, in a point kd-tree with a radius each; photons leave the primary
//! lights, must meet a specular part first, and at every later vertex land in every bin that
//! covers them (part B, `EDS(S|D)*L`, and behind specular chains part C). With
//! `indirect_caustics = k` photons also leave the VPLs of the first `k` diffuse bounces, in
//! directions drawn from their diffuse part (the thesis' artist-set depth of indirect
//! caustics, `EDS+D+L`); without them those paths are missing from the image, a bias the
//! thesis accepts by default.
//!
//! A photon's contribution to its bin's pixel is `β_eye · f_D(ω_photon) · Φ / (π r²)`, `Φ` the
//! photon's power over the draws of its light (rejected draws of the projection maps
//! included). Bias: the density estimate over a disc of half the pixel footprint blurs the
//! caustic like a reconstruction filter of that size. Deviation: a photon only lands in a bin
//! whose surface faces the same way (normals within 25°, the eye and the photon on the same
//! side), which keeps caustics from leaking round corners and through thin walls. Deviation: a
//! photon lands in every covering bin, where the thesis gives it to the nearest one only
//! ("bins never overlap"). With fresh jitter every pass, neighbouring eye vertices are often
//! closer than two radii, and the nearest-only rule then drops the overlap from every other
//! bin's density: the caustic core under a glass sphere came out 15 % dark
//! (`tests/tests/caustic_histogram.rs` fails with it, block z 9.4).

use super::eye::EyeVertex;
use super::projection::{Occupant, ProjectionMap};
use super::vpl::{PrimaryLight, Source, Vpl};
use super::Partitioned;
use crate::transport::{importance_weight, survives_roulette};
use crate::{Ctx, RayCounters};
use rayon::prelude::*;
use rt_accel::points::{PointItem, PointKdTree, PointQuery};
use rt_core::{
    emission::{cosine_emission, plane_sample},
    glam::{Vec2, Vec3},
    material::{Bsdf, LayerClass},
    ray::spawn_ray,
    Aabb, Ray, Rgb, SampleStream, Sampler,
};
use std::f32::consts::PI;
use std::time::{Duration, Instant};

/// Photons per parallel work item.
const CHUNK: u32 = 1024;

/// One work item's landings (pixel, value), rays and photons traced.
type ItemResult = (Vec<(u32, Rgb)>, RayCounters, u64);

/// Cosine of the largest angle between a bin's and a photon's surface normals.
const SAME_SURFACE_COS: f32 = 0.9;

/// What one pass's caustic photons did.
#[derive(Default)]
pub(super) struct CausticPass {
    /// Per pixel, the sum of its bin's photons.
    pub radiance: Vec<Rgb>,
    /// Photon draws (the normalisation), traced photons, photons landed in a bin.
    pub emitted: u64,
    pub traced: u64,
    pub landed: u64,
    /// Sum over the emitter lights of their map's coverage, and how many maps.
    pub coverage_sum: f64,
    pub maps: u64,
    pub map_time: Duration,
}

/// Specular triangles grouped by [`OCCUPANT_GROUP`] consecutive ones of one object, each group
/// as its bounding sphere: what the projection maps cover. Per triangle (the thesis' choice),
/// the 1280 triangles of a glass sphere made the maps cost 12 % of the caustic time; grouped,
/// the spheres grow a little and cover slightly more cells, and building takes an eighth.
pub(super) fn occupants(scene: &rt_core::Scene) -> Vec<Occupant> {
    let specular = |m: &rt_core::Material| {
        m.layers
            .iter()
            .any(|l| l.weight > 0.0 && LayerClass::Specular.contains(l))
    };
    let mut out = Vec::new();
    let mut group: Vec<Vec3> = Vec::with_capacity(3 * OCCUPANT_GROUP);
    let flush = |group: &mut Vec<Vec3>, out: &mut Vec<Occupant>| {
        if group.is_empty() {
            return;
        }
        let b = Aabb::from_points(group.iter());
        let center = b.center();
        let radius = group.iter().map(|p| p.distance(center)).fold(0.0, f32::max);
        out.push(Occupant {
            center,
            radius: radius * (1.0 + 1e-4) + 1e-6 * center.abs().max_element(),
        });
        group.clear();
    };
    // Object ranges in triangle order; triangles outside every object form their own run.
    let mut object_end = scene.objects.iter().map(|o| o.first + o.count);
    let mut next_end = object_end.next();
    let mut prev: Option<u32> = None;
    for (i, v) in scene.triangles.iter().enumerate() {
        let i = i as u32;
        while next_end.is_some_and(|e| i >= e) {
            flush(&mut group, &mut out);
            next_end = object_end.next();
        }
        if !specular(scene.material_of(i)) {
            continue;
        }
        if prev.is_some_and(|p| p + 1 != i) || group.len() >= 3 * OCCUPANT_GROUP {
            flush(&mut group, &mut out);
        }
        group.extend_from_slice(v);
        prev = Some(i);
    }
    flush(&mut group, &mut out);
    out
}

/// Consecutive specular triangles per projection-map occupant.
const OCCUPANT_GROUP: usize = 8;

/// One work item: photons `first..first + count` of photon source `light` (the primary
/// lights, then the VPLs that emit indirect caustics).
#[derive(Clone, Copy)]
struct Item {
    light: usize,
    first: u32,
    count: u32,
}

/// Where a pass's caustic photons start.
#[derive(Clone, Copy)]
enum PhotonSource<'v, 'a> {
    /// A point on a light (or the environment).
    Light(&'v PrimaryLight),
    /// A VPL on a surface with a diffuse part: indirect caustics.
    Vpl(&'v Vpl<'a>),
}

/// A photon in flight: its ray, power, wavelength and the scattering vertices of its light
/// path before the ray (0 from a light).
struct Photon {
    ray: Ray,
    beta: Rgb,
    lambda: Option<f32>,
    vertices: u32,
}

impl Partitioned {
    /// Traces the pass's caustic photons into the bins at `eyes`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn caustics(
        &self,
        ctx: &Ctx<'_>,
        bounds: &Aabb,
        seed: u32,
        stream: SampleStream,
        index: u32,
        eyes: &[EyeVertex],
        primaries: &[PrimaryLight],
        vpls: &[Vpl<'_>],
        occupants: &[Occupant],
        counters: &mut RayCounters,
    ) -> CausticPass {
        let pixels = (ctx.camera.width * ctx.camera.height) as usize;
        let mut out = CausticPass {
            radiance: vec![Rgb::ZERO; pixels],
            ..CausticPass::default()
        };
        let per_light = self.options.photons / self.options.vpl_paths.max(1);
        if occupants.is_empty() || primaries.is_empty() || per_light == 0 {
            return out;
        }
        let items: Vec<PointItem> = eyes
            .iter()
            .enumerate()
            .filter(|(_, e)| e.radius > 0.0 && e.radius.is_finite())
            .map(|(i, e)| PointItem::with_radius(e.p, i as u32, e.radius))
            .collect();
        let Ok(bins) = PointKdTree::build(&items) else {
            return out;
        };
        if bins.is_empty() {
            return out;
        }
        // A photon from a VPL needs a specular vertex and then a diffuse one within the depth.
        let sources: Vec<PhotonSource> = primaries
            .iter()
            .map(PhotonSource::Light)
            .chain(
                vpls.iter()
                    .filter(|v| {
                        matches!(v.source, Source::Surface { .. })
                            && v.bounce <= self.options.indirect_caustics
                            && v.bounce + 2 <= self.max_depth
                    })
                    .map(PhotonSource::Vpl),
            )
            .collect();
        let start = Instant::now();
        let maps: Vec<Option<ProjectionMap>> = sources
            .par_iter()
            .map(|source| match source {
                _ if !self.options.projection_maps => None,
                PhotonSource::Light(l) => (l.travel == Vec3::ZERO)
                    .then(|| ProjectionMap::build(l.p, l.n, l.two_sided, occupants)),
                // Both hemispheres: a diffuse part may transmit.
                PhotonSource::Vpl(v) => Some(ProjectionMap::build(v.p, v.ng, true, occupants)),
            })
            .collect();
        out.map_time = start.elapsed();
        for m in maps.iter().flatten() {
            out.coverage_sum += f64::from(m.coverage());
            out.maps += 1;
        }
        let work: Vec<Item> = (0..sources.len())
            .flat_map(|light| {
                (0..per_light.div_ceil(CHUNK)).map(move |c| Item {
                    light,
                    first: c * CHUNK,
                    count: CHUNK.min(per_light - c * CHUNK),
                })
            })
            .collect();
        let vpl_paths = self.options.vpl_paths;
        let results: Vec<ItemResult> = work
            .par_iter()
            .map(|item| {
                let mut sampler = Sampler::with_stream(seed, stream);
                let mut query = PointQuery::new(1);
                let mut deposits = Vec::new();
                let mut rays = RayCounters::default();
                let mut traced = 0u64;
                let map = maps[item.light].as_ref();
                for m in item.first..item.first + item.count {
                    let k = (item.light as u32)
                        .wrapping_mul(per_light)
                        .wrapping_add(vpl_paths + m);
                    sampler.start_light_path(k, index);
                    let photon = match sources[item.light] {
                        PhotonSource::Light(light) => {
                            photon_ray(light, map, bounds, sampler.next_2d()).map(|(ray, w)| {
                                Photon {
                                    ray,
                                    beta: light.beta * w / per_light as f32,
                                    lambda: None,
                                    vertices: 0,
                                }
                            })
                        }
                        PhotonSource::Vpl(vpl) => {
                            let u_layer = sampler.next_1d();
                            vpl_photon(vpl, map, per_light, u_layer, sampler.next_2d())
                        }
                    };
                    let Some(photon) = photon else {
                        continue;
                    };
                    traced += 1;
                    self.trace_photon(
                        ctx,
                        photon,
                        &mut sampler,
                        &bins,
                        &mut query,
                        eyes,
                        &mut deposits,
                        &mut rays,
                    );
                }
                (deposits, rays, traced)
            })
            .collect();
        for (deposits, rays, traced) in results {
            out.landed += deposits.len() as u64;
            for (pixel, v) in deposits {
                out.radiance[pixel as usize] += v;
            }
            *counters += rays;
            out.traced += traced;
        }
        out.emitted = u64::from(per_light) * sources.len() as u64;
        out
    }

    /// Follows one photon through specular parts, landing it in a bin at every vertex after
    /// the first.
    #[allow(clippy::too_many_arguments)]
    fn trace_photon(
        &self,
        ctx: &Ctx<'_>,
        photon: Photon,
        sampler: &mut Sampler,
        bins: &PointKdTree,
        query: &mut PointQuery,
        eyes: &[EyeVertex],
        deposits: &mut Vec<(u32, Rgb)>,
        counters: &mut RayCounters,
    ) {
        let scene = ctx.scene;
        let Photon {
            mut ray,
            mut beta,
            // The photon's wavelength once a dispersive event has drawn one (§6.6).
            mut lambda,
            vertices,
        } = photon;
        let start = beta.max_element();
        for bounce in 0..self.max_depth.saturating_sub(vertices) {
            counters.rays += 1;
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                return;
            };
            let si = scene.surface(&hit, 0.0);
            let wo = -ray.dir;
            if bounce > 0 {
                // Every bin whose disk holds the photon, not only the nearest (the thesis'
                // rule): jittered eye vertices are often closer than two radii, and giving the
                // overlap to one bin lost 15 % of a caustic's core
                // (tests/tests/caustic_histogram.rs).
                bins.for_each_within(si.p, bins.max_radius(), query, |n| {
                    let e = &eyes[n.payload as usize];
                    let same_side = e.wo.dot(si.ng) * wo.dot(si.ng) > 0.0;
                    if n.dist2 <= e.radius * e.radius
                        && e.depth + bounce + vertices <= self.max_depth
                        && same_side
                        && e.ng.dot(si.ng) >= SAME_SURFACE_COS
                    {
                        let f = e.diffuse_bsdf(ctx).eval(wo);
                        let v = e.beta * f * beta / (PI * e.radius * e.radius);
                        if v.max_element() > 0.0 && v.is_finite() {
                            deposits.push((e.pixel, v));
                        }
                    }
                });
            }
            let material = &scene.materials[si.material as usize];
            let tint = scene.tint(material, si.uv);
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            // Only the specular part carries a photon on: its diffuse part is the VPLs'.
            // Importance's BSDF, as the light tracer's (refraction without `1/η²`).
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo)
                .with_wavelength(lambda)
                .adjoint()
                .restricted(LayerClass::Specular);
            let Some(s) = bsdf.sample(u_layer, u_bsdf) else {
                return;
            };
            beta *= importance_weight(&s, wo, si.ns, si.ng);
            lambda = s.wavelength;
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                return;
            }
            if bounce + 1 > self.rr_depth && !survives_roulette(&mut beta, start, u_rr) {
                return;
            }
            ray = spawn_ray(si.p, si.p_error, si.ng, s.wi);
        }
    }
}

/// A photon leaving `vpl` in a direction its diffuse part scatters to, for random numbers
/// `u_layer` and `u`, with its share of `per_light` photons; `None` when the projection map
/// rejects the direction or the part scatters nothing.
fn vpl_photon(
    vpl: &Vpl<'_>,
    map: Option<&ProjectionMap>,
    per_light: u32,
    u_layer: f32,
    u: Vec2,
) -> Option<Photon> {
    let Source::Surface { bsdf, wo, ns } = &vpl.source else {
        return None;
    };
    let s = bsdf.sample(u_layer, u)?;
    if map.is_some_and(|m| !m.allows(s.wi)) {
        return None;
    }
    let beta = vpl.beta * importance_weight(&s, *wo, *ns, vpl.ng) / per_light as f32;
    Some(Photon {
        ray: spawn_ray(vpl.p, vpl.p_error, vpl.ng, s.wi),
        beta,
        lambda: s.wavelength.or(bsdf.wavelength()),
        vertices: vpl.bounce,
    })
}

/// The ray of a photon from `light` for random numbers `u` and what multiplies the light's
/// `beta` for it (1, or a point or spot light's emission over the direction's pdf), or `None`
/// when the projection map rejects its direction (it would meet a diffuse surface first).
fn photon_ray(
    light: &PrimaryLight,
    map: Option<&ProjectionMap>,
    bounds: &Aabb,
    u: Vec2,
) -> Option<(Ray, Rgb)> {
    if light.travel != Vec3::ZERO {
        let (o, _) = plane_sample(bounds, light.travel, u)?;
        return Some((Ray::new(o, light.travel), Rgb::ONE));
    }
    if let Some(delta) = &light.delta {
        let e = delta.emit(bounds, Vec2::ZERO, u)?;
        if map.is_some_and(|m| !m.allows(e.dir)) {
            return None;
        }
        return Some((Ray::new(e.origin, e.dir), e.beta));
    }
    let (n, dir, _) = cosine_emission(light.n, light.two_sided, u)?;
    if map.is_some_and(|m| !m.allows(dir)) {
        return None;
    }
    Some((spawn_ray(light.p, light.p_error, n, dir), Rgb::ONE))
}
