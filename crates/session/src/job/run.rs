//! Running a job: one image per frame of its frame loop ([`RenderJob::each_frame`]), fixed,
//! adaptive or checkpointed, and its outputs (image, denoised image, part file, GREE
//! composite); temporally denoised sequences go to `sequence.rs`.

use super::parts::{denoise_film, Checkpointer, Cut};
use super::report::{AdaptiveSummary, FrameReport, GreeSummary, JobReport, JobSink, Rendered};
use super::{load_scene, refuse, Delivery, Frames, JobError, JobScene, RenderJob};
use crate::frames::frame_path;
use crate::memory::Estimate;
use crate::{pick_camera, render_adaptive_until, Adaptive, RenderReport, ReportInputs};
use rt_core::{Accel, Camera, RgbImage, Scene};
use rt_film::{AovSet, ExrImage, Film, FilmBuffers, LateSums, OutputOptions};
use rt_integrators::{Ctx, RadianceCache, RenderStats, SamplePass, Technique};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// About how long a pass of an interruptible render lasts ([`RenderJob::interruptible`]):
/// how long stopping it may wait. Every pass costs a little (the wavefront's batches are
/// filled and drained, threads wait for the last band): on the default scene at 16 spp on one
/// thread, passes of one sample per pixel cost 3–4 % more CPU time than one pass, and
/// quarter-second passes made a render from Python 5 % dearer than the CLI's
/// (docs/benchmarks.md, "The Python module").
pub const INTERRUPTIBLE_PASS: Duration = Duration::from_secs(1);

/// A rayon pool of `threads` workers (all cores by default), the one every render and
/// benchmark uses.
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, JobError> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        let max = rt_core::limits::MAX_THREADS;
        if t == 0 || t > max {
            return refuse(format!("--threads must be between 1 and {max}, got {t}"));
        }
        pool = pool.num_threads(t);
    }
    pool.build()
        .map_err(|e| JobError::Failed(format!("cannot start worker threads: {e}")))
}

/// One frame's scene, structure and timings, as the image render needs them.
struct FrameEnv<'a> {
    scene: &'a Scene,
    accel: &'a dyn Accel,
    frame: Option<u32>,
    output: PathBuf,
    seed: u32,
    load: Duration,
    build: Duration,
    threads: usize,
    scene_hash: Option<&'a str>,
}

impl RenderJob {
    /// Loads the scene and runs the job: every frame rendered and written, each reported to
    /// `sink`. A checkpointed render stops at the next pass after `stop` is set, writes its
    /// checkpoint and its image so far, and returns [`JobError::Interrupted`].
    pub fn run(&self, sink: &dyn JobSink, stop: &AtomicBool) -> Result<JobReport, JobError> {
        self.check()?;
        let t = Instant::now();
        let scene = load_scene(&self.scene, self.confine.as_deref(), &self.defines)?;
        for w in &scene.loaded.warnings {
            sink.warning(w);
        }
        self.run_loaded(scene, t.elapsed(), sink, stop)
    }

    /// [`RenderJob::run`] with the scene already loaded ([`load_scene`]; its warnings are
    /// the caller's to show), `load` long.
    pub fn run_loaded(
        &self,
        scene: JobScene,
        load: Duration,
        sink: &dyn JobSink,
        stop: &AtomicBool,
    ) -> Result<JobReport, JobError> {
        self.check()?;
        // A part or a checkpoint names the scene's content; nothing else reads the files twice.
        let scene_hash = (self.writes_part() || self.checkpoint.is_some()).then(|| {
            rt_parts::content_hash(&scene.access.files_used(), &self.scene.to_string_lossy())
        });
        let mut scene = scene.loaded.scene;
        self.set_shutter(&mut scene)?;
        self.check_filter(&scene)?;
        self.check_lights(&scene)?;
        self.check_memory(&scene)?;
        if self.temporal().is_some() {
            if self.writes_part() {
                return refuse(format!(
                    "{}: a part file cannot hold a temporally denoised sequence: its history carries from frame to frame; render the frames' parts without it",
                    self.output.display()
                ));
            }
            return self.run_sequence(&mut scene, sink);
        }
        let pool = thread_pool(self.settings.threads)?;
        // One cache for the whole job: it persists across passes and frames.
        let cache =
            crate::worldcache::for_job(self.cache.as_ref(), &self.settings.integrator, &scene)?;
        let started = Instant::now();
        let threads = pool.current_num_threads();
        let mut frames = 0;
        self.each_frame(&mut scene, &mut |at| {
            if let Some(e) = at.scene().motion_blur_error() {
                return refuse(format!("{}: --shutter: {e}", self.scene.display()));
            }
            let (frame, seed) = (at.frame, at.seed);
            let output = frame.map_or_else(|| self.output.clone(), |f| frame_path(&self.output, f));
            let t_build = Instant::now();
            let ctx = pool.install(|| at.ctx())?;
            let env = FrameEnv {
                scene: ctx.scene,
                accel: ctx.accel,
                frame,
                output,
                seed,
                load,
                build: t_build.elapsed(),
                threads,
                scene_hash: scene_hash.as_deref(),
            };
            frames += 1;
            pool.install(|| self.render_frame(&env, cache.clone(), sink, stop))
        })?;
        Ok(JobReport {
            frames,
            elapsed: started.elapsed(),
            temporal: false,
        })
    }

