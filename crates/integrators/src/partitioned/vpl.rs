//! Virtual point lights of the partitioned renderer (instant radiosity, Keller 1997; Dammertz
//! 2011, §6.3.1): particle walks from the lights leave a VPL at every vertex with a diffuse
//! part, and every eye vertex gathers from all of them (part A, `EDL` and `EDD(S|D)*L`; behind
//! specular chains also part C).

use super::eye::EyeVertex;
use super::{Culling, Partitioned};
use crate::transport::{adjoint_cos, importance_weight, survives_roulette};
use crate::{Ctx, RayCounters};
use rt_core::{
    delta_light::DeltaLight,
    emission::plane_area,
    glam::{Vec2, Vec3},
    material::{Bsdf, LayerClass},
    ray::{shadow_segment, spawn_ray},
    Aabb, Ray, Rgb, Sampler,
};

/// What a VPL is.
#[derive(Clone)]
// Most VPLs are surface points, which hold their BSDF (with its textured parameters) inline:
// boxing it would allocate per VPL for no memory saved.
#[allow(clippy::large_enum_variant)]
pub(super) enum Source<'a> {
    /// A point on an emissive triangle: radiance `le` to the front (both faces if two-sided).
    Emitter { le: Rgb, two_sided: bool },
    /// The environment in one direction (`dir`, towards it), with its radiance over the
    /// direction's pdf.
    Distant { dir: Vec3 },
    /// A diffuse surface point lit by the walk; the diffuse part of its BSDF for light
    /// arriving from the walk's side.
    Surface { bsdf: Bsdf<'a>, wo: Vec3, ns: Vec3 },
    /// A point, spot or directional light itself: what it sends to an eye vertex is exact
    /// (`I·falloff/r²` or `E`), so its geometric term is not clamped.
    Delta { light: DeltaLight },
}

/// One virtual point light.
#[derive(Clone)]
pub(super) struct Vpl<'a> {
    pub source: Source<'a>,
    pub p: Vec3,
    pub p_error: Vec3,
    pub ng: Vec3,
    /// Power: the walk's throughput over the number of walks (and the culling weight).
    pub beta: Rgb,
    /// Scattering vertices of the light path up to this one (0 for the light itself).
    pub bounce: u32,
}

/// A light point a pass's caustic photons start from (the walks' first vertices).
#[derive(Clone, Copy)]
pub(super) struct PrimaryLight {
    pub p: Vec3,
    pub p_error: Vec3,
    pub n: Vec3,
    pub two_sided: bool,
    /// For the environment: the direction the photons travel, else zero.
    pub travel: Vec3,
    /// `Le / pdf_position` (emitters: Le times π and the faces over the area pdf, the cosine
    /// direction's weight; environment: radiance over the direction's pdf times the plane's
    /// area), over the number of walks. For a point or spot light, one over the probability
    /// of choosing it, over the number of walks: each photon then carries what
    /// [`DeltaLight::emit`] gives its direction.
    pub beta: Rgb,
    /// A point or spot light, whose photons leave it as [`DeltaLight::emit`] sends them.
    pub delta: Option<DeltaLight>,
}

