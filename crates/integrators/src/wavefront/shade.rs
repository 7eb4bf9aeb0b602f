//! One path vertex of the wavefront tracer: what the scalar path tracer does between two ray
//! queries, with the queries taken out. The arithmetic is [`crate::PathIntegrator::li`]'s,
//! step for step and in the same order, so a sample gives the same bits in both.

use super::lambert::{LambertQueue, LambertResult};
use super::lanes::{PathState, PendingShadow, VertexDraws};
use crate::transport::{emission_weight, shadow_query, survives_roulette, ShadowQuery};
use crate::{Ctx, PathIntegrator};
use rt_core::glam::Vec3;
use rt_core::lights::{LightSample, LightSampler};
use rt_core::material::Bsdf;
use rt_core::scene::SurfaceHit;
use rt_core::{Hit, Rgb};

/// What shading needs besides the lane: the estimator's settings and the scene's lights.
pub(crate) struct Shader<'a> {
    pub ctx: Ctx<'a>,
    pub settings: &'a PathIntegrator,
    pub lights: &'a LightSampler,
    pub use_nee: bool,
    pub want_first_hit: bool,
}

impl Shader<'_> {
    /// Shades `path` at `hit` (the result of tracing `path.ray`): adds emission, may request
    /// a shadow ray (returned with the radiance it carries), samples the next direction or
    /// marks the path done. A plain Lambertian vertex stops after its light sample and goes
    /// to `queue` for the vectorised BSDF stage instead ([`Shader::finish_lambert`]).
    #[inline]
    pub fn vertex(
        &self,
        path: &mut PathState,
        hit: Option<Hit>,
        u: &VertexDraws,
        lane: u32,
        queue: &mut LambertQueue,
    ) -> Option<(ShadowQuery, PendingShadow)> {
        let scene = self.ctx.scene;
        let lights = self.lights;
        let ray = path.ray;
        let Some(hit) = hit else {
            let le = scene.environment.radiance(ray.dir);
            if le.max_element() > 0.0 {
                let w = emission_weight(path.prev_delta, self.use_nee, path.prev_pdf, || {
                    lights.pdf_env(scene, ray.dir)
                });
                path.l += path.beta * le * w;
            }
            path.done = true;
            return None;
        };
        let si = scene.surface(&hit, ray.time);
        let material = &scene.materials[si.material as usize];
        let wo = -ray.dir;
        let le = material.emitted(si.ng, wo);
        if le.max_element() > 0.0 {
            let w = emission_weight(path.prev_delta, self.use_nee, path.prev_pdf, || {
                lights.pdf_triangle(scene, si.prim, path.prev_p, si.p, si.ng)
            });
            path.l += path.beta * le * w;
        }
        let max_depth = self.settings.max_depth;
        let first_hit_wanted = path.depth == 0 && self.want_first_hit;
        if path.depth >= max_depth && !first_hit_wanted {
            path.done = true;
            return None;
        }
        if !first_hit_wanted {
            if let Some(f) = material.plain_lambert(scene.texture_color(material, si.uv)) {
                // The BSDF stage runs for all such vertices at once (`LambertQueue::run`);
                // `finish_lambert` takes the path on from its result.
                let light = if self.use_nee {
                    lights.sample(scene, si.p, u.light_sel, u.light)
                } else {
                    None
                };
                queue.push(lane, &si, wo, f, path.beta, light, u.bsdf);
                return None;
            }
        }
        let tint = scene.tint(material, si.uv);
        let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo).with_wavelength(path.lambda);
        let bsdf = if self.settings.spectral {
            bsdf
        } else {
            bsdf.without_dispersion()
        };
        if first_hit_wanted {
            path.first_hit = Some(crate::first_hit(&bsdf, &si, wo, hit.t * ray.dir.length()));
        }
        if path.depth >= max_depth {
            path.done = true;
            return None;
        }

        let mut shadow = None;
        if self.use_nee && bsdf.has_non_delta() {
            if let Some(ls) = lights.sample(scene, si.p, u.light_sel, u.light) {
                let (f, bsdf_pdf) = bsdf.eval_pdf(ls.wi);
                let cos = ls.wi.dot(si.ns).abs();
                if f.max_element() > 0.0 && cos > 0.0 {
                    let w = ls.mis_weight(bsdf_pdf);
                    let contribution = path.beta * f * ls.le * (cos * w / ls.pdf);
                    let query = shadow_query(si.p, si.p_error, si.ng, si.time, &ls);
                    shadow = Some((query, PendingShadow { lane, contribution }));
                }
            }
        }

        match bsdf.sample(u.layer, u.bsdf) {
            Some(s) => {
                path.lambda = s.wavelength;
                self.advance(path, &si, s.wi, s.weight, s.pdf, s.delta, u.rr);
            }
            None => path.done = true,
        }
        shadow
    }

    /// Takes a queued Lambertian vertex on from the BSDF stage's result `r`: the shadow ray
    /// its light sample asks for, and the next direction or the path's end. As `vertex` does
    /// after its BSDF sample.
    pub fn finish_lambert(
        &self,
        path: &mut PathState,
        si: &SurfaceHit,
        light: Option<&LightSample>,
        r: &LambertResult,
        u_rr: f32,
        lane: u32,
    ) -> Option<(ShadowQuery, PendingShadow)> {
        let shadow = match (r.contribution, light) {
            (Some(contribution), Some(ls)) => Some((
                shadow_query(si.p, si.p_error, si.ng, si.time, ls),
                PendingShadow { lane, contribution },
            )),
            _ => None,
        };
        match r.sample {
            Some((wi, weight, pdf)) => self.advance(path, si, wi, weight, pdf, false, u_rr),
            None => path.done = true,
        }
        shadow
    }

    /// The path after a BSDF sample at `si` (direction `wi`, weight `f·|cos|/pdf`, `pdf`):
    /// throughput, MIS state, the next ray, Russian roulette.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn advance(
        &self,
        path: &mut PathState,
        si: &SurfaceHit,
        wi: Vec3,
        weight: Rgb,
        pdf: f32,
        delta: bool,
        u_rr: f32,
    ) {
        path.beta *= weight;
        if path.beta.max_element() <= 0.0 || !path.beta.is_finite() {
            path.done = true;
            return;
        }
        path.prev_delta = delta;
        path.prev_pdf = pdf;
        path.prev_p = si.p;
        path.ray = si.spawn_ray(wi);
        path.depth += 1;
        if path.depth > self.settings.rr_depth && !survives_roulette(&mut path.beta, 1.0, u_rr) {
            path.done = true;
        }
    }
}
