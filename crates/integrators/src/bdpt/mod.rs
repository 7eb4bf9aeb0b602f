//! Bidirectional path tracing (Veach 1997, ch. 10; Lafortune & Willems 1993) with multiple
//! importance sampling over every strategy, after pbrt-v4's `BDPTIntegrator` (Pharr, Jakob &
//! Humphreys, *Physically Based Rendering*, 4th ed., §13.4 of the online edition): per pixel
//! sample, a camera subpath and a light subpath, every prefix pair `(s, t)` connected, each
//! weighted by the power heuristic over all strategies that could have made the same path.
//! Dammertz (2011, §6.3–6.4) compares both the partitioned renderer and plane sampling with it.
//!
//! Strategies: `s = 0` (the camera subpath hits a light), `s = 1` (next-event estimation, the
//! path tracer's light sample), `t = 1` (the light subpath connected to the camera and splatted,
//! as [`crate::LightTracer`] does), and the rest connecting a light vertex to a camera vertex
//! by a shadow ray. Light subpaths from the environment start by plane sampling
//! ([`rt_core::emission`]), so the environment takes part in every strategy. Delta lights
//! (points, spots, directional lights) start light subpaths and are sampled by `s = 1`; as in
//! pbrt-v4 (`IsDeltaLight`), the strategy `s = 0`, which cannot find them, drops out of their
//! paths' weights.
//!
//! Choices and deviations from pbrt-v4:
//! - The power heuristic (exponent 2), where pbrt-v4 uses the balance heuristic.
//! - Russian roulette, as the path tracer's, on both subpaths; the MIS weights ignore its
//!   probabilities (they still sum to one over strategies, so the estimate stays unbiased).
//! - `max_depth = D` as for the path tracer: at most `D` scattering vertices between camera and
//!   light, so `bdpt` and `path` with the same depth estimate the same image.
//! - The light subpath for pixel `k` and sample index `i` is [`crate::LightTracer`]'s light path
//!   `k` of index `i` (same stream, same dimension order), so one light path per pixel per
//!   sample index; its camera connections splat, normalised by the number of light paths.
//! - Light-subpath vertices use Veach's adjoint shading-normal factor, as the light tracer
//!   does. The layered material's coat weights depend on the outgoing direction only (not
//!   reciprocal); light vertices evaluate it with `wo` towards the light, so on coated materials
//!   light strategies estimate the adjoint and the MIS blend differs slightly from the path
//!   tracer's image. Diffuse, glossy and mirror layers are reciprocal; refraction is up to
//!   `η²`, which light vertices leave out (`rt_core::material::Bsdf::adjoint`; with radiance's
//!   `1/η²` there, light through an open sheet of rough glass came out `η²` off).
//! - The camera strategy `t = 0` (a light path hitting the lens) and `s = 1, t = 1` (a light
//!   point connected to the camera) are not used, as in pbrt: camera rays that hit a light cover
//!   those paths.
//! - Dispersion (§6.6): each subpath draws its own wavelength at its first dispersive event and
//!   keeps it. A connection joining two subpaths that both did combines two independent
//!   wavelengths, so such doubly dispersed paths keep their energy but not their exact colour;
//!   paths dispersed on one side only are exact.

mod vertex;

use crate::driver::{RenderStats, SamplePass};
use crate::technique::Technique;
use crate::transport::{adjoint_cos, importance_weight, light_visible, survives_roulette};
use crate::work;
use crate::{Ctx, RayCounters};
use rayon::prelude::*;
use rt_core::{
    delta_light::DeltaLight,
    emission::plane_area,
    glam::{Vec2, Vec3},
    material::Bsdf,
    ray::{shadow_segment, spawn_ray},
    Ray, Rgb, Sampler,
};
use rt_film::{Film, Splat};
use std::time::Instant;
use vertex::{direction, to_area, Densities, Kind, Vertex};

/// Pixels per work item.
const CHUNK_PIXELS: u32 = 1024;

/// Work items rendered between two merges into the film (bounds the splats in flight).
const BATCH_ITEMS: usize = 64;

/// Bidirectional path tracing.
#[derive(Clone, Debug)]
pub struct Bdpt {
    /// Maximum number of bounces (scattering vertices), as for the path tracer.
    pub max_depth: u32,
    /// Bounce after which Russian roulette may end subpaths.
    pub rr_depth: u32,
}

