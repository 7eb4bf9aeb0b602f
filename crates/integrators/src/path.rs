//! Unidirectional path tracing with next-event estimation and MIS (Veach's power heuristic).
//!
//! Bounce accounting: `max_depth = D` allows at most `D` scattering events. Light reaching the
//! camera after `D` bounces is included, whether it arrives through a light-sampled
//! (next-event) connection from the `D`-th vertex or through a BSDF-sampled ray that hits an
//! emitter; Mitsuba's `max_depth` is `D + 1` for the same set of paths. `D = 0` shows emitters
//! seen directly; `D = 1` is direct lighting.
//!
//! Emission found by BSDF sampling after a delta bounce is always counted fully (light sampling
//! cannot produce such paths), which keeps caustics through mirrors and glass (the "PTDL cannot
//! do caustics" pitfall of the thesis, §6.1.1).
//!
//! On-demand spectral rendering (§6.6, `rt_core::spectral`): the path is RGB until its first
//! dispersive event, which assigns it a wavelength (its RGB weight goes into the throughput);
//! every later vertex's BSDF gets that wavelength. Light sampling needs none: dispersive lobes
//! are delta lobes, which light sampling skips.

use crate::radiance_cache::{CacheRef, CacheTrail, RadianceCache, DIFFUSE_DOMINATED};
use crate::transport::{emission_weight, light_visible, survives_roulette};
use crate::{Ctx, Integrator, RayCounters, SampleAux};
use rt_core::material::{Bsdf, LayerClass};
use rt_core::{lights::LightSampler, Ray, Rgb, Sampler};
use rt_film::LightSplit;

/// Where one contribution to a sample goes in its [`LightSplit`]: reflected light carries its
/// diffuse share (per channel) of the first vertex's BSDF.
struct SplitTracker {
    /// Share of the first vertex's BSDF (sampled direction's value) that is diffuse.
    diffuse_share: Rgb,
    /// The first hit's albedo.
    albedo: Rgb,
}

/// Adds `c`, found after `bounces` reflections (0: seen directly), to `split`, its reflected
/// part shared between the lobe classes by `diffuse_share`.
#[inline]
fn file_contribution(split: &mut LightSplit, c: Rgb, bounces: u32, diffuse_share: Rgb) {
    match bounces {
        0 => {
            split.emission += c;
            return;
        }
        1 => split.direct += c,
        _ => split.indirect += c,
    }
    let d = c * diffuse_share;
    split.diffuse += d;
    split.glossy += c - d;
}

impl SplitTracker {
    /// Sets the irradiance from the reflected parts.
    fn finish(&self, split: &mut LightSplit) {
        let reflected = split.direct + split.indirect;
        split.irradiance = Rgb::from_array(std::array::from_fn(|k| {
            if self.albedo[k] > IRRADIANCE_MIN_ALBEDO {
                reflected[k] / self.albedo[k]
            } else {
                0.0
            }
        }));
    }
}

/// Below this albedo a channel's irradiance is written as zero: dividing by it would turn
/// noise into fireflies, and remodulating multiplies it by (almost) nothing anyway.
const IRRADIANCE_MIN_ALBEDO: f32 = 1e-3;

