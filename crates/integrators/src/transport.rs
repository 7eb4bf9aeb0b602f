//! Steps every path-building technique here takes the same way: importance transport's
//! shading-normal factor, Russian roulette, and the shadow test of a light sample.

use crate::Ctx;
use rt_core::{
    glam::Vec3,
    lights::LightSample,
    material::BsdfSample,
    ray::{shadow_segment, spawn_ray},
    Rgb,
};

/// The cosine factor of importance transport with shading normals (Veach 1997, eq. 5.17):
/// `|wo·ns| |wi·ng| / |wo·ng|` in place of the radiance transport's `|wi·ns|`, where `wo`
/// points to the light side and `wi` onward (to the camera for a connection). Equal to
/// `|wi·n|` when the normals agree.
#[inline]
pub(crate) fn adjoint_cos(wo: Vec3, wi: Vec3, ns: Vec3, ng: Vec3) -> f32 {
    let wo_ng = wo.dot(ng).abs();
    if wo_ng <= 0.0 {
        return 0.0;
    }
    wo.dot(ns).abs() * wi.dot(ng).abs() / wo_ng
}

/// The throughput factor of BSDF sample `s` on a path from the lights: the sample's weight
/// (which holds `|wi·ns|`) with the adjoint cosine in its place.
#[inline]
pub(crate) fn importance_weight(s: &BsdfSample, wo: Vec3, ns: Vec3, ng: Vec3) -> Rgb {
    let cos_ns = s.wi.dot(ns).abs();
    let correction = if cos_ns > 0.0 {
        adjoint_cos(wo, s.wi, ns, ng) / cos_ns
    } else {
        0.0
    };
    s.weight * correction
}

/// Russian roulette on throughput `beta` with random number `u`: continues with probability
/// tied to the throughput relative to `start`, the largest channel of the path's weight where
/// it began (1 for camera paths; a light path's `Le / pdf`, a photon's `Φ / N`), so surviving
/// paths carry comparable weights, capped so bright paths still end. Returns false if the path
/// ends; a survivor's `beta` is divided by the probability.
///
/// Relative, not absolute: a caustic photon carries `Φ / N` (10⁻³ on `scenes/caustic.toml`),
/// and roulette on that killed 999 photons in 1000 and gave the survivor a thousandfold weight,
/// one pixel of 1600 in one pass.
#[inline]
pub(crate) fn survives_roulette(beta: &mut Rgb, start: f32, u: f32) -> bool {
    let q = (beta.max_element() / start).min(0.95);
    if q.is_nan() {
        return false;
    }
    if u >= q {
        return false;
    }
    *beta /= q;
    true
}

/// True if light sample `ls` is unoccluded from surface point `p` (error bound `p_error`,
/// geometric normal `ng`) at shutter time `time`: a ray to infinity for the environment, else
/// a segment to the light point (which keys the shadow cache of structures that have one).
pub(crate) fn light_visible(
    ctx: &Ctx<'_>,
    p: Vec3,
    p_error: Vec3,
    ng: Vec3,
    time: f32,
    ls: &LightSample,
) -> bool {
    let q = shadow_query(p, p_error, ng, time, ls);
    match q.toward {
        Some(target) => !ctx.accel.occluded_toward(&q.ray, q.t_max, target),
        None => !ctx.accel.occluded(&q.ray, q.t_max),
    }
}

/// The shadow ray [`light_visible`] traces: the ray, its extent, and the light-side point it
/// aims at (`None` for the environment).
pub(crate) struct ShadowQuery {
    pub ray: rt_core::Ray,
    pub t_max: f32,
    pub toward: Option<Vec3>,
}

/// The shadow ray of light sample `ls` from surface point `p` (see [`light_visible`]).
#[inline]
pub(crate) fn shadow_query(
    p: Vec3,
    p_error: Vec3,
    ng: Vec3,
    time: f32,
    ls: &LightSample,
) -> ShadowQuery {
    if ls.dist.is_infinite() {
        ShadowQuery {
            ray: spawn_ray(p, p_error, ng, ls.wi).at_time(time),
            t_max: f32::INFINITY,
            toward: None,
        }
    } else {
        let (r, t_max) = shadow_segment(p, p_error, ng, ls.point, ls.point_error, ls.normal);
        ShadowQuery {
            ray: r.at_time(time),
            t_max,
            toward: Some(ls.point),
        }
    }
}

/// MIS weight of emission found by BSDF sampling: 1 after a delta bounce or without light
/// sampling, else the power heuristic of the BSDF pdf `prev_pdf` against light sampling's pdf
/// for the same point (`light_pdf`, only evaluated when needed).
#[inline]
pub(crate) fn emission_weight(
    prev_delta: bool,
    use_nee: bool,
    prev_pdf: f32,
    light_pdf: impl FnOnce() -> f32,
) -> f32 {
    if prev_delta || !use_nee {
        1.0
    } else {
        rt_core::sampling::power_heuristic(prev_pdf, light_pdf())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roulette_is_relative_to_the_starting_weight() {
        // A photon of power 1e-3 that lost nothing survives as often as a camera path of 1.
        let survivals = |start: f32| {
            (0..1000)
                .filter(|i| {
                    let mut b = Rgb::splat(start);
                    survives_roulette(&mut b, start, (*i as f32 + 0.5) / 1000.0)
                })
                .count()
        };
        assert_eq!(survivals(1e-3), survivals(1.0));
        assert_eq!(survivals(1.0), 950);
        // And the survivor's weight grows by 1/0.95, not by 1/q of the absolute weight.
        let mut b = Rgb::splat(1e-3);
        assert!(survives_roulette(&mut b, 1e-3, 0.5));
        assert!((b.x - 1e-3 / 0.95).abs() < 1e-9);
    }
}
