//! `rt-integrators`: light transport estimators and the loop that drives them over the film.
//!
//! An [`Integrator`] estimates the radiance arriving along one camera ray; the [`driver`] owns
//! the image loop (bands of rows in parallel with rayon, a deterministic sample stream per pixel
//! and sample index) and writes into an `rt_film::Film`. Integrators see geometry only through
//! `&dyn rt_core::Accel`, so they do not care which acceleration structure was built.
//!
//! Provided: [`PathIntegrator`] (unidirectional path tracing with next-event estimation and
//! multiple importance sampling, Russian roulette and a bounce limit; also usable with BSDF
//! sampling only), direct lighting (the same estimator stopped after one bounce) and
//! [`AoIntegrator`] (ambient occlusion); and [`LightTracer`] (particles from the lights, splatted
//! through the camera). Every one is a [`Technique`], the pass-based seam: camera-ray
//! integrators through [`CameraRays`], light-path techniques on their own.
//!
//! [`IntegratorSpec`] is the one place techniques are named, parsed from text such as
//! `path:max-depth=8` and built, so a program using this crate offers the same choice as
//! `render --integrator`.
//!
//! Depends on `rt-core` and `rt-film`.
// Unsafe code only where a module allows it: the SIMD kernels of `wavefront`.
#![deny(unsafe_code)]

mod ao;
mod bdpt;
pub mod driver;
pub mod guides;
mod light;
pub mod partitioned;
mod path;
pub mod radiance_cache;
pub mod spec;
pub mod technique;
mod transport;
mod wavefront;
mod work;

pub use ao::{AoIntegrator, CachedAo};
pub use bdpt::Bdpt;
pub use driver::{render, render_pixels, render_samples, RenderOptions, RenderStats, SamplePass};
pub use guides::{render_guides, GuideOptions, PreviousView};
pub use light::LightTracer;
pub use partitioned::{Culling, PartitionOptions, PartitionStats, Partitioned};
pub use path::PathIntegrator;
pub use radiance_cache::{CacheRef, CachedPasses, RadianceCache};
pub use spec::{
    IntegratorKind, IntegratorSpec, IntegratorSpecError, Target, DEFAULT_MAX_DEPTH, MAX_DEPTH,
};
pub use technique::{CameraRays, Technique, TechniqueStage};
pub use wavefront::{Wavefront, DEFAULT_LANES};

use rt_core::{Accel, Camera, Rgb, Sampler, Scene};
use rt_film::{FirstHit, LightSplit};

/// What an integrator needs to trace rays: the scene, a structure to query it, the camera.
#[derive(Clone, Copy)]
pub struct Ctx<'a> {
    /// Scene data.
    pub scene: &'a Scene,
    /// Ray queries.
    pub accel: &'a dyn Accel,
    /// The camera rays come from.
    pub camera: &'a Camera,
}

/// Rays traced, for the rays-per-second report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounters {
    /// Closest-hit queries.
    pub rays: u64,
    /// Occlusion queries.
    pub shadow_rays: u64,
}

impl std::ops::AddAssign for RayCounters {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
    }
}

/// Per-sample outputs besides radiance.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleAux {
    /// Fill `first_hit` (only when some first-hit AOV is wanted: it costs a BSDF setup).
    pub want_first_hit: bool,
    /// The first visible surface, if any and if wanted.
    pub first_hit: Option<FirstHit>,
    /// Fill `split` (only integrators whose [`Integrator::writes_split`] is true do).
    pub want_split: bool,
    /// How the sample's radiance divides (emission, direct/indirect, diffuse/glossy,
    /// irradiance), if wanted.
    pub split: LightSplit,
}

/// The first-hit AOVs of surface point `si` seen from direction `wo` (unit, towards the
/// camera) at distance `depth`, with its BSDF `bsdf`: the normal is turned to face the camera.
pub(crate) fn first_hit(
    bsdf: &rt_core::material::Bsdf<'_>,
    si: &rt_core::scene::SurfaceHit,
    wo: rt_core::glam::Vec3,
    depth: f32,
) -> FirstHit {
    let n = if si.ns.dot(wo) < 0.0 { -si.ns } else { si.ns };
    FirstHit {
        albedo: bsdf.albedo(),
        normal: n,
        depth,
        position: si.p,
    }
}

/// A radiance estimator for camera rays.
pub trait Integrator: Send + Sync {
    /// Short name for reports.
    fn name(&self) -> &str;

    /// True if the integrator fills [`SampleAux::split`] when asked (the lighting-split AOVs).
    fn writes_split(&self) -> bool {
        false
    }

    /// Estimates the radiance arriving at the camera along `ray`, drawing random numbers from
    /// `sampler`. Must not allocate: it runs once per sample.
    fn li(
        &self,
        ctx: &Ctx<'_>,
        ray: rt_core::Ray,
        sampler: &mut Sampler,
        aux: &mut SampleAux,
        counters: &mut RayCounters,
    ) -> Rgb;
}
