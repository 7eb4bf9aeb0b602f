//! Ambient occlusion: the fraction of the cosine-weighted hemisphere above the first visible
//! surface that is open up to a distance. Equivalently, the image of a white Lambertian scene
//! under a uniform white sky with one bounce and no emitters; camera rays that miss see the sky
//! (value 1).

use crate::{Ctx, Integrator, RayCounters, SampleAux};
use rt_core::{frame::Frame, sampling::cosine_hemisphere, Ray, Rgb, Sampler};
use rt_film::FirstHit;

/// Ambient-occlusion estimator.
#[derive(Clone, Debug)]
pub struct AoIntegrator {
    /// Occluders farther than this do not count (`f32::INFINITY` for all).
    pub max_distance: f32,
}

impl Integrator for AoIntegrator {
    fn name(&self) -> &str {
        "ao"
    }

    fn li(
        &self,
        ctx: &Ctx<'_>,
        ray: Ray,
        sampler: &mut Sampler,
        aux: &mut SampleAux,
        counters: &mut RayCounters,
    ) -> Rgb {
        counters.rays += 1;
        let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
            return Rgb::ONE;
        };
        let si = ctx.scene.surface(&hit, ray.time);
        let wo = -ray.dir;
        let flip = if si.ng.dot(wo) < 0.0 { -1.0 } else { 1.0 };
        let (ng, ns) = (si.ng * flip, si.ns * flip);
        if aux.want_first_hit {
            aux.first_hit = Some(FirstHit {
                albedo: Rgb::ONE,
                normal: ns,
                depth: hit.t * ray.dir.length(),
                position: si.p,
            });
        }
        let d = Frame::from_normal(ns).to_world(cosine_hemisphere(sampler.next_2d()));
        if d.dot(ng) <= 0.0 {
            return Rgb::ZERO;
        }
        counters.shadow_rays += 1;
        let r = si.spawn_ray(d);
        if ctx.accel.occluded(&r, self.max_distance) {
            Rgb::ZERO
        } else {
            Rgb::ONE
        }
    }
}

/// Ambient occlusion through a world-space cache, as Delaere's thesis caches it: every sample
/// records its one-ray AO at the first hit, and the pixel gets the cache's reconstruction
/// there (from earlier passes; the raw sample where the cache has nothing yet). Render through
/// [`crate::CachedPasses`].
pub struct CachedAo {
    /// The estimator whose samples are cached.
    pub ao: AoIntegrator,
    /// The cache.
    pub cache: crate::CacheRef,
}

impl Integrator for CachedAo {
    fn name(&self) -> &str {
        "ao"
    }

    fn li(
        &self,
        ctx: &Ctx<'_>,
        ray: Ray,
        sampler: &mut Sampler,
        aux: &mut SampleAux,
        counters: &mut RayCounters,
    ) -> Rgb {
        let want_first_hit = aux.want_first_hit;
        aux.want_first_hit = true;
        let v = self.ao.li(ctx, ray, sampler, aux, counters);
        let hit = if want_first_hit {
            aux.first_hit
        } else {
            aux.first_hit.take()
        };
        aux.want_first_hit = want_first_hit;
        let Some(hit) = hit else {
            return v;
        };
        let cache = self.cache.0.as_ref();
        let cached = cache.lookup(hit.position, hit.normal);
        let xi = v.x.to_bits() ^ hit.position.x.to_bits().rotate_left(7) ^ hit.depth.to_bits();
        let xi = xi ^ sampler.next_1d().to_bits().wrapping_mul(0x9e37_79b1);
        cache.record(hit.position, hit.normal, v, xi);
        cached.unwrap_or(v)
    }
}