impl Partitioned {
    /// The pass's VPLs and the primary lights the caustic photons start from. `sentinels`:
    /// the eye vertices the culling test looks at.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn vpls<'a>(
        &self,
        ctx: &Ctx<'a>,
        bounds: &Aabb,
        seed: u32,
        stream: rt_core::SampleStream,
        index: u32,
        sentinels: &[EyeVertex],
        counters: &mut RayCounters,
        culled: &mut u64,
    ) -> (Vec<Vpl<'a>>, Vec<PrimaryLight>) {
        let scene = ctx.scene;
        let lights = scene.lights();
        let n = self.options.vpl_paths;
        let scale = 1.0 / n as f32;
        let mut vpls = Vec::new();
        let mut primaries = Vec::new();
        let mut sampler = Sampler::with_stream(seed, stream);
        for j in 0..n {
            sampler.start_light_path(j, index);
            let u_sel = sampler.next_1d();
            let u_pos = sampler.next_2d();
            let u_dir = sampler.next_2d();
            let Some(e) = lights.sample_emission(scene, bounds, u_sel, u_pos, u_dir) else {
                continue;
            };
            match (e.point, e.delta_light) {
                (Some(pt), _) => {
                    let faces = if pt.two_sided { 2.0 } else { 1.0 };
                    primaries.push(PrimaryLight {
                        p: pt.point,
                        p_error: pt.error,
                        n: pt.normal,
                        two_sided: pt.two_sided,
                        travel: Vec3::ZERO,
                        beta: pt.emission * (std::f32::consts::PI * faces / pt.pdf_area * scale),
                        delta: None,
                    });
                    vpls.push(Vpl {
                        source: Source::Emitter {
                            le: pt.emission,
                            two_sided: pt.two_sided,
                        },
                        p: pt.point,
                        p_error: pt.error,
                        ng: pt.normal,
                        beta: Rgb::splat(scale / pt.pdf_area),
                        bounce: 0,
                    });
                }
                (None, Some(light)) => {
                    // The probability of choosing the light: `pdf_position` holds it times the
                    // position's density (1 for a point or spot, the plane's for a direction).
                    let choice = match light {
                        DeltaLight::Directional { .. } => {
                            e.pdf_position * plane_area(bounds, e.dir)
                        }
                        _ => e.pdf_position,
                    };
                    let directional = matches!(light, DeltaLight::Directional { .. });
                    primaries.push(PrimaryLight {
                        p: e.origin,
                        p_error: Vec3::ZERO,
                        n: e.dir,
                        // A point's photons may leave in any direction: the whole sphere's map.
                        two_sided: true,
                        travel: if directional { e.dir } else { Vec3::ZERO },
                        beta: if directional {
                            e.beta * scale
                        } else {
                            Rgb::splat(scale / choice)
                        },
                        delta: (!directional).then_some(light),
                    });
                    vpls.push(Vpl {
                        source: Source::Delta { light },
                        p: e.origin,
                        p_error: Vec3::ZERO,
                        ng: Vec3::ZERO,
                        beta: Rgb::splat(scale / choice),
                        bounce: 0,
                    });
                }
                (None, None) => {
                    primaries.push(PrimaryLight {
                        p: e.origin,
                        p_error: Vec3::ZERO,
                        n: e.dir,
                        two_sided: false,
                        travel: e.dir,
                        beta: e.beta * scale,
                        delta: None,
                    });
                    vpls.push(Vpl {
                        source: Source::Distant { dir: -e.dir },
                        p: Vec3::ZERO,
                        p_error: Vec3::ZERO,
                        ng: Vec3::ZERO,
                        beta: scene.environment.radiance(-e.dir) * (scale / e.pdf_direction),
                        bounce: 0,
                    });
                }
            }
            let ray = e.ray();
            self.walk(
                ctx,
                ray,
                e.beta * scale,
                &mut sampler,
                sentinels,
                &mut vpls,
                counters,
                culled,
            );
        }
        (vpls, primaries)
    }

    /// The particle walk of one VPL path, storing a VPL at every vertex with a diffuse part.
    #[allow(clippy::too_many_arguments)]
    fn walk<'a>(
        &self,
        ctx: &Ctx<'a>,
        mut ray: Ray,
        mut beta: Rgb,
        sampler: &mut Sampler,
        sentinels: &[EyeVertex],
        vpls: &mut Vec<Vpl<'a>>,
        counters: &mut RayCounters,
        culled: &mut u64,
    ) {
        let scene = ctx.scene;
        // A VPL at bounce b lights eye vertices of depth at most max_depth - b.
        // The walk's wavelength once a dispersive event has drawn one (§6.6).
        let mut lambda: Option<f32> = None;
        let start = beta.max_element();
        for bounce in 1..self.max_depth {
            counters.rays += 1;
            let Some(hit) = ctx.accel.intersect(&ray, f32::INFINITY) else {
                break;
            };
            let si = scene.surface(&hit, 0.0);
            let material = &scene.materials[si.material as usize];
            let wo = -ray.dir;
            let tint = scene.tint(material, si.uv);
            // Importance's BSDF (refraction without radiance's `1/η²`), as the light tracer's;
            // the VPL keeps it too: it reflects light arriving from `wo`.
            let bsdf = Bsdf::new(material, tint, si.ns, si.ng, wo)
                .with_wavelength(lambda)
                .adjoint();
            let u_layer = sampler.next_1d();
            let u_bsdf = sampler.next_2d();
            let u_rr = sampler.next_1d();
            let u_cull = sampler.next_1d();
            if bsdf.share(LayerClass::Diffuse) > 0.0 {
                let weight =
                    self.cull_weight(ctx, si.p, si.p_error, si.ng, sentinels, u_cull, counters);
                if weight > 0.0 {
                    vpls.push(Vpl {
                        source: Source::Surface {
                            bsdf: bsdf.restricted(LayerClass::Diffuse),
                            wo,
                            ns: si.ns,
                        },
                        p: si.p,
                        p_error: si.p_error,
                        ng: si.ng,
                        beta: beta * weight,
                        bounce,
                    });
                } else {
                    *culled += 1;
                }
            }
            let Some(s) = bsdf.sample(u_layer, u_bsdf) else {
                break;
            };
            beta *= importance_weight(&s, wo, si.ns, si.ng);
            lambda = s.wavelength;
            if beta.max_element() <= 0.0 || !beta.is_finite() {
                break;
            }
            if bounce > self.rr_depth && !survives_roulette(&mut beta, start, u_rr) {
                break;
            }
            ray = spawn_ray(si.p, si.p_error, si.ng, s.wi);
        }
    }

    /// The weight a VPL at `p` is stored with: 1 if it sees one of the sentinel eye vertices;
    /// otherwise 0, or (unbiased culling) `1 / KEEP` with probability `KEEP`.
    #[allow(clippy::too_many_arguments)]
    fn cull_weight(
        &self,
        ctx: &Ctx<'_>,
        p: Vec3,
        p_error: Vec3,
        ng: Vec3,
        sentinels: &[EyeVertex],
        u: f32,
        counters: &mut RayCounters,
    ) -> f32 {
        /// Probability of keeping a VPL no sentinel sees, in unbiased culling.
        const KEEP: f32 = 0.125;
        if self.options.cull == Culling::Off || sentinels.is_empty() {
            return 1.0;
        }
        for e in sentinels {
            counters.shadow_rays += 1;
            let (r, t_max) = shadow_segment(p, p_error, ng, e.p, e.p_error, e.ng);
            if !ctx.accel.occluded(&r, t_max) {
                return 1.0;
            }
        }
        match self.options.cull {
            Culling::Unbiased if u < KEEP => 1.0 / KEEP,
            _ => 0.0,
        }
    }

    /// Light from every VPL reaching eye vertex `e` through its diffuse part.
    pub(super) fn gather(
        &self,
        ctx: &Ctx<'_>,
        e: &EyeVertex,
        vpls: &[Vpl<'_>],
        g_max: f32,
        counters: &mut RayCounters,
    ) -> Rgb {
        let bsdf = e.diffuse_bsdf(ctx);
        let mut sum = Rgb::ZERO;
        for v in vpls {
            if e.depth + v.bounce > self.max_depth {
                continue;
            }
            let (w, value) = match &v.source {
                Source::Delta { light } => {
                    let Some(inc) = light.incident(e.p) else {
                        continue;
                    };
                    let value = bsdf.eval(inc.wi) * inc.le * v.beta * inc.wi.dot(e.ns).abs();
                    if value.max_element() <= 0.0 || !value.is_finite() {
                        continue;
                    }
                    counters.shadow_rays += 1;
                    if !delta_light_occluded(ctx, e, &inc) {
                        sum += value;
                    }
                    continue;
                }
                Source::Distant { dir } => {
                    let f = bsdf.eval(*dir);
                    (*dir, f * v.beta * dir.dot(e.ns).abs())
                }
                Source::Emitter { le, two_sided } => {
                    let d = v.p - e.p;
                    let d2 = d.length_squared();
                    let w = d / d2.sqrt();
                    let cos_l = -v.ng.dot(w);
                    if !(*two_sided || cos_l > 0.0) {
                        continue;
                    }
                    let g = (w.dot(e.ns).abs() * cos_l.abs() / d2).min(g_max);
                    (w, bsdf.eval(w) * *le * v.beta * g)
                }
                Source::Surface { bsdf: vb, wo, ns } => {
                    let d = v.p - e.p;
                    let d2 = d.length_squared();
                    let w = d / d2.sqrt();
                    let g = (w.dot(e.ns).abs() * adjoint_cos(*wo, -w, *ns, v.ng) / d2).min(g_max);
                    (w, bsdf.eval(w) * vb.eval(-w) * v.beta * g)
                }
            };
            if value.max_element() <= 0.0 || !value.is_finite() {
                continue;
            }
            counters.shadow_rays += 1;
            let occluded = match v.source {
                Source::Distant { .. } => {
                    let r = spawn_ray(e.p, e.p_error, e.ng, w);
                    ctx.accel.occluded(&r, f32::INFINITY)
                }
                _ => {
                    let (r, t_max) = shadow_segment(e.p, e.p_error, e.ng, v.p, v.p_error, v.ng);
                    ctx.accel.occluded(&r, t_max)
                }
            };
            if !occluded {
                sum += value;
            }
        }
        e.beta * sum
    }
}

/// True if something blocks the light `inc` arriving at eye vertex `e` (a shadow ray to the
/// light's position, or towards a directional light's infinity).
fn delta_light_occluded(
    ctx: &Ctx<'_>,
    e: &EyeVertex,
    inc: &rt_core::delta_light::DeltaIncidence,
) -> bool {
    if inc.dist.is_infinite() {
        let r = spawn_ray(e.p, e.p_error, e.ng, inc.wi);
        return ctx.accel.occluded(&r, f32::INFINITY);
    }
    let (r, t_max) = shadow_segment(e.p, e.p_error, e.ng, inc.point, Vec3::ZERO, Vec3::ZERO);
    ctx.accel.occluded(&r, t_max)
}

/// The `i`-th point of the 2D Halton sequence (bases 2 and 3).
pub(super) fn halton2(i: u32) -> Vec2 {
    let radical = |mut i: u32, base: u32| {
        let (mut f, mut r) = (1.0f64, 0.0f64);
        while i > 0 {
            f /= f64::from(base);
            r += f * f64::from(i % base);
            i /= base;
        }
        r as f32
    };
    Vec2::new(radical(i, 2), radical(i, 3))
}