    /// The frames to render: `None` for a still (the scene at time 0).
    pub(super) fn frame_list(&self) -> Vec<Option<u32>> {
        match &self.frames {
            Frames::Still => vec![None],
            Frames::One(f) => vec![Some(*f)],
            Frames::Range(r) => r.clone().map(Some).collect(),
        }
    }

    /// The camera of the job (resized), in `scene` as it is now.
    pub(super) fn camera_in(&self, scene: &Scene) -> Result<Camera, JobError> {
        let c = pick_camera(scene, &self.scene, self.camera.as_deref())?;
        Ok(self.size.apply(c))
    }

    /// The single-frame denoiser, built (`None` without one, or with a temporal one).
    pub fn frame_denoiser(&self) -> Result<Option<Box<dyn rt_denoise::Denoiser>>, JobError> {
        match &self.settings.denoiser {
            Some(rt_temporal::TemporalSpec::PerFrame(spec)) => spec
                .build()
                .map(Some)
                .map_err(|e| JobError::Refused(format!("--denoiser {spec}: {e}"))),
            _ => Ok(None),
        }
    }

    /// The film buffers a render keeps: only what its outputs and its denoiser read, no
    /// variance or half-buffers unless asked for; the stopping criterion reads the even
    /// samples' half.
    pub fn film_buffers(&self, denoiser: Option<&dyn rt_denoise::Denoiser>) -> FilmBuffers {
        let denoise_aovs = denoiser.map_or(AovSet::default(), |d| AovSet::for_channels(d.needs()));
        let buffers = FilmBuffers::for_outputs(self.settings.aovs.union(denoise_aovs));
        if self.stop.is_some_and(|s| s.error.is_some()) {
            buffers.with_halves()
        } else {
            buffers
        }
    }

    /// Refuses a pixel filter wider than the box with a technique that splats: its light
    /// paths land where they land, so only camera samples can be placed by the filter. A
    /// filter the film splats ([`rt_core::pixel_filter`]) keeps only the image and its
    /// half-images, whose pixels share samples: it refuses what needs more (the other
    /// buffers, a denoiser, which assumes independent pixel noise) or a region, whose samples
    /// would splat past its border.
    fn check_filter(&self, scene: &Scene) -> Result<(), JobError> {
        let camera = self.camera_in(scene)?;
        if camera.filter.splats() {
            let b = self.film_buffers(None);
            let a = b.aovs;
            let what = if self.settings.denoiser.is_some() {
                Some("a denoiser (it assumes independent pixel noise)".to_string())
            } else if b.variance || a.any_first_hit() || a.any_split() || b.samples {
                Some(format!("--aov {}", a.names().join(",")))
            } else if self.slice.region.is_some() {
                Some("--region (its samples would splat past its border)".to_string())
            } else {
                None
            };
            if let Some(what) = what {
                return Err(JobError::Refused(format!(
                    "{}: camera \"{}\" splats its pixel filter ({}), which keeps only the image \
                     and its half-images; {what} needs the filter importance-sampled (drop `:splat`)",
                    self.scene.display(),
                    camera.name,
                    camera.filter,
                )));
            }
        }
        if camera.filter == rt_core::pixel_filter::PixelFilter::Box
            || !self.settings.integrator.build().splats()
        {
            return Ok(());
        }
        Err(JobError::Refused(format!(
            "{}: camera \"{}\" has pixel filter {}, which {} cannot apply (it splats light \
             paths onto the image); use a box filter or a camera-ray integrator",
            self.scene.display(),
            camera.name,
            camera.filter,
            self.settings.integrator.kind.name()
        )))
    }