impl Bdpt {
    /// Bidirectional path tracing allowing `max_depth` bounces.
    pub fn new(max_depth: u32) -> Self {
        Self {
            max_depth,
            rr_depth: 3,
        }
    }
}

/// What one work item produced, merged into the film in item order.
#[derive(Default)]
struct ItemOutput {
    radiance: Vec<Rgb>,
    splats: Vec<Splat>,
    counters: RayCounters,
}

impl Technique for Bdpt {
    fn name(&self) -> &str {
        "bdpt"
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
        let (w, h) = (film.width(), film.height());
        let pixels = w.saturating_mul(h);
        let items = work::items(pass.indices.clone(), pixels, CHUNK_PIXELS);
        let mut outputs: Vec<ItemOutput> = (0..BATCH_ITEMS.min(items.len()))
            .map(|_| ItemOutput::default())
            .collect();
        let dens = Densities {
            scene: ctx.scene,
            lights: ctx.scene.lights(),
            camera: ctx.camera,
            bounds: ctx.accel.bounds(),
        };
        let mut rays = RayCounters::default();
        for (b, batch) in items.chunks(BATCH_ITEMS).enumerate() {
            outputs[..batch.len()]
                .par_iter_mut()
                .zip(batch.par_iter())
                .for_each(|(out, item)| {
                    out.radiance.clear();
                    out.splats.clear();
                    out.counters = RayCounters::default();
                    let cap = (self.max_depth as usize + 2).min(64);
                    let mut paths = Subpaths {
                        camera: Vec::with_capacity(cap),
                        light: Vec::with_capacity(cap),
                    };
                    let mut cam_sampler = Sampler::with_stream(seed, pass.stream);
                    let mut light_sampler = Sampler::with_stream(seed, pass.stream);
                    for k in item.first..item.first + item.count {
                        cam_sampler.start(k % w, k / w, item.index);
                        light_sampler.start_light_path(k, item.index);
                        let l = self.sample(
                            ctx,
                            &dens,
                            &mut cam_sampler,
                            &mut light_sampler,
                            &mut paths,
                            out,
                            (k % w, k / w),
                        );
                        out.radiance.push(l);
                    }
                });
            for (item, out) in batch.iter().zip(&outputs) {
                for (k, l) in (item.first..).zip(&out.radiance) {
                    film.add_sample(k % w, k / w, item.index, *l, None);
                }
                film.add_splats(item.index, u64::from(item.count), &out.splats);
                rays += out.counters;
            }
            progress(work::rows_done(
                b * BATCH_ITEMS + batch.len(),
                items.len(),
                h,
            ));
        }
        RenderStats {
            elapsed: start.elapsed(),
            samples: u64::from(pixels) * pass.indices.len() as u64,
            rays,
            discarded: film.discarded() - discarded_before,
        }
    }
}

/// The two subpaths of one sample, reused from sample to sample.
struct Subpaths<'a> {
    camera: Vec<Vertex<'a>>,
    light: Vec<Vertex<'a>>,
}

/// Which way a subpath carries light.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Transport {
    Radiance,
    Importance,
}

