//! Sequence experiments: every scene is an animation (`frames = [A, B]`), every method runs
//! one job per scene ([`crate::config::Pair::sequence_job`]) whose frames render in order
//! through one [`rt_session::SequenceRenderer`] ([`rt_session::RenderJob::render_sequence`]),
//! so a temporal denoiser (SVGF) keeps its history, and each frame is measured against its
//! own reference frame. The temporal metrics (temporal error, temporal relMSE, lag after an
//! event) are `rt_metrics::temporal`'s, streamed through [`SequenceComparison`].
//!
//! References: a job over the scene's frames in the reference stream walks them
//! ([`rt_session::RenderJob::each_frame`]: the scene, its structure and the camera at each
//! frame's time), and frame `f`'s reference is a still reference job of the scene at that
//! time ([`crate::reference::obtain`]), at the reference's spp, through the [`Cache`], keyed
//! like any reference by the scene's content and the camera, which both change with the
//! frame's time ([`rt_core::Scene::set_time`] writes the time into the scene), so every frame
//! is its own entry. Every frame's reference uses the same seed: where nothing moved between
//! two frames their references have the same noise, so the reference's frame differences are
//! nearly noise-free there.

use crate::cache::{Cache, ReferenceRequest};
use crate::config::{Plan, ReferencePlan, Runs, SequencePlan};
use crate::error::{io, ExperimentError, Result};
use crate::Progress;
use rt_core::RgbImage;
use rt_integrators::GuideOptions;
use rt_metrics::temporal::{
    lag, luminance_change_in, LagOptions, SequenceComparison, TemporalError,
};
use rt_metrics::{CompareOptions, Metrics};
use rt_session::{FrameTimes, SequenceFrame, Settings, Stream};
use std::path::{Path, PathBuf};

/// The lag's steady state is the median of at most this many frames before the event.
pub const LAG_WINDOW: usize = 10;

/// The lag's threshold: back within this factor of the steady state.
pub const LAG_FACTOR: f64 = 2.0;

/// One frame of one method on one scene: a row of frames.csv.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameRow {
    /// Index into the plan's pairs.
    pub pair: usize,
    /// Frame number.
    pub frame: u32,
    /// The frame (denoised, if the method denoises) against its reference frame.
    pub metrics: Metrics,
    /// Stage times of the frame.
    pub times: FrameTimes,
}

/// One method on one scene over all its frames: a row of sequences.csv.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceRow {
    /// Index into the plan's pairs.
    pub pair: usize,
    /// Frames rendered.
    pub frames: usize,
    /// Mean absolute luminance change between consecutive frames of the method's images.
    pub temporal_error: f64,
    /// The same of the reference frames (what the scene itself changes).
    pub reference_temporal_error: f64,
    /// The temporal error over the specular pixels only (primary roughness below SVGF's
    /// specular limit in the frame's guide buffers, the same for every method): where
    /// reflection reprojection acts. `None` when no frame shows a specular surface.
    pub temporal_error_specular: Option<f64>,
    /// Mean relMSE of the method's frame differences against the reference's.
    pub temporal_relmse: f64,
    /// Frames after the scene's event until the per-frame relMSE is back within
    /// [`LAG_FACTOR`] × its steady state; `None` without an event or if it never is.
    pub lag: Option<usize>,
    /// The lag's steady state (median relMSE before the event), when there is an event.
    pub steady_relmse: Option<f64>,
    /// Mean of the per-frame relMSE.
    pub mean_relmse: f64,
    /// The last frame's relMSE.
    pub last_relmse: f64,
    /// Mean wall time per frame in milliseconds (update, render, guides, denoise).
    pub ms_per_frame: f64,
}

/// A picture written for the report: a frame of a method (or of the reference).
#[derive(Clone, Debug, PartialEq)]
pub struct Still {
    /// Index into the plan's scenes.
    pub scene: usize,
    /// The method's name, or `reference`.
    pub method: String,
    /// Frame number.
    pub frame: u32,
    /// The PNG, relative to the output folder, with `/` separators.
    pub file: String,
    /// The same frame as linear EXR (the data the PNG shows), relative to the output folder.
    pub exr: String,
}

/// Everything a sequence experiment measured.
pub struct SequenceResults {
    /// Per scene: where its references came from.
    pub reference_origins: Vec<String>,
    /// Every frame of every pair, pair-major, frames in order.
    pub frames: Vec<FrameRow>,
    /// One per pair, in pair order.
    pub sequences: Vec<SequenceRow>,
    /// First, middle and last frames of every method and of the references.
    pub stills: Vec<Still>,
}

impl SequenceResults {
    /// The frame rows of one pair.
    pub fn frames_of(&self, pair: usize) -> impl Iterator<Item = &FrameRow> {
        self.frames.iter().filter(move |r| r.pair == pair)
    }
}