    /// Refuses a scene with delta lights for a technique that cannot render them
    /// ([`rt_integrators::Technique::delta_lights`]).
    fn check_lights(&self, scene: &Scene) -> Result<(), JobError> {
        if scene.delta_lights.is_empty() || self.settings.integrator.build().delta_lights() {
            return Ok(());
        }
        Err(JobError::Refused(format!(
            "{}: the scene has point, spot or directional lights, which {} does not render \
             yet; use path, wavefront, direct, light or bdpt",
            self.scene.display(),
            self.settings.integrator.kind.name()
        )))
    }

    /// Refuses, before the structure and the film are allocated, a render whose estimate
    /// exceeds the job's limit, else the memory available ([`crate::memory`]).
    fn check_memory(&self, scene: &Scene) -> Result<(), JobError> {
        let camera = self.camera_in(scene)?;
        // A temporal denoiser's needs are its own; the plain film is still the floor.
        let denoiser = self.frame_denoiser()?;
        let late = LateSums {
            light_splats: self.settings.integrator.build().splats(),
            filtered: camera.filter.splats(),
        };
        Estimate::new(
            camera.width,
            camera.height,
            self.film_buffers(denoiser.as_deref()),
            self.settings.spp,
            late,
            &self.settings.accel,
            scene.triangle_count(),
        )
        .check(&self.scene.display().to_string(), self.max_memory)
        .map_err(|e| JobError::Refused(e.to_string()))
    }

    /// Opens the scene's shutter for the job's fraction of a frame and checks that the
    /// render can blur what moves: a camera-ray technique, and a structure that places
    /// instances per ray.
    fn set_shutter(&self, scene: &mut Scene) -> Result<(), JobError> {
        if self.shutter == 0.0 {
            return Ok(());
        }
        scene.shutter = (self.shutter / self.fps) as f32;
        let path = self.scene.display();
        let moving_instances = scene.instances.iter().any(|i| i.is_animated());
        if !moving_instances && scene.camera_motions.is_empty() {
            return Ok(());
        }
        let s = &self.settings;
        if !s.integrator.build().motion_blur() {
            return refuse(format!(
                "{path}: --shutter: the {} integrator cannot motion blur (wavefront, path, path-bsdf, direct and ao can)",
                s.integrator
            ));
        }
        if moving_instances && !s.accel.kind.is_two_level() {
            return refuse(format!(
                "{path}: --shutter: --accel {} holds the scene at one time; motion blur needs two-level or clusters",
                s.accel
            ));
        }
        Ok(())
    }

    /// Renders the samples and pixels of `cut` into `film` in one pass.
    pub(super) fn fixed_pass(
        &self,
        ctx: &Ctx<'_>,
        technique: &dyn Technique,
        film: &mut Film,
        seed: u32,
        cut: &Cut,
        sink: &dyn JobSink,
    ) -> RenderStats {
        let (w, h) = (ctx.camera.width, ctx.camera.height);
        let pass = SamplePass {
            indices: cut.samples.clone(),
            stream: self.stream.sample_stream(),
            pixels: cut.mask(w, h),
            centre_first: false,
        };
        let rows = f64::from(h.max(1));
        technique.render_pass(ctx, film, seed, &pass, &|r| {
            sink.progress(f64::from(r) / rows)
        })
    }

