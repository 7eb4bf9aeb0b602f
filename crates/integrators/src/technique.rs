//! The pass-based seam every light-transport technique implements: add sample indices `a..b`
//! to a film. Camera-ray estimators ([`Integrator`]) are one kind, driven pixel by pixel by
//! [`render_samples`]; light-path techniques ([`crate::LightTracer`]) splat anywhere.
//!
//! Whatever the technique, a pass is a pure function of (seed, sample indices, scene,
//! settings): passes `0..a` then `a..b` give the same film as `0..b`, bit for bit, on any
//! number of threads.

use crate::driver::{render_samples, RenderStats, SamplePass};
use crate::{Ctx, Integrator};
use rt_film::Film;
use std::time::Duration;

/// One line of a technique's own account of a render (`render --stats`): a stage it ran, the
/// time it took if measured, and what it did.
#[derive(Clone, Debug, PartialEq)]
pub struct TechniqueStage {
    /// Stage name, e.g. `projection maps`.
    pub name: &'static str,
    /// Time spent in it, summed over passes and threads' wall time, if measured.
    pub time: Option<Duration>,
    /// What it did, as text.
    pub details: String,
}

/// A light-transport technique that renders in passes of sample indices.
pub trait Technique: Send + Sync {
    /// Short name for reports.
    fn name(&self) -> &str;

    /// Adds the samples `pass.indices` to `film`. `progress` is called from worker threads with
    /// the work done so far in this pass, in image rows (a splatting technique converts its own
    /// units), so one progress bar serves every technique. `samples` in the result counts
    /// camera samples and light paths alike (a light-path technique takes one light path per
    /// pixel per sample index).
    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats;

    /// The per-ray estimator, for a technique that is one (callers that trace single camera
    /// rays, like tests of an estimator's value, need it).
    fn camera_integrator(&self) -> Option<&dyn Integrator> {
        None
    }

    /// True if the technique splats light paths onto the film, whose per-pixel variance the
    /// film then does not know: the one answer (settings, references, adaptive passes and the
    /// memory estimate all ask the built technique).
    fn splats(&self) -> bool {
        false
    }

    /// True if the technique traces every ray of a sample at the sample's shutter time, so
    /// it can render a motion-blurred scene ([`rt_core::Scene::is_motion_blurred`]).
    /// Camera-ray estimators do; light-path techniques do not yet (their light paths and
    /// caches are traced at the shutter's opening), and callers refuse the combination.
    fn motion_blur(&self) -> bool {
        false
    }

    /// True if the technique renders scenes with delta lights (point, spot, directional;
    /// [`rt_core::delta_light`]). Techniques that weigh light-path vertices against each
    /// other by their area pdfs would not handle a light of no extent and say so here; callers
    /// refuse the combination.
    fn delta_lights(&self) -> bool {
        true
    }

    /// True if the technique writes the lighting-split AOVs (emission, direct, indirect,
    /// diffuse, glossy, irradiance): a camera-ray estimator whose
    /// [`Integrator::writes_split`] says so. Callers refuse a film that asks for the split
    /// otherwise, since the driver would leave its sums at zero.
    fn writes_split(&self) -> bool {
        self.camera_integrator().is_some_and(|i| i.writes_split())
    }

    /// The technique's own stages over the passes rendered so far, for reports; none by
    /// default (camera-ray estimators have nothing beyond the render's totals).
    fn stages(&self) -> Vec<TechniqueStage> {
        Vec::new()
    }
}

/// A camera-ray [`Integrator`] as a [`Technique`]: every pixel takes its own samples.
pub struct CameraRays(pub Box<dyn Integrator>);

impl Technique for CameraRays {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats {
        render_samples(ctx, self.0.as_ref(), film, seed, pass, progress)
    }

    fn motion_blur(&self) -> bool {
        true
    }

    fn camera_integrator(&self) -> Option<&dyn Integrator> {
        Some(self.0.as_ref())
    }
}