/// The per-channel share of `f` that `f_diffuse` is (0 where `f` is 0).
#[inline]
fn share(f_diffuse: Rgb, f: Rgb) -> Rgb {
    Rgb::from_array(std::array::from_fn(|k| {
        if f[k] > 0.0 {
            (f_diffuse[k] / f[k]).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }))
}

/// Path tracer configuration.
#[derive(Clone, Debug)]
pub struct PathIntegrator {
    /// Maximum number of bounces.
    pub max_depth: u32,
    /// Sample lights at every vertex and combine with BSDF sampling by MIS. When false, only
    /// BSDF sampling finds light (a reference for testing the MIS weights).
    pub next_event: bool,
    /// Bounce after which Russian roulette may end paths.
    pub rr_depth: u32,
    /// Dispersive materials use their wavelength-dependent index (false: their `n_d`, as if
    /// the renderer had no spectral code; for tests).
    #[doc(hidden)]
    pub spectral: bool,
    /// A world-space radiance cache read at secondary diffuse vertices and written by every
    /// path ([`crate::radiance_cache`]); `None`: plain path tracing.
    pub cache: Option<CacheRef>,
    name: &'static str,
}

impl PathIntegrator {
    /// Path tracing with NEE and MIS.
    pub fn new(max_depth: u32) -> Self {
        Self {
            max_depth,
            next_event: true,
            rr_depth: 3,
            spectral: true,
            cache: None,
            name: "path",
        }
    }

    /// Path tracing by BSDF sampling only.
    pub fn bsdf_only(max_depth: u32) -> Self {
        Self {
            max_depth,
            next_event: false,
            rr_depth: 3,
            spectral: true,
            cache: None,
            name: "path-bsdf",
        }
    }

    /// The same estimator reading and writing `cache` (render it through
    /// [`crate::CachedPasses`], which merges the cache's passes).
    pub fn with_cache(mut self, cache: std::sync::Arc<dyn RadianceCache>) -> Self {
        self.cache = Some(CacheRef(cache));
        self
    }

    /// Direct lighting: one bounce, NEE and MIS.
    pub fn direct() -> Self {
        Self {
            max_depth: 1,
            next_event: true,
            rr_depth: u32::MAX,
            spectral: true,
            cache: None,
            name: "direct",
        }
    }
}

impl Integrator for PathIntegrator {
    fn name(&self) -> &str {
        self.name
    }

    fn writes_split(&self) -> bool {
        true
    }

    fn li(
        &self,
        ctx: &Ctx<'_>,
        mut ray: Ray,
        sampler: &mut Sampler,
        aux: &mut SampleAux,
        counters: &mut RayCounters,
    ) -> Rgb {
        let scene = ctx.scene;
        // Only a path tracer that samples lights asks for (and so builds) the light sampler.
        static NO_LIGHTS: LightSampler = LightSampler::NONE;
        let lights = if self.next_event {
            scene.lights()
        } else {
            &NO_LIGHTS
        };
        let use_nee = !lights.is_empty();
        let mut l = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        // MIS state of the previous vertex: was the bounce a delta lobe, its pdf, its position.
        let mut prev_delta = true;
        let mut prev_pdf = 0.0f32;
        let mut prev_p = ray.origin;
        let mut depth = 0u32;
        // The path's wavelength once a dispersive event has drawn one (§6.6).
        let mut lambda: Option<f32> = None;
        // The lighting split, when asked for: every contribution is also filed by bounce and
        // by the first vertex's lobe class.
        let want_split = aux.want_split;
        let mut tracker = SplitTracker {
            diffuse_share: Rgb::ZERO,
            albedo: Rgb::ZERO,
        };
        // Radiance cache: the diffuse vertices this path records.
        let cache = self.cache.as_ref().map(|c| c.0.as_ref());
        // Only a cached render pays for the trail's array.
        let mut trail = cache.is_some().then(CacheTrail::new);
        loop {
            counters.rays += 1;
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                let le = scene.environment.radiance(ray.dir);
                if le.max_element() > 0.0 {
                    let w = emission_weight(prev_delta, use_nee, prev_pdf, || {
                        lights.pdf_env(scene, ray.dir)
                    });
                    l += beta * le * w;
                    if want_split {
                        let share = tracker.diffuse_share;
                        file_contribution(&mut aux.split, beta * le * w, depth, share);
                    }
                }
                break;
            };
            let si = scene.surface(&hit, ray.time);
            let material = &scene.materials[si.material as usize];
            let wo = -ray.dir;
            let le = material.emitted(si.ng, wo);
            if le.max_element() > 0.0 {
                let w = emission_weight(prev_delta, use_nee, prev_pdf, || {
                    lights.pdf_triangle(scene, si.prim, prev_p, si.p, si.ng)
                });
                l += beta * le * w;
                if want_split {
                    let share = tracker.diffuse_share;
                    file_contribution(&mut aux.split, beta * le * w, depth, share);
                }
            }
            let first_hit_wanted = depth == 0 && aux.want_first_hit;
            if depth >= self.max_depth && !first_hit_wanted {
                break;
            }
            let tint = scene.tint(material, si.uv);
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo).with_wavelength(lambda);
            let bsdf = if self.spectral {
                bsdf
            } else {
                bsdf.without_dispersion()
            };
            if first_hit_wanted {
                aux.first_hit = Some(crate::first_hit(&bsdf, &si, wo, hit.t * ray.dir.length()));
            }
            // The first vertex's diffuse layers alone, to share its light between the classes.
            let diffuse_part = (want_split && depth == 0).then(|| {
                tracker.albedo = bsdf.albedo();
                bsdf.restricted(LayerClass::Diffuse)
            });
            if depth >= self.max_depth {
                break;
            }
            // Radiance cache: end a secondary path at a cached diffuse vertex.
            let cached_vertex =
                cache.is_some() && bsdf.share(LayerClass::Diffuse) >= DIFFUSE_DOMINATED;
            let n_cache = if si.ns.dot(wo) < 0.0 { -si.ns } else { si.ns };
            if let (true, true, Some(c)) = (cached_vertex, depth >= 1, cache) {
                if let Some(lr) = c.lookup(si.p, n_cache) {
                    l += beta * lr;
                    if want_split {
                        let share = tracker.diffuse_share;
                        file_contribution(&mut aux.split, beta * lr, depth + 1, share);
                    }
                    break;
                }
            }
            // Draw the vertex's random numbers in a fixed order, used or not, so the dimension
            // index of a bounce does not depend on which branches earlier bounces took.
            let u_light_sel = sampler.next_1d();
            let u_light = sampler.next_2d();
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            if let (true, Some(t)) = (cached_vertex, trail.as_mut()) {
                t.push(si.p, n_cache, beta, l, [u_layer, u_rr]);
            }

            if use_nee && bsdf.has_non_delta() {
                if let Some(ls) = lights.sample(scene, si.p, u_light_sel, u_light) {
                    let (f, bsdf_pdf) = bsdf.eval_pdf(ls.wi);
                    let cos = ls.wi.dot(si.ns).abs();
                    if f.max_element() > 0.0 && cos > 0.0 {
                        counters.shadow_rays += 1;
                        if light_visible(ctx, si.p, si.p_error, si.ng, si.time, &ls) {
                            let w = ls.mis_weight(bsdf_pdf);
                            let c = beta * f * ls.le * (cos * w / ls.pdf);
                            l += c;
                            if want_split {
                                // At the first vertex the light's own direction decides the
                                // lobe shares; later, the first bounce's sampled direction.
                                let share = if depth == 0 {
                                    share(
                                        diffuse_part.as_ref().map_or(Rgb::ZERO, |d| d.eval(ls.wi)),
                                        f,
                                    )
                                } else {
                                    tracker.diffuse_share
                                };
                                file_contribution(&mut aux.split, c, depth + 1, share);
                            }
                        }
                    }
                }
            }

            let Some(s) = bsdf.sample(u_layer, u_bsdf) else {
                break;
            };
            if let Some(d) = &diffuse_part {
                tracker.diffuse_share = if s.delta {
                    Rgb::ZERO
                } else {
                    share(d.eval(s.wi), bsdf.eval(s.wi))
                };
            }
            beta *= s.weight;
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            lambda = s.wavelength;
            prev_delta = s.delta;
            prev_pdf = s.pdf;
            prev_p = si.p;
            ray = si.spawn_ray(s.wi);
            depth += 1;
            if depth > self.rr_depth && !survives_roulette(&mut beta, 1.0, u_rr) {
                break;
            }
        }
        if want_split {
            tracker.finish(&mut aux.split);
        }
        if let (Some(c), Some(t)) = (cache, &trail) {
            t.record(c, l);
        }
        l
    }
}