    /// Renders one image of the frame `env` and writes it (or its part, or its GREE
    /// composite).
    fn render_frame(
        &self,
        env: &FrameEnv<'_>,
        cache: Option<Arc<dyn RadianceCache>>,
        sink: &dyn JobSink,
        stop: &AtomicBool,
    ) -> Result<(), JobError> {
        let camera = self.camera_in(env.scene)?;
        let technique = crate::worldcache::technique(&self.settings.integrator, cache)?;
        let ctx = Ctx {
            scene: env.scene,
            accel: env.accel,
            camera: &camera,
        };
        let report = |stats: RenderStats, output: PathBuf, rendered: Rendered| FrameReport {
            scene: self.scene.clone(),
            frame: env.frame,
            output,
            width: camera.width,
            height: camera.height,
            spp: self.settings.spp,
            technique: technique.name().to_string(),
            accel: self.settings.accel.to_string(),
            accel_name: env.accel.name().to_string(),
            triangles: env.scene.triangle_count(),
            threads: env.threads,
            load: env.load,
            build: env.build,
            stats,
            rendered,
            stages: None,
        };
        if self.gree.is_some() {
            let (stats, rendered) = self.render_gree(&ctx, technique.as_ref(), env, sink)?;
            sink.frame(&report(stats, env.output.clone(), rendered));
            return Ok(());
        }
        let denoiser = self.frame_denoiser()?;
        if let Some(d) = &denoiser {
            if AovSet::for_channels(d.needs()).any_split() && !technique.writes_split() {
                return refuse(format!(
                    "{}: --denoiser {} reads the lighting split, which the {} technique does not write",
                    self.scene.display(),
                    d.name(),
                    self.settings.integrator
                ));
            }
        }
        let mut film = Film::new(
            camera.width,
            camera.height,
            self.film_buffers(denoiser.as_deref()),
        );
        let cut = self.cut(camera.width, camera.height, &film)?;
        let mut adaptive: Option<Adaptive> = None;
        let mut interrupted = None;
        let stats = match (&self.stop, &self.checkpoint, env.scene_hash) {
            (None, Some(_), Some(scene_hash)) => {
                let ck = Checkpointer {
                    job: self,
                    camera: &camera.name,
                    scene_hash,
                    frame: env.frame,
                };
                let (stats, stopped) = self.render_in_passes(
                    Some(&ck),
                    &ctx,
                    technique.as_ref(),
                    &mut film,
                    env,
                    sink,
                    stop,
                )?;
                interrupted = stopped;
                stats
            }
            (None, None, _) if self.interruptible && cut.is_none() => {
                let (stats, stopped) = self.render_in_passes(
                    None,
                    &ctx,
                    technique.as_ref(),
                    &mut film,
                    env,
                    sink,
                    stop,
                )?;
                if let Some(samples) = stopped {
                    return Err(JobError::Stopped {
                        samples,
                        spp: self.settings.spp,
                    });
                }
                stats
            }
            (None, _, _) => {
                let whole = Cut {
                    samples: 0..self.settings.spp,
                    region: rt_film::Rect::full(camera.width, camera.height),
                };
                let cut = cut.as_ref().unwrap_or(&whole);
                self.fixed_pass(&ctx, technique.as_ref(), &mut film, env.seed, cut, sink)
            }
            (Some(rule), _, _) => {
                // Only an interruptible job listens to `stop` here (a checkpointed one cannot
                // be adaptive).
                let never = AtomicBool::new(false);
                let stop = if self.interruptible { stop } else { &never };
                let a = render_adaptive_until(
                    &ctx,
                    technique.as_ref(),
                    &mut film,
                    env.seed,
                    rule,
                    &|f| sink.progress(f),
                    stop,
                )
                .map_err(|e| JobError::Refused(format!("--error {}", e.0)))?;
                if a.reason == crate::StopReason::Stopped {
                    return Err(JobError::Stopped {
                        samples: a.spp,
                        spp: rule.max_spp,
                    });
                }
                let stats = a.stats;
                adaptive = Some(a);
                stats
            }
        };

        if let (Some(cut), Some(hash)) = (&cut, env.scene_hash) {
            let mut header = self.header(
                &film,
                cut,
                &camera.name,
                hash,
                env.frame,
                rt_parts::PartKind::Part,
            );
            header.seconds = stats.elapsed.as_secs_f64();
            rt_parts::Part {
                header,
                sums: film.encode_sums(cut.region),
            }
            .write(&env.output)
            .map_err(|e| JobError::Failed(format!("{}: {e}", env.output.display())))?;
            let rendered = Rendered::Part {
                samples: cut.samples.clone(),
                region: cut.region,
            };
            sink.frame(&report(stats, env.output.clone(), rendered));
            return Ok(());
        }
        let stages = |film: &Film, write_time| {
            RenderReport::collect(&ReportInputs {
                scene: env.scene,
                camera: &camera,
                accel: env.accel,
                accel_spec: self.settings.accel.to_string(),
                film,
                render: &stats,
                technique: &technique.stages(),
                load_time: env.load,
                accel_time: env.build,
                write_time,
                output: &env.output,
            })
        };
        let (rendered, write_time) = if let Some(d) = &denoiser {
            let t = Instant::now();
            let image = denoise_film(&mut film, d.as_ref(), &self.scene, sink, env.frame)?;
            self.deliver(&env.output, env.frame, FrameImage::Rgb(&image), sink)?;
            let time = t.elapsed();
            let rendered = Rendered::Denoised {
                denoiser: d.name().to_string(),
                time,
            };
            // The denoiser's time stands where the plain image's write would.
            (rendered, time)
        } else {
            let t = Instant::now();
            let extra = match adaptive.as_ref() {
                Some(a) if self.settings.aovs.blocks => block_channels(a, &film),
                _ => Vec::new(),
            };
            self.deliver(
                &env.output,
                env.frame,
                FrameImage::Film(&film, &extra),
                sink,
            )?;
            let rendered = Rendered::Image {
                adaptive: adaptive.as_ref().map(AdaptiveSummary::from),
            };
            (rendered, t.elapsed())
        };
        let mut r = report(stats, env.output.clone(), rendered);
        r.stages = Some(stages(&film, write_time));
        sink.frame(&r);
        self.end_checkpoint(&env.output, interrupted)
    }

