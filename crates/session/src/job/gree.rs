//! A GREE job's run kept in memory ([`RenderJob::gree_run`]): the noisy image, the filter
//! caches, the bank's images and the composite, for `render --gree` to write and for an
//! experiment to measure.

use super::report::JobSink;
use super::{refuse, JobError, RenderJob};
use crate::GreeRun;
use rt_denoise::Bank;
use rt_film::AovSet;
use rt_integrators::{Ctx, Technique};

impl RenderJob {
    /// Renders this GREE job's image of `ctx` with `technique` (its `settings.spp` is GREE's
    /// budget) from stream `seed` and denoises it with `bank` (`crate::gree`); nothing is
    /// written. Refuses a job without [`RenderJob::gree`], a technique that cannot render
    /// filter caches pixel by pixel, a stop rule and AOVs. Call it inside the thread pool that
    /// should do the work.
    pub fn gree_run(
        &self,
        ctx: &Ctx<'_>,
        technique: &dyn Technique,
        bank: &Bank,
        seed: u32,
        sink: &dyn JobSink,
    ) -> Result<GreeRun, JobError> {
        let Some(g) = self.gree.as_ref() else {
            return refuse("not a GREE job (no gree options)".into());
        };
        let scene = self.scene.display();
        let Some(integrator) = technique.camera_integrator() else {
            return refuse(format!(
                "{scene}: --gree renders filter caches pixel by pixel, which the {} technique cannot (use wavefront, path, path-bsdf, direct or ao)",
                technique.name()
            ));
        };
        if self.stop.is_some() {
            return refuse("--gree spends a fixed budget (--spp); it cannot be combined with --error or --time-limit".into());
        }
        if self.settings.aovs != AovSet::default() {
            return refuse("--gree writes the composite only; save a noisy frame's AOVs with a render without --gree".into());
        }
        let params = g
            .options
            .params(self.settings.spp, self.settings.seed)
            .map_err(|e| JobError::Refused(format!("--gree {}: {e}", g.options)))?;
        let rows = f64::from(ctx.camera.height.max(1));
        crate::render_gree(ctx, integrator, bank, &params, seed, &|r| {
            sink.progress(f64::from(r) / rows)
        })
        .map_err(|e| JobError::Failed(format!("{scene}: {e}")))
    }
}
