//! Light tracing (Dammertz 2011, §6.1.2; Veach 1997, §10.3.3 and Arvo & Kirk's particle
//! tracing): particles leave the lights, and every vertex with a non-delta BSDF is connected
//! to the camera deterministically and splatted onto the pixel it is seen in.
//!
//! It estimates the same image as the path tracer, less what it cannot sample: paths whose
//! last bounce before the camera is a delta lobe (mirrors and smooth glass seen by the
//! camera, and whatever is seen through them, are black) and the environment seen directly.
//! Caustics on diffuse surfaces are its strength. Particles from the environment start by
//! plane sampling ([`rt_core::emission`]).
//!
//! Deviations and choices: `max_depth = D` connects vertices 1 to `D` (the path tracer's
//! bounce count: a path of `D` scattering events), and the emitter itself is connected too
//! (emitters seen directly). Shading normals use Veach's adjoint correction (§5.3), so light
//! tracing and path tracing agree on smooth-shaded meshes; the layered material's Fresnel
//! weights depend on the outgoing direction only, which is not reciprocal, so on coated
//! materials the two converge to slightly different images (the partitioned renderer of §6.3
//! tolerates this by construction; light tracing simply estimates the adjoint). Russian
//! roulette is the path tracer's. A pass takes one light path per pixel per sample index.
//!
//! On-demand spectral rendering (§6.6, `rt_core::spectral`): a particle is RGB until its first
//! dispersive event (a prism), which assigns it a wavelength and its RGB weight; the wavelength
//! stays with it for the rest of its walk, so a prism casts a coloured caustic.

use crate::driver::{RenderStats, SamplePass};
use crate::technique::Technique;
use crate::transport::{adjoint_cos, importance_weight, survives_roulette};
use crate::work;
use crate::{Ctx, RayCounters};
use rayon::prelude::*;
use rt_core::{
    camera::CameraConnection,
    glam::{Vec2, Vec3},
    material::Bsdf,
    ray::{shadow_segment, spawn_ray},
    Rgb, Sampler,
};
use rt_film::{Film, Splat};
use std::time::Instant;

/// Light paths per work item: enough that scheduling is noise, few enough that a pass of a
/// small image still spreads over the threads.
const CHUNK_PATHS: u32 = 4096;

/// Work items rendered between two merges into the film; bounds the memory of splats in
/// flight (a few splats per light path) whatever the image size.
const BATCH_ITEMS: usize = 64;

/// The light tracer.
#[derive(Clone, Debug)]
pub struct LightTracer {
    /// Maximum number of bounces (scattering events) of a path, as for the path tracer.
    pub max_depth: u32,
    /// Bounce after which Russian roulette may end paths.
    pub rr_depth: u32,
    /// Dispersive materials use their wavelength-dependent index (false: their `n_d`, as if
    /// the renderer had no spectral code; for tests).
    #[doc(hidden)]
    pub spectral: bool,
}

impl LightTracer {
    /// A light tracer allowing `max_depth` bounces.
    pub fn new(max_depth: u32) -> Self {
        Self {
            max_depth,
            rr_depth: 3,
            spectral: true,
        }
    }
}

impl Technique for LightTracer {
    fn name(&self) -> &str {
        "light"
    }

    fn splats(&self) -> bool {
        true
    }

    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats {
        let start = Instant::now();
        let discarded_before = film.discarded();
        let paths = film.width().saturating_mul(film.height());
        let items = work::items(pass.indices.clone(), paths, CHUNK_PATHS);
        let mut buffers: Vec<(Vec<Splat>, RayCounters)> = (0..BATCH_ITEMS.min(items.len()))
            .map(|_| (Vec::new(), RayCounters::default()))
            .collect();
        let mut rays = RayCounters::default();
        let rows = film.height();
        // Plane sampling's box, read once per pass rather than once per light path.
        let bounds = ctx.accel.bounds();
        for (b, batch) in items.chunks(BATCH_ITEMS).enumerate() {
            buffers[..batch.len()]
                .par_iter_mut()
                .zip(batch.par_iter())
                .for_each(|((splats, counters), item)| {
                    splats.clear();
                    *counters = RayCounters::default();
                    let mut sampler = Sampler::with_stream(seed, pass.stream);
                    for k in item.first..item.first + item.count {
                        sampler.start_light_path(k, item.index);
                        self.trace(ctx, &bounds, &mut sampler, splats, counters);
                    }
                });
            for (item, (splats, counters)) in batch.iter().zip(&buffers) {
                film.add_splats(item.index, u64::from(item.count), splats);
                rays += *counters;
            }
            progress(work::rows_done(
                b * BATCH_ITEMS + batch.len(),
                items.len(),
                rows,
            ));
        }
        RenderStats {
            elapsed: start.elapsed(),
            samples: u64::from(paths) * pass.indices.len() as u64,
            rays,
            discarded: film.discarded() - discarded_before,
        }
    }
}