    /// Renders the job's samples into `film` pass by pass, writing checkpoints through `ck` if
    /// given; stops early at a pass boundary when `stop` is set (a checkpoint then holds every
    /// finished pass). Returns the samples per pixel taken when stopped. A checkpointed render
    /// takes one sample per pixel a pass (a checkpoint may fall after any); without one a pass
    /// takes as many as fit in about [`INTERRUPTIBLE_PASS`], so that stopping waits for little
    /// and the passes cost little. Passes add up to the bits of one pass either way.
    #[allow(clippy::too_many_arguments)]
    fn render_in_passes(
        &self,
        ck: Option<&Checkpointer<'_>>,
        ctx: &Ctx<'_>,
        technique: &dyn Technique,
        film: &mut Film,
        env: &FrameEnv<'_>,
        sink: &dyn JobSink,
        stop: &AtomicBool,
    ) -> Result<(RenderStats, Option<u32>), JobError> {
        let spp = self.settings.spp;
        let (start, before) = match (&self.resume, ck) {
            (Some(path), Some(ck)) => ck.restore(path, film)?,
            _ => (0, 0.0),
        };
        let every = Duration::from_secs_f64(self.checkpoint.as_ref().map_or(0.0, |c| c.every));
        let mut last = Instant::now();
        let mut stats = RenderStats::default();
        sink.progress(f64::from(start) / f64::from(spp));
        let rows = f64::from(ctx.camera.height.max(1));
        let (mut i, mut n) = (start, 1);
        while i < spp {
            n = n.min(spp - i);
            let pass = SamplePass {
                indices: i..i + n,
                stream: self.stream.sample_stream(),
                pixels: None,
                centre_first: false,
            };
            let s = technique.render_pass(ctx, film, env.seed, &pass, &|r| {
                sink.progress((f64::from(i) + f64::from(n) * f64::from(r) / rows) / f64::from(spp))
            });
            if ck.is_none() {
                let per_sample = s.elapsed.as_secs_f64() / f64::from(n);
                let fit = (INTERRUPTIBLE_PASS.as_secs_f64() / per_sample.max(1e-9)) as u32;
                // A first pass of one sample may mislead (caches are cold): grow at most 4x.
                n = fit.clamp(1, 4 * n);
            }
            stats += s;
            i += pass.indices.len() as u32;
            sink.progress(f64::from(i) / f64::from(spp));
            let seconds = before + stats.elapsed.as_secs_f64();
            if stop.load(Ordering::Relaxed) {
                if let Some(ck) = ck {
                    ck.write(film, i, seconds)?;
                }
                return Ok((stats, Some(i)));
            }
            if let Some(ck) = ck.filter(|_| i < spp && last.elapsed() >= every) {
                ck.write(film, i, seconds)?;
                last = Instant::now();
            }
        }
        Ok((stats, None))
    }

    /// After the image is written: an interrupted render says so and fails; a finished one
    /// removes its checkpoint (everything in it is in the image).
    fn end_checkpoint(
        &self,
        output: &std::path::Path,
        interrupted: Option<u32>,
    ) -> Result<(), JobError> {
        let Some(ck) = &self.checkpoint else {
            return Ok(());
        };
        if let Some(samples) = interrupted {
            return Err(JobError::Interrupted {
                samples,
                spp: self.settings.spp,
                output: output.to_path_buf(),
                checkpoint: ck.path.clone(),
            });
        }
        match std::fs::remove_file(&ck.path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(JobError::Failed(format!(
                "--checkpoint {}: cannot remove it: {e}",
                ck.path.display()
            ))),
            _ => Ok(()),
        }
    }