/// The frames whose images are kept: the first, the middle and the last.
pub fn still_frames(seq: &SequencePlan) -> Vec<u32> {
    let (a, b) = (seq.frames.start, seq.frames.end);
    let mut v = vec![a, a + (b - a) / 2, b - 1];
    v.dedup();
    v
}

fn slash(p: &Path) -> String {
    p.to_string_lossy().replace('\\', "/")
}

fn run_error(what: impl std::fmt::Display) -> ExperimentError {
    ExperimentError::Run(what.to_string())
}

/// Writes frame `f` of `method` as `<dir>/<method>-f<frame>.png` (tone mapped like `render -o
/// x.png`) and `.exr`.
fn write_still(
    out: &Path,
    dir: &Path,
    scene: usize,
    method: &str,
    f: u32,
    image: &RgbImage,
) -> Result<Still> {
    let png = dir.join(format!("{method}-f{f:04}.png"));
    let exr = png.with_extension("exr");
    rt_film::write_rgb(&out.join(&png), image, &Default::default())?;
    rt_film::write_rgb(&out.join(&exr), image, &Default::default())?;
    Ok(Still {
        scene,
        method: method.to_string(),
        frame: f,
        file: slash(&png),
        exr: slash(&exr),
    })
}

/// Runs a sequence plan, writing stills under `out/images`. Call inside the thread pool that
/// should do the work.
pub fn run(
    plan: &Plan,
    out: &Path,
    cache: &Cache,
    progress: &dyn Progress,
) -> Result<SequenceResults> {
    let opts = CompareOptions {
        epsilon: plan.epsilon,
        peak: rt_metrics::DEFAULT_PEAK,
    };
    let seq_of = |si: usize| {
        plan.scenes[si]
            .sequence
            .as_ref()
            .ok_or_else(|| run_error(format!("{}: not a sequence", plan.scenes[si].name)))
    };
    // Progress in frames: every scene's references, then every pair's frames.
    let mut total = 0u64;
    for (si, _) in plan.scenes.iter().enumerate() {
        total += seq_of(si)?.len() as u64;
    }
    for p in &plan.pairs {
        total += seq_of(p.scene)?.len() as u64;
    }
    progress.set_length(total);
    let mut done = 0u64;

    let mut results = SequenceResults {
        reference_origins: Vec::new(),
        frames: Vec::new(),
        sequences: Vec::new(),
        stills: Vec::new(),
    };
    for (si, scene) in plan.scenes.iter().enumerate() {
        let seq = seq_of(si)?;
        let dir: PathBuf = ["images", &scene.name].iter().collect();
        std::fs::create_dir_all(out.join(&dir)).map_err(io(&out.join(&dir)))?;
        let stills = still_frames(seq);
        progress.set_message(format!("{}: references", scene.name));
        let (references, origin) = references(plan, si, seq, cache, progress, &mut done)?;
        for &f in &stills {
            results.stills.push(write_still(
                out,
                &dir,
                si,
                "reference",
                f,
                &references[(f - seq.frames.start) as usize],
            )?);
        }
        results.reference_origins.push(origin);

        for (pi, pair) in plan.pairs.iter().enumerate() {
            if pair.scene != si {
                continue;
            }
            let method = &plan.methods[pair.method];
            let Runs::Sequence { spp } = method.runs else {
                return Err(run_error(format!("{}: not a sequence method", method.name)));
            };
            let at = |e: &dyn std::fmt::Display| {
                run_error(format!("{}: {}: {e}", scene.name, method.name))
            };
            progress.set_message(format!("{}: {}", scene.name, method.name));
            let job = pair.sequence_job(scene, method, seq, spp);
            let mut renderer = job
                .sequence_renderer(&scene.loaded.scene)
                .map_err(|e| at(&e))?;
            renderer.set_guides(true);
            let mut moving = scene.loaded.scene.clone();
            let mut specular = SpecularFlicker::default();
            let mut comparison = SequenceComparison::new(opts).map_err(|e| at(&e))?;
            let mut total_ms = 0.0;
            job.render_sequence(&mut renderer, &mut moving, &mut |frame| -> Result<()> {
                let f = frame.frame;
                if stills.contains(&f) {
                    results
                        .stills
                        .push(write_still(out, &dir, si, &method.name, f, &frame.image)?);
                }
                specular
                    .push(frame)
                    .map_err(|e| at(&format!("frame {f}: {e}")))?;
                let reference = references[(f - seq.frames.start) as usize].clone();
                let measured = comparison
                    .push(frame.image.clone(), reference)
                    .map_err(|e| at(&format!("frame {f}: {e}")))?;
                total_ms += frame.times.total().as_secs_f64() * 1e3;
                results.frames.push(FrameRow {
                    pair: pi,
                    frame: f,
                    metrics: measured.metrics,
                    times: frame.times,
                });
                done += 1;
                progress.set_position(done);
                Ok(())
            })?;
            let m = comparison.finish().map_err(|e| at(&e))?;
            let relmse = m.per_frame(|m| m.relmse);
            let (lag_frames, steady) = match seq.event {
                None => (None, None),
                Some(event) => {
                    let index = (event - seq.frames.start) as usize;
                    let l = lag(
                        &relmse,
                        index,
                        &LagOptions {
                            factor: LAG_FACTOR,
                            window: index.min(LAG_WINDOW),
                        },
                    )
                    .map_err(|e| at(&format!("lag: {e}")))?;
                    (l.frames, Some(l.steady_state))
                }
            };
            results.sequences.push(SequenceRow {
                pair: pi,
                frames: relmse.len(),
                temporal_error: m.temporal_error_test.mean,
                reference_temporal_error: m.temporal_error_reference.mean,
                temporal_error_specular: specular.mean(),
                temporal_relmse: m.temporal_relmse.mean,
                lag: lag_frames,
                steady_relmse: steady,
                mean_relmse: m.mean(|m| m.relmse),
                last_relmse: relmse.last().copied().unwrap_or(f64::NAN),
                ms_per_frame: total_ms / relmse.len().max(1) as f64,
            });
        }
    }
    Ok(results)
}

