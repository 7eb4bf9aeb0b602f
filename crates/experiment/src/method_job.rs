//! The render job of a method on a scene ([`Pair::job`]): what the grid runs for each of a
//! method's progressive budgets or adaptive rules, the same [`RenderJob`] `render`, `render
//! part`, `--resume` and the references run; and of a sequence method on a sequence scene
//! ([`Pair::sequence_job`]), the frames `render --frames A..B --denoiser ...` renders.

use crate::config::{MethodPlan, Pair, ScenePlan, SequencePlan};
use rt_session::{Budgets, Frames, GreeJob, ImageSize, RenderJob, Settings, StopRule, Stream};
use rt_temporal::TemporalSpec;

impl Pair {
    /// The job of this pair's `method` on `scene`: its estimator, structure and seed, the
    /// scene's camera at the plan's size, the normal streams, and the method's denoiser (the
    /// film then keeps what it reads; the grid denoises each stop itself, to time and measure
    /// it apart) or its GREE options. Without `stop` the job renders `budgets` progressively
    /// ([`RenderJob::render_stops`]), or for GREE the one budget in `budgets`
    /// ([`RenderJob::gree_run`]); with it, one adaptive render capped at its `max_spp`.
    pub fn job(
        &self,
        scene: &ScenePlan,
        method: &MethodPlan,
        budgets: Option<&Budgets>,
        stop: Option<StopRule>,
    ) -> RenderJob {
        let spp = match (stop, budgets) {
            (Some(rule), _) => rule.max_spp,
            (None, Some(Budgets::Spp(list))) => list.last().copied().unwrap_or(0),
            (None, _) => 0,
        };
        let denoiser = method.denoiser.clone().map(TemporalSpec::PerFrame);
        let mut job = RenderJob::new(&scene.path, self.settings(spp, denoiser));
        job.camera = Some(scene.camera.name.clone());
        job.size = ImageSize::Pixels(scene.camera.width, scene.camera.height);
        job.stream = Stream::Render;
        job.stop = stop;
        job.gree = method.gree.as_ref().map(|g| GreeJob {
            options: g.options,
            // The plan's bank, which the grid hands to `RenderJob::gree_run`.
            bank: None,
            labels: None,
            error_maps: None,
        });
        job
    }

    /// The job of this pair's sequence `method` on the frames `seq` of `scene`
    /// ([`SequencePlan::job`]) at `spp` samples per pixel per frame: its estimator, structure
    /// and seed, and the method's denoiser, temporal or run on each frame alone
    /// ([`RenderJob::sequence_renderer`]).
    pub fn sequence_job(
        &self,
        scene: &ScenePlan,
        method: &MethodPlan,
        seq: &SequencePlan,
        spp: u32,
    ) -> RenderJob {
        seq.job(scene, self.settings(spp, method.temporal.clone()))
    }

    /// This pair's estimator, structure and seed at `spp` with `denoiser`.
    fn settings(&self, spp: u32, denoiser: Option<TemporalSpec>) -> Settings {
        Settings {
            integrator: self.estimator,
            accel: self.accel,
            spp,
            threads: None,
            seed: self.seed,
            aovs: Default::default(),
            output: None,
            denoiser,
        }
    }
}

impl SequencePlan {
    /// A job over these frames of `scene` with `settings`: the sequence's camera (looked up
    /// again at every frame's time, as cameras move) at its size, its frames and rate.
    pub fn job(&self, scene: &ScenePlan, settings: Settings) -> RenderJob {
        let mut job = RenderJob::new(&scene.path, settings);
        job.camera = self.camera.clone();
        job.size = self.size;
        job.frames = Frames::Range(self.frames.clone());
        job.fps = self.fps;
        job
    }
}