impl Bdpt {
    /// One sample of pixel `(x, y)`: both subpaths, every strategy. Returns the camera-side
    /// estimate; light-tracing connections go to `out.splats`.
    #[allow(clippy::too_many_arguments)]
    fn sample<'a>(
        &self,
        ctx: &Ctx<'a>,
        dens: &Densities<'_>,
        cam_sampler: &mut Sampler,
        light_sampler: &mut Sampler,
        paths: &mut Subpaths<'a>,
        out: &mut ItemOutput,
        (x, y): (u32, u32),
    ) -> Rgb {
        let camera = ctx.camera;
        let thin_lens = !camera.is_pinhole();
        // The camera-ray driver's first dimensions: film position, then the lens.
        let film_pos = camera.filter.film_position(x, y, cam_sampler.next_2d());
        let lens = if thin_lens {
            cam_sampler.next_2d()
        } else {
            Vec2::ZERO
        };
        let ray = camera.generate_ray(film_pos, lens);
        paths.camera.clear();
        paths.camera.push(Vertex::endpoint(
            Kind::Camera,
            camera.lens_point(lens),
            Rgb::ONE,
            0.0,
        ));
        let pdf_dir = camera.pdf_direction(ray.dir);
        self.walk(
            ctx,
            ray,
            Rgb::ONE,
            pdf_dir,
            self.max_depth as usize + 1,
            Transport::Radiance,
            cam_sampler,
            &mut paths.camera,
            &mut out.counters,
        );
        self.light_subpath(
            ctx,
            dens,
            light_sampler,
            &mut paths.light,
            &mut out.counters,
        );

        let (cam, light) = (&paths.camera, &paths.light);
        let mut l = Rgb::ZERO;
        for t in 1..=cam.len() {
            for s in 0..=light.len() {
                let depth = s + t;
                if (s == 1 && t == 1) || depth < 2 || depth - 2 > self.max_depth as usize {
                    continue;
                }
                if t == 1 {
                    if let Some(splat) = self.connect_camera(ctx, dens, cam, light, s, out) {
                        out.splats.push(splat);
                    }
                } else {
                    l += self.connect(ctx, dens, cam, light, s, t, &mut out.counters);
                }
            }
        }
        l
    }

    /// The light subpath: an emitter point or a plane-sampled environment start, then a walk.
    fn light_subpath<'a>(
        &self,
        ctx: &Ctx<'a>,
        dens: &Densities<'_>,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex<'a>>,
        counters: &mut RayCounters,
    ) {
        path.clear();
        let scene = ctx.scene;
        let thin_lens = !ctx.camera.is_pinhole();
        // The light tracer's dimension order: selection, position, direction, lens.
        let u_sel = sampler.next_1d();
        let u_pos = sampler.next_2d();
        let u_dir = sampler.next_2d();
        let u_lens = if thin_lens {
            sampler.next_2d()
        } else {
            Vec2::ZERO
        };
        let Some(e) = dens
            .lights
            .sample_emission(scene, &dens.bounds, u_sel, u_pos, u_dir)
        else {
            return;
        };
        // The start, and the next vertex's density: the direction's for a point (converted to
        // area at the hit), the plane point's for the environment and a directional light
        // (`Densities::pdf_light`).
        let (start, pdf_next) = match (e.point, e.delta_light) {
            (Some(pt), _) => {
                let mut v = Vertex::endpoint(Kind::Light, pt.point, Rgb::ONE, e.pdf_position);
                v.p_error = pt.error;
                v.ng = pt.normal;
                v.ns = pt.normal;
                v.emission = pt.emission;
                v.two_sided = pt.two_sided;
                v.u_connect = [u_lens.x, u_lens.y, 0.0];
                (v, e.pdf_direction)
            }
            // A directional light: a delta direction (density 0, which MIS reads as "no other
            // strategy"); the plane point's density without the light's choice, as the
            // environment's.
            (None, Some(light @ DeltaLight::Directional { .. })) => {
                let mut v = Vertex::endpoint(Kind::Env, -e.dir, Rgb::ONE, 0.0);
                v.delta_light = Some(light);
                let area = plane_area(&dens.bounds, e.dir);
                (v, if area > 0.0 { 1.0 / area } else { 0.0 })
            }
            // A point or spot light: a delta position, chosen with `pdf_position`.
            (None, Some(light)) => {
                let mut v = Vertex::endpoint(Kind::Light, e.origin, Rgb::ONE, e.pdf_position);
                v.delta_light = Some(light);
                (v, e.pdf_direction)
            }
            // At infinity: the vertex's density is the direction's (solid angle).
            (None, None) => (
                Vertex::endpoint(Kind::Env, -e.dir, Rgb::ONE, e.pdf_direction),
                e.pdf_position,
            ),
        };
        path.push(start);
        let ray = e.ray();
        self.walk(
            ctx,
            ray,
            e.beta,
            pdf_next,
            self.max_depth as usize,
            Transport::Importance,
            sampler,
            path,
            counters,
        );
    }

    /// Extends `path` (which holds its start vertex) by a random walk of at most `max_vertices`
    /// more vertices, recording forward and reverse densities as pbrt's `RandomWalk` does.
    /// `pdf` is the density of the first ray's direction (for a walk from the environment, the
    /// plane point's density, which converts to area by the cosine alone).
    #[allow(clippy::too_many_arguments)]
    fn walk<'a>(
        &self,
        ctx: &Ctx<'a>,
        mut ray: Ray,
        mut beta: Rgb,
        mut pdf: f32,
        max_vertices: usize,
        mode: Transport,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex<'a>>,
        counters: &mut RayCounters,
    ) {
        let scene = ctx.scene;
        let thin_lens = !ctx.camera.is_pinhole();
        let mut bounces = 0usize;
        let start = beta.max_element();
        // The subpath's wavelength once a dispersive event has drawn one (§6.6).
        let mut lambda: Option<f32> = None;
        while bounces < max_vertices {
            counters.rays += 1;
            let prev = path.len() - 1;
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                if mode == Transport::Radiance && !scene.environment.is_black() {
                    // The environment as the camera subpath's last vertex (strategy s = 0);
                    // its density stays the direction's.
                    path.push(Vertex::endpoint(Kind::Env, ray.dir, beta, pdf));
                }
                break;
            };
            let si = scene.surface(&hit, 0.0);
            let material = &scene.materials[si.material as usize];
            let wo = -ray.dir;
            let tint = scene.tint(material, si.uv);
            let mut v = Vertex::endpoint(Kind::Surface, si.p, beta, 0.0);
            v.p_error = si.p_error;
            v.ng = si.ng;
            v.ns = si.ns;
            v.wo = wo;
            v.material = Some(material);
            v.tint = tint;
            v.prim = si.prim;
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo).with_wavelength(lambda);
            // A light subpath carries importance: refraction without radiance's `1/η²`.
            v.bsdf = Some(match mode {
                Transport::Radiance => bsdf,
                Transport::Importance => bsdf.adjoint(),
            });
            v.pdf_fwd = if path[prev].kind == Kind::Env {
                // Plane sampling: uniform over the plane perpendicular to the ray.
                pdf * si.ng.dot(wo).abs()
            } else {
                to_area(pdf, &path[prev], &v)
            };
            // Fixed dimensions per vertex, used or not.
            v.u_connect = match mode {
                Transport::Radiance => {
                    let u_sel = sampler.next_1d();
                    let u = sampler.next_2d();
                    [u_sel, u.x, u.y]
                }
                Transport::Importance => {
                    let u = if thin_lens {
                        sampler.next_2d()
                    } else {
                        Vec2::ZERO
                    };
                    [u.x, u.y, 0.0]
                }
            };
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            path.push(v);
            bounces += 1;
            if bounces >= max_vertices {
                break;
            }
            let cur = path.len() - 1;
            let Some(s) = path[cur]
                .bsdf
                .as_ref()
                .and_then(|b| b.sample(u_layer, u_bsdf))
            else {
                break;
            };
            let (pdf_fwd, pdf_rev) = if s.delta {
                (0.0, 0.0)
            } else {
                (s.pdf, path[cur].bsdf_pdf(Some(s.wi), wo))
            };
            beta *= match mode {
                Transport::Radiance => s.weight,
                Transport::Importance => importance_weight(&s, wo, si.ns, si.ng),
            };
            path[cur].delta = s.delta;
            lambda = s.wavelength;
            let rev = to_area(pdf_rev, &path[cur], &path[prev]);
            path[prev].pdf_rev = rev;
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            if bounces > self.rr_depth as usize && !survives_roulette(&mut beta, start, u_rr) {
                break;
            }
            pdf = pdf_fwd;
            ray = spawn_ray(si.p, si.p_error, si.ng, s.wi);
        }
    }

    /// Strategy `(s, t)` with `t ≥ 2`: the camera-side contribution, MIS-weighted.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &self,
        ctx: &Ctx<'_>,
        dens: &Densities<'_>,
        cam: &[Vertex],
        light: &[Vertex],
        s: usize,
        t: usize,
        counters: &mut RayCounters,
    ) -> Rgb {
        let scene = ctx.scene;
        let pt = &cam[t - 1];
        let ptm = &cam[t - 2];
        if s == 0 {
            // The camera subpath found a light.
            if !(pt.kind == Kind::Env || pt.emits()) {
                return Rgb::ZERO;
            }
            let le = pt.le(scene, pt.wo);
            if le.max_element() <= 0.0 {
                return Rgb::ZERO;
            }
            let ov = Overrides {
                pt_rev: dens.pdf_light_origin(pt),
                ptm_rev: dens.pdf_light(pt, ptm),
                ..Overrides::default()
            };
            return pt.beta * le * mis_weight(cam, light, s, t, &ov);
        }
        if pt.kind != Kind::Surface || !pt.connectible() {
            return Rgb::ZERO;
        }
        let pt_bsdf = pt.bsdf.as_ref().expect("surface vertices have a BSDF");
        if s == 1 {
            return self.next_event(ctx, dens, cam, light, t, counters);
        }
        let qs = &light[s - 1];
        let qsm = &light[s - 2];
        if !qs.connectible() {
            return Rgb::ZERO;
        }
        let qs_bsdf = qs.bsdf.as_ref().expect("surface vertices have a BSDF");
        let (w, d2) = direction(pt, qs);
        let f_pt = pt_bsdf.eval(w);
        let f_qs = qs_bsdf.eval(-w);
        let g = w.dot(pt.ns).abs() * adjoint_cos(qs.wo, -w, qs.ns, qs.ng) / d2;
        let value = pt.beta * f_pt * qs.beta * f_qs * g;
        if value.max_element() <= 0.0 || !value.is_finite() {
            return Rgb::ZERO;
        }
        counters.shadow_rays += 1;
        let (r, t_max) = shadow_segment(pt.p, pt.p_error, pt.ng, qs.p, qs.p_error, qs.ng);
        if ctx.accel.occluded(&r, t_max) {
            return Rgb::ZERO;
        }
        let ov = Overrides {
            pt_rev: dens.pdf(qs, None, pt),
            ptm_rev: dens.pdf(pt, Some(w), ptm),
            qs_rev: dens.pdf(pt, None, qs),
            qsm_rev: dens.pdf(qs, Some(-w), qsm),
            qs_fwd: None,
            qs_delta_light: false,
        };
        value * mis_weight(cam, light, s, t, &ov)
    }

    /// Strategy `s = 1`: a fresh light sample from camera vertex `t - 1`, as the path tracer's
    /// next-event estimation, weighted against every other strategy.
    fn next_event(
        &self,
        ctx: &Ctx<'_>,
        dens: &Densities<'_>,
        cam: &[Vertex],
        light: &[Vertex],
        t: usize,
        counters: &mut RayCounters,
    ) -> Rgb {
        let pt = &cam[t - 1];
        let ptm = &cam[t - 2];
        let bsdf = pt.bsdf.as_ref().expect("surface vertices have a BSDF");
        let [u_sel, u0, u1] = pt.u_connect;
        let Some(ls) = dens
            .lights
            .sample(ctx.scene, pt.p, u_sel, Vec2::new(u0, u1))
        else {
            return Rgb::ZERO;
        };
        let (f, bsdf_pdf) = bsdf.eval_pdf(ls.wi);
        let value = pt.beta * f * ls.le * (ls.wi.dot(pt.ns).abs() / ls.pdf);
        if value.max_element() <= 0.0 || !value.is_finite() {
            return Rgb::ZERO;
        }
        counters.shadow_rays += 1;
        if !light_visible(ctx, pt.p, pt.p_error, pt.ng, 0.0, &ls) {
            return Rgb::ZERO;
        }
        // The sampled light as a vertex, for the densities of the other strategies. A delta
        // light's is only its choice; BSDF sampling cannot reach it.
        let q = if ls.delta {
            let (kind, p) = if ls.dist.is_infinite() {
                (Kind::Env, ls.wi)
            } else {
                (Kind::Light, ls.point)
            };
            let mut q = Vertex::endpoint(kind, p, Rgb::ONE, ls.pdf);
            q.delta_light = dens.lights.chosen_delta(u_sel).copied();
            q
        } else if ls.dist.is_infinite() {
            Vertex::endpoint(Kind::Env, ls.wi, Rgb::ONE, ls.pdf)
        } else {
            let cos_l = ls.normal.dot(ls.wi).abs();
            let mut q = Vertex::endpoint(
                Kind::Light,
                ls.point,
                Rgb::ONE,
                ls.pdf * cos_l / (ls.dist * ls.dist),
            );
            q.ng = ls.normal;
            q.two_sided = ls.two_sided;
            q
        };
        let ov = Overrides {
            pt_rev: dens.pdf_light(&q, pt),
            ptm_rev: dens.pdf(pt, Some(ls.wi), ptm),
            qs_rev: if ls.delta {
                0.0
            } else {
                to_area(bsdf_pdf, pt, &q)
            },
            qsm_rev: 0.0,
            qs_fwd: Some(q.pdf_fwd),
            qs_delta_light: ls.delta,
        };
        value * mis_weight(cam, light, 1, t, &ov)
    }

    /// Strategy `t = 1`: light vertex `s - 1` connected to the camera through its lens sample,
    /// as a splat.
    fn connect_camera(
        &self,
        ctx: &Ctx<'_>,
        dens: &Densities<'_>,
        cam: &[Vertex],
        light: &[Vertex],
        s: usize,
        out: &mut ItemOutput,
    ) -> Option<Splat> {
        let qs = &light[s - 1];
        let qsm = &light[s - 2];
        if !qs.connectible() {
            return None;
        }
        let camera = ctx.camera;
        let c = camera.connect(qs.p, Vec2::new(qs.u_connect[0], qs.u_connect[1]))?;
        let f = qs.bsdf.as_ref()?.eval(c.wi);
        let value = qs.beta * f * (adjoint_cos(qs.wo, c.wi, qs.ns, qs.ng) * c.importance);
        if value.max_element() <= 0.0 || !value.is_finite() {
            return None;
        }
        out.counters.shadow_rays += 1;
        let (r, t_max) = shadow_segment(qs.p, qs.p_error, qs.ng, c.near_point, Vec3::ZERO, c.wi);
        if ctx.accel.occluded(&r, t_max) {
            return None;
        }
        let lens = Vertex::endpoint(Kind::Camera, c.lens_point, Rgb::ONE, 0.0);
        let ov = Overrides {
            qs_rev: dens.pdf(&lens, None, qs),
            qsm_rev: dens.pdf(qs, Some(c.wi), qsm),
            ..Overrides::default()
        };
        let value = value * mis_weight(cam, light, s, 1, &ov);
        let x = (c.raster.x as u32).min(camera.width - 1);
        let y = (c.raster.y as u32).min(camera.height - 1);
        Some(Splat {
            pixel: y * camera.width + x,
            value,
        })
    }
}