/// The temporal error over each step's specular pixels, accumulated frame by frame.
#[derive(Default)]
struct SpecularFlicker {
    previous: Option<RgbImage>,
    sum: f64,
    steps: usize,
}

impl SpecularFlicker {
    fn push(&mut self, frame: &SequenceFrame) -> std::result::Result<(), TemporalError> {
        if let (Some(previous), Some(g)) = (&self.previous, &frame.guides) {
            let limit = GuideOptions::default().specular_limit;
            let mask: Vec<bool> = (0..g.roughness.pixels().len())
                .map(|i| g.has_surface(i) && g.roughness.pixels()[i] < limit)
                .collect();
            if let Some(v) = luminance_change_in(previous, &frame.image, &mask)? {
                self.sum += v;
                self.steps += 1;
            }
        }
        self.previous = Some(frame.image.clone());
        Ok(())
    }

    fn mean(&self) -> Option<f64> {
        (self.steps > 0).then(|| self.sum / self.steps as f64)
    }
}

/// Every frame's reference of scene `si`, from the cache or rendered into it, and a line on
/// where they came from.
fn references(
    plan: &Plan,
    si: usize,
    seq: &SequencePlan,
    cache: &Cache,
    progress: &dyn Progress,
    done: &mut u64,
) -> Result<(Vec<RgbImage>, String)> {
    let scene = &plan.scenes[si];
    let ReferencePlan::Render {
        spp,
        estimator,
        seed,
        accel,
    } = &scene.reference
    else {
        return Err(run_error(format!(
            "{}: a sequence's references are rendered frame by frame",
            scene.name
        )));
    };
    // Only the walk over the frames: each frame's reference is a still job of its own, every
    // frame's from the same seed.
    let mut walk = seq.job(
        scene,
        Settings {
            integrator: *estimator,
            accel: *accel,
            spp: *spp,
            threads: None,
            seed: *seed,
            aovs: Default::default(),
            output: None,
            denoiser: None,
        },
    );
    walk.stream = Stream::Reference;
    let mut moving = scene.loaded.scene.clone();
    let mut images = Vec::with_capacity(seq.len());
    let (mut cached, mut rendered, mut seconds) = (0usize, 0usize, 0.0f64);
    walk.each_frame(&mut moving, &mut |at| -> Result<()> {
        let key = ReferenceRequest {
            scene: at.scene(),
            camera: &at.camera,
            ..scene.reference_request(*estimator, *spp, *seed)
        }
        .key()?;
        let path = match cache.lookup(&scene.path, &key) {
            Some((path, sidecar)) => {
                cached += 1;
                seconds += sidecar.seconds;
                path
            }
            None => {
                // Built in the scene's order: the next frame's key hashes the scene again.
                let ctx = at.ctx_in_order()?;
                let base = *done;
                let got = crate::reference::obtain(
                    &ReferenceRequest {
                        scene: ctx.scene,
                        camera: ctx.camera,
                        ..scene.reference_request(*estimator, *spp, *seed)
                    },
                    (accel, ctx.accel),
                    Some(cache),
                    None,
                    &|_| progress.set_position(base),
                )?;
                rendered += 1;
                seconds += got.seconds;
                got.path
            }
        };
        images.push(rt_film::read_rgb(&path)?);
        *done += 1;
        progress.set_position(*done);
        Ok(())
    })?;
    let origin = format!(
        "{} frames at {spp} spp: {rendered} rendered, {cached} from the cache ({seconds:.1} s of rendering)",
        seq.len()
    );
    progress.message(&format!("{}: references: {origin}", scene.name));
    Ok((images, origin))
}
