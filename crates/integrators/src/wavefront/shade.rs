//! One path vertex of the wavefront tracer: what the scalar path tracer does between two ray
//! queries, with the queries taken out. The arithmetic is [`crate::PathIntegrator::li`]'s,
//! step for step and in the same order, so a sample gives the same bits in both.

use super::lanes::{PathState, PendingShadow, VertexDraws};
use crate::transport::{emission_weight, shadow_query, survives_roulette, ShadowQuery};
use crate::{Ctx, PathIntegrator};
use rt_core::lights::LightSampler;
use rt_core::material::Bsdf;
use rt_core::sampling::power_heuristic;
use rt_core::Hit;

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
    /// marks the path done.
    #[inline]
    pub fn vertex(
        &self,
        path: &mut PathState,
        hit: Option<Hit>,
        u: &VertexDraws,
        lane: u32,
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
                    let w = power_heuristic(ls.pdf, bsdf_pdf);
                    let contribution = path.beta * f * ls.le * (cos * w / ls.pdf);
                    let query = shadow_query(si.p, si.p_error, si.ng, si.time, &ls);
                    shadow = Some((query, PendingShadow { lane, contribution }));
                }
            }
        }

        let Some(s) = bsdf.sample(u.layer, u.bsdf) else {
            path.done = true;
            return shadow;
        };
        path.beta *= s.weight;
        if path.beta.max_element() <= 0.0 || !path.beta.is_finite() {
            path.done = true;
            return shadow;
        }
        path.lambda = s.wavelength;
        path.prev_delta = s.delta;
        path.prev_pdf = s.pdf;
        path.prev_p = si.p;
        path.ray = si.spawn_ray(s.wi);
        path.depth += 1;
        if path.depth > self.settings.rr_depth && !survives_roulette(&mut path.beta, 1.0, u.rr) {
            path.done = true;
        }
        shadow
    }
}
