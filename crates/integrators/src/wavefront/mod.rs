//! The wavefront path tracer: the estimator of [`PathIntegrator`] (next-event estimation with
//! MIS, Russian roulette, the layered material, on-demand spectral paths), advanced for
//! thousands of samples at a time, stage by stage.
//!
//! Each thread keeps one batch of paths ([`lanes::Batch`], allocated once) and runs rounds
//! of: camera rays for the lanes that are free, one closest-hit stream for every lane
//! ([`rt_core::Accel::intersect_stream`]), the vertex's random numbers for every lane in one
//! vectorised kernel ([`lanes::draw_vertices`]: the sampler's hashes, eight lanes per AVX2
//! instruction when the CPU has it, the same bits without), shading, one shadow-ray stream
//! ([`rt_core::Accel::occluded_stream`]), and the finished paths into the film. The stages
//! and their queues follow pbrt-v4's wavefront integrator (Pharr, Jakob, Humphreys,
//! *Physically Based Rendering*, 4th ed., ch. 15) on a CPU thread instead of a GPU, with
//! lanes refilled as paths end ("regeneration", as in Áfra et al., HPG 2016) so a batch stays
//! full through the long tail of an unlimited-depth render.
//!
//! Every sample draws the same random numbers at the same dimensions as in the scalar tracer
//! and shades with the same arithmetic in the same order ([`shade`]), so the wavefront image
//! is the scalar image, bit for bit: everything proven of `path` (convergence, MIS, parts that
//! merge exactly) holds here, and the tests check the equality itself.
//!
//! Deviations, and what is left to the scalar tracer: a render that asks for the lighting
//! split AOVs, per-sample records (SBMF) or a world-space radiance cache runs its passes on
//! the scalar path tracer (the same estimator, so the same image), and says so in
//! [`Technique::stages`].
//!
//! Shading is sorted by material kind: plain Lambertian vertices, the common case, go to a
//! structure-of-arrays queue whose BSDF stage runs eight lanes at a time ([`lambert`], after
//! Áfra et al., HPG 2016, "Local Shading Coherence Extraction for SIMD-Efficient Path Tracing
//! on CPUs"); every other vertex, emission, surface reconstruction and light sampling are
//! shaded one lane at a time ([`shade`]).

#[cfg(target_arch = "x86_64")]
mod draws_avx2;
mod lambert;
mod lanes;
mod pass;
mod profile;
mod shade;
mod simd;

use crate::driver::{render_samples, RenderStats, SamplePass};
use crate::technique::{Technique, TechniqueStage};
use crate::{Ctx, Integrator, PathIntegrator};
use profile::Profile;
use rt_film::Film;
use std::sync::Mutex;

/// Paths per thread's batch when nothing else is asked for: large enough that a stream's
/// rays and a kernel's lanes amortise their set-up, small enough that the batch's state
/// (about 150 bytes a lane) stays in the L2 cache.
pub const DEFAULT_LANES: u32 = 1024;

/// The wavefront path tracer (see the module doc).
pub struct Wavefront {
    settings: PathIntegrator,
    lanes: usize,
    profile: Mutex<Profile>,
    /// Passes rendered by the scalar tracer, and why.
    scalar: Mutex<(u32, &'static str)>,
}

impl Wavefront {
    /// The wavefront form of `settings` (a path tracer with or without light sampling) with
    /// `lanes` paths per thread's batch.
    pub fn new(settings: PathIntegrator, lanes: u32) -> Self {
        Self {
            settings,
            lanes: lanes.max(1) as usize,
            profile: Mutex::new(Profile::default()),
            scalar: Mutex::new((0, "")),
        }
    }

    /// Why `film` needs the scalar tracer, if it does.
    fn scalar_reason(&self, film: &Film) -> Option<&'static str> {
        if film.aovs().any_split() {
            Some("the lighting-split AOVs")
        } else if film.buffers().samples {
            Some("per-sample records")
        } else if self.settings.cache.is_some() {
            Some("a radiance cache")
        } else {
            None
        }
    }
}

impl Technique for Wavefront {
    fn name(&self) -> &str {
        "wavefront"
    }

    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats {
        if let Some(why) = self.scalar_reason(film) {
            {
                let mut scalar = self.scalar.lock().unwrap_or_else(|e| e.into_inner());
                scalar.0 += 1;
                scalar.1 = why;
            }
            return render_samples(ctx, &self.settings, film, seed, pass, progress);
        }
        pass::render_pass(self, ctx, film, seed, pass, progress)
    }

    fn camera_integrator(&self) -> Option<&dyn Integrator> {
        Some(&self.settings)
    }

    fn motion_blur(&self) -> bool {
        true
    }

    fn stages(&self) -> Vec<TechniqueStage> {
        let p = self.profile.lock().unwrap_or_else(|e| e.into_inner());
        let mut out = Vec::new();
        if p.rounds > 0 {
            out.push(TechniqueStage {
                name: "wavefront batches",
                time: Some(p.time.iter().sum()),
                details: format!(
                    "{} lanes per thread, {} rounds, {:.0} % of lanes busy; {}",
                    self.lanes,
                    p.rounds,
                    100.0 * p.occupancy(),
                    p.shares()
                ),
            });
        }
        let (passes, why) = *self.scalar.lock().unwrap_or_else(|e| e.into_inner());
        if passes > 0 {
            out.push(TechniqueStage {
                name: "scalar path tracer",
                time: None,
                details: format!("{passes} passes: the film asks for {why}"),
            });
        }
        out
    }
}