impl LightTracer {
    /// Traces one light path, pushing its camera connections onto `splats`. Random numbers are
    /// drawn in a fixed order per vertex, used or not, so a vertex's dimensions do not depend
    /// on the branches earlier vertices took.
    fn trace(
        &self,
        ctx: &Ctx<'_>,
        bounds: &rt_core::Aabb,
        sampler: &mut Sampler,
        splats: &mut Vec<Splat>,
        counters: &mut RayCounters,
    ) {
        let (scene, camera) = (ctx.scene, ctx.camera);
        let thin_lens = !camera.is_pinhole();
        let lens = |s: &mut Sampler| {
            if thin_lens {
                s.next_2d()
            } else {
                Vec2::ZERO
            }
        };
        let u_sel = sampler.next_1d();
        let u_pos = sampler.next_2d();
        let u_dir = sampler.next_2d();
        let u_lens = lens(sampler);
        let Some(e) = scene
            .lights()
            .sample_emission(scene, bounds, u_sel, u_pos, u_dir)
        else {
            return;
        };
        // The emitter seen directly: Le · cos / pdf_area, through the camera's importance.
        if let Some(pt) = e.point {
            if let Some(c) = camera.connect(pt.point, u_lens) {
                let le = pt.radiance_toward(c.wi);
                let cos = pt.normal.dot(c.wi).abs();
                let value = le * (cos * c.importance / pt.pdf_area);
                splat(
                    ctx, splats, counters, &c, value, pt.point, pt.error, pt.normal,
                );
            }
        }
        let mut beta = e.beta;
        let start = beta.max_element();
        let mut ray = e.ray();
        let mut depth = 0u32;
        // The particle's wavelength once a dispersive event has drawn one (§6.6).
        let mut lambda: Option<f32> = None;
        while depth < self.max_depth {
            counters.rays += 1;
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                break;
            };
            depth += 1;
            let si = scene.surface(&hit, 0.0);
            let material = &scene.materials[si.material as usize];
            let wo = -ray.dir;
            let tint = scene.tint(material, si.uv);
            // Importance's BSDF: refraction without radiance's `1/η²`.
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo)
                .with_wavelength(lambda)
                .adjoint();
            let bsdf = if self.spectral {
                bsdf
            } else {
                bsdf.without_dispersion()
            };
            let u_lens = lens(sampler);
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            if bsdf.has_non_delta() {
                if let Some(c) = camera.connect(si.p, u_lens) {
                    let f = bsdf.eval(c.wi);
                    if f.max_element() > 0.0 {
                        let value = beta * f * (adjoint_cos(wo, c.wi, si.ns, si.ng) * c.importance);
                        splat(ctx, splats, counters, &c, value, si.p, si.p_error, si.ng);
                    }
                }
            }
            if depth >= self.max_depth {
                break;
            }
            let Some(s) = bsdf.sample(u_layer, u_bsdf) else {
                break;
            };
            // `s.weight` holds |cos(wi, ns)|; importance transport wants the adjoint's.
            beta *= importance_weight(&s, wo, si.ns, si.ng);
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            lambda = s.wavelength;
            ray = spawn_ray(si.p, si.p_error, si.ng, s.wi);
            if depth > self.rr_depth && !survives_roulette(&mut beta, start, u_rr) {
                break;
            }
        }
    }
}

/// Pushes `value` for the pixel `c` lands in if the segment from `p` to the lens is clear.
#[allow(clippy::too_many_arguments)]
fn splat(
    ctx: &Ctx<'_>,
    splats: &mut Vec<Splat>,
    counters: &mut RayCounters,
    c: &CameraConnection,
    value: Rgb,
    p: Vec3,
    p_error: Vec3,
    n: Vec3,
) {
    if value.max_element() <= 0.0 {
        return;
    }
    counters.shadow_rays += 1;
    let (r, t_max) = shadow_segment(p, p_error, n, c.near_point, Vec3::ZERO, c.wi);
    if ctx.accel.occluded(&r, t_max) {
        return;
    }
    let cam = ctx.camera;
    let x = (c.raster.x as u32).min(cam.width - 1);
    let y = (c.raster.y as u32).min(cam.height - 1);
    splats.push(Splat {
        pixel: y * cam.width + x,
        value,
    });
}
