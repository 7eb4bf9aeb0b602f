//! A job's frames rendered in order through one [`SequenceRenderer`], so that a temporal
//! denoiser (SVGF) carries its history from frame to frame: what `render --frames A..B
//! --denoiser svgf` runs ([`RenderJob::run`]) and an experiment's sequence methods run over
//! the scene they hold ([`RenderJob::render_sequence`], which hands each frame over with its
//! noisy image, guide buffers and stage times).

use super::report::{FrameReport, JobReport, JobSink, Rendered};
use super::run::{thread_pool, FrameImage};
use super::{refuse, Frames, JobError, RenderJob};
use crate::frames::frame_path;
use crate::{SequenceFrame, SequenceRenderer};
use rt_core::Scene;
use std::time::{Duration, Instant};

impl RenderJob {
    /// The renderer of this job's frames over `scene`: its technique (over the job's
    /// world-space cache, which then carries over from frame to frame), structure, camera,
    /// samples, seed and rate, and its denoiser (`settings.denoiser`, temporal or run on each
    /// frame alone; none without one). A sequence renders a fixed number of samples per
    /// frame, without motion blur (the guide buffers describe one instant).
    pub fn sequence_renderer(&self, scene: &Scene) -> Result<SequenceRenderer, JobError> {
        let denoiser = self.settings.denoiser.as_ref();
        let what = denoiser.map_or_else(
            || "a sequence".to_string(),
            |spec| format!("--denoiser {spec}"),
        );
        if self.stop.is_some() {
            return refuse(format!("{what}: a sequence renders a fixed number of samples per frame (--spp); --error and --time-limit do not apply"));
        }
        if self.shutter != 0.0 {
            return refuse(format!("{what}: its guide buffers describe one instant; motion blur (--shutter) would not match them"));
        }
        let denoiser = denoiser
            .map(|spec| {
                spec.build()
                    .map_err(|e| JobError::Refused(format!("--denoiser {spec}: {e}")))
            })
            .transpose()?;
        let cache =
            crate::worldcache::for_job(self.cache.as_ref(), &self.settings.integrator, scene)?;
        SequenceRenderer::new(
            crate::worldcache::technique(&self.settings.integrator, cache)?,
            self.settings.accel,
            denoiser,
            self.camera.clone(),
            self.settings.spp,
            self.settings.seed,
            self.fps,
        )
        .map_err(|e| JobError::Refused(format!("{}: {what}: {e}", self.scene.display())))
    }

    /// Renders the job's frames of `scene` (which the caller loaded) in order with `renderer`
    /// (from [`RenderJob::sequence_renderer`]), each through the job's camera at its size, and
    /// calls `each` with every frame. Call it inside the thread pool that should do the work.
    pub fn render_sequence<E: From<JobError>>(
        &self,
        renderer: &mut SequenceRenderer,
        scene: &mut Scene,
        each: &mut dyn FnMut(&SequenceFrame) -> Result<(), E>,
    ) -> Result<(), E> {
        self.each_frame(scene, &mut |at| {
            let f = at.frame.unwrap_or(0);
            let camera = at.camera.clone();
            let out = renderer
                .render_with(at.scene_mut(), f, Some(&camera))
                .map_err(|e| {
                    JobError::Failed(format!("{}: frame {f}: {e}", self.scene.display()))
                })?;
            each(&out)
        })
    }

    /// Runs a temporally denoised job: its frames through [`RenderJob::render_sequence`],
    /// each written (or handed to the sink) and reported.
    pub(super) fn run_sequence(
        &self,
        scene: &mut Scene,
        sink: &dyn JobSink,
    ) -> Result<JobReport, JobError> {
        let mut renderer = self.sequence_renderer(scene)?;
        let denoiser = renderer.denoiser_name().unwrap_or_default().to_string();
        let pool = thread_pool(self.settings.threads)?;
        let threads = pool.current_num_threads();
        let triangles = scene.triangle_count();
        let started = Instant::now();
        let mut frames = 0;
        pool.install(|| {
            self.render_sequence(&mut renderer, scene, &mut |out| {
                let frame = (self.frames != Frames::Still).then_some(out.frame);
                let output =
                    frame.map_or_else(|| self.output.clone(), |f| frame_path(&self.output, f));
                sink.denoiser_input(
                    frame,
                    &rt_temporal::TemporalFrame {
                        frame: &out.noisy,
                        guides: out.guides.as_ref(),
                        extra: &out.extra,
                    },
                );
                self.deliver(&output, frame, FrameImage::Rgb(&out.image), sink)?;
                sink.frame(&FrameReport {
                    scene: self.scene.clone(),
                    frame: Some(out.frame),
                    output,
                    width: out.image.width() as u32,
                    height: out.image.height() as u32,
                    spp: self.settings.spp,
                    technique: self.settings.integrator.to_string(),
                    accel: self.settings.accel.to_string(),
                    accel_name: String::new(),
                    triangles,
                    threads,
                    load: Duration::ZERO,
                    build: out.times.update,
                    stats: out.stats,
                    rendered: Rendered::Sequence {
                        denoiser: denoiser.clone(),
                        times: out.times,
                    },
                    stages: None,
                });
                frames += 1;
                Ok::<_, JobError>(())
            })
        })?;
        Ok(JobReport {
            frames,
            elapsed: started.elapsed(),
            temporal: true,
        })
    }
}