    /// One image denoised by GREE (`crate::gree`), with its label map and error maps when
    /// asked for.
    fn render_gree(
        &self,
        ctx: &Ctx<'_>,
        technique: &dyn Technique,
        env: &FrameEnv<'_>,
        sink: &dyn JobSink,
    ) -> Result<(RenderStats, Rendered), JobError> {
        let g = self.gree.as_ref().expect("a GREE job");
        let bank = match &g.bank {
            Some(p) => rt_denoise::Bank::from_file(p),
            None => rt_denoise::Bank::default_gree(),
        }
        .map_err(|e| JobError::Refused(e.to_string()))?;
        let run = self.gree_run(ctx, technique, &bank, env.seed, sink)?;
        let failed = |e: rt_film::FilmError| JobError::Failed(e.to_string());
        let composite = FrameImage::Rgb(&run.composite.image);
        self.deliver(&env.output, env.frame, composite, sink)?;
        let names: Vec<&str> = bank.members().iter().map(|m| m.name()).collect();
        if let Some(p) = &g.labels {
            run.write_labels(p).map_err(failed)?;
        }
        if let Some(dir) = &g.error_maps {
            run.write_error_maps(dir, &names).map_err(failed)?;
        }
        let summary = GreeSummary::of(&run, &names, g.labels.is_some());
        Ok((run.render, Rendered::Gree(Box::new(summary))))
    }
}

/// What a frame's output holds.
pub(super) enum FrameImage<'a> {
    /// The film: its beauty image and AOVs, with further channels (the `blocks` AOV).
    Film(&'a Film, &'a [(&'static str, Vec<f32>)]),
    /// A finished image: denoised, GREE's composite, a frame of a temporally denoised sequence.
    Rgb(&'a RgbImage),
}

impl RenderJob {
    /// Hands the image of `frame` to where the job's images go ([`Delivery`]): the file
    /// `output` (EXR or PNG by its extension) or the sink, as the channels the EXR would hold.
    /// Both go through [`ExrImage`], so the sink's channels are the file's bits.
    pub(super) fn deliver(
        &self,
        output: &Path,
        frame: Option<u32>,
        image: FrameImage<'_>,
        sink: &dyn JobSink,
    ) -> Result<(), JobError> {
        let opts = OutputOptions {
            exposure: self.exposure,
        };
        let written = match (self.delivery, image) {
            (Delivery::Files, FrameImage::Film(film, extra)) => {
                rt_film::write_image_with(output, film, &opts, extra)
            }
            (Delivery::Files, FrameImage::Rgb(image)) => rt_film::write_rgb(output, image, &opts),
            (Delivery::Sink, FrameImage::Film(film, extra)) => {
                sink.image(
                    frame,
                    ExrImage::of_film(film, extra).map_err(JobError::Failed)?,
                );
                Ok(())
            }
            (Delivery::Sink, FrameImage::Rgb(image)) => {
                sink.image(frame, ExrImage::of_rgb(image));
                Ok(())
            }
        };
        written.map_err(|e| JobError::Failed(e.to_string()))
    }
}

/// The `blocks` AOV: each pixel's final block (`blocks.index`), its sample count
/// (`blocks.spp`; light-path techniques sample every pixel alike, so it is the passes' samples
/// per pixel) and whether its block met the threshold (`blocks.converged`, 0 or 1).
fn block_channels(a: &Adaptive, film: &Film) -> Vec<(&'static str, Vec<f32>)> {
    let Some(map) = a.block_map(film.width(), film.height()) else {
        return Vec::new();
    };
    let spp: Vec<f32> = if film.light_paths() > 0 {
        vec![a.spp as f32; map.index.len()]
    } else {
        film.pixels().map(|p| p.count() as f32).collect()
    };
    vec![
        (
            "blocks.index",
            map.index.iter().map(|&i| i as f32).collect(),
        ),
        ("blocks.spp", spp),
        (
            "blocks.converged",
            map.converged
                .iter()
                .map(|&c| f32::from(u8::from(c)))
                .collect(),
        ),
    ]
}