/// The reverse densities of the vertices next to a connection, which depend on the strategy
/// (pbrt's `ScopedAssignment`s in `MISWeight`), and for `s = 1` the sampled light's own
/// forward density.
#[derive(Default)]
struct Overrides {
    /// Reverse density of camera vertex `t - 1`.
    pt_rev: f32,
    /// Of camera vertex `t - 2`.
    ptm_rev: f32,
    /// Of light vertex `s - 1`.
    qs_rev: f32,
    /// Of light vertex `s - 2`.
    qsm_rev: f32,
    /// For `s = 1`: the forward density of the sampled light vertex.
    qs_fwd: Option<f32>,
    /// For `s = 1`: the sampled light is a delta light (no strategy with `s = 0` finds it).
    qs_delta_light: bool,
}

/// The power-heuristic weight of strategy `(s, t)` for its path: `1 / Σ_i (p_i / p_s)²` over
/// the strategies that could have sampled it, computed from ratios of reverse to forward
/// densities along the path (Veach 1997, §10.2). A zero density (a delta bounce) counts as one,
/// and strategies connecting at a delta vertex are left out.
fn mis_weight(cam: &[Vertex], light: &[Vertex], s: usize, t: usize, ov: &Overrides) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
    let mut sum = 0.0f32;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        let rev = if i == t - 1 {
            ov.pt_rev
        } else if i + 2 == t {
            ov.ptm_rev
        } else {
            cam[i].pdf_rev
        };
        let r = remap(rev) / remap(cam[i].pdf_fwd);
        ri *= r * r;
        let delta_here = i != t - 1 && cam[i].delta;
        if !delta_here && !cam[i - 1].delta {
            sum += ri;
        }
    }
    ri = 1.0;
    for i in (0..s).rev() {
        let rev = if i == s - 1 {
            ov.qs_rev
        } else if i + 2 == s {
            ov.qsm_rev
        } else {
            light[i].pdf_rev
        };
        let fwd = match ov.qs_fwd {
            Some(f) if i == 0 => f,
            _ => light[i].pdf_fwd,
        };
        let r = remap(rev) / remap(fwd);
        ri *= r * r;
        let delta_here = i != s - 1 && light[i].delta;
        // Before the light's own vertex: whether the light is a delta light, which the camera
        // subpath (strategy s = 0) cannot hit.
        let delta_before = if i > 0 {
            light[i - 1].delta
        } else if ov.qs_fwd.is_some() {
            ov.qs_delta_light
        } else {
            light[0].delta_light.is_some()
        };
        if !delta_here && !delta_before {
            sum += ri;
        }
    }
    let w = 1.0 / (1.0 + sum);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}
