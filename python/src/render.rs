//! `Scene.render`: the keyword arguments become an `rt_session::RenderJob` (as `render`'s flags
//! do in cli/src/render.rs), which runs over the scene in memory on a thread of its own while
//! the calling thread, without the GIL held most of the time, reports progress to the callback
//! and checks for signals. The job hands its images to the sink instead of writing files
//! (`rt_session::Delivery::Sink`): each is the channels the CLI's EXR holds, made by the same
//! code that the EXR writer consumes, so the image and AOVs are the CLI's, bit for bit,
//! whatever the job's output path (plain film, denoiser, GREE composite, a temporally denoised
//! sequence, the stopping criterion's block map) made of them.
//!
//! Ctrl-C: Python's handler only runs when the main thread asks (`check_signals`); when it
//! raises, the job's stop flag is set and the render, made interruptible, ends after the pass
//! running (`RenderJob::interruptible`, passes of one sample per pixel) and the exception
//! propagates.

use crate::arrays::frame_to_dict;
use crate::input::{input_to_dict, Input};
use crate::scene::Scene;
use crate::{rt_err, value_err};
use pyo3::prelude::*;
use rt_film::ExrImage;
use rt_session::{Delivery, JobScene, JobSink, Overrides, RenderJob, StopRule, MAX_SPP};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

/// How often the waiting thread takes the GIL to check signals and report progress.
const POLL: Duration = Duration::from_millis(50);

/// The keyword arguments of `Scene.render`.
pub struct RenderArgs {
    pub spp: Option<u32>,
    pub integrator: Option<String>,
    pub accel: Option<String>,
    pub seed: Option<u64>,
    pub error: Option<f32>,
    pub time_limit: Option<f64>,
    pub aovs: Option<Vec<String>>,
    pub threads: Option<usize>,
    pub denoiser: Option<String>,
    pub camera: Option<String>,
    pub max_depth: Option<u32>,
    pub size: Option<(u32, u32)>,
    /// Frames `a..b` of the animation (one frame dict each; a temporal denoiser carries its
    /// history across them).
    pub frames: Option<std::ops::Range<u32>>,
    /// One frame of the animation.
    pub frame: Option<u32>,
    /// GREE's options (`""`: the defaults) instead of a denoiser, with its bank file.
    pub gree: Option<String>,
    pub bank: Option<std::path::PathBuf>,
    /// Hand over what the denoiser read with each frame (`"input"`, `input.rs`).
    pub inputs: bool,
}

/// The job `args` describe over `scene`, handing its images to the sink.
fn job(scene: &Scene, args: &RenderArgs) -> PyResult<RenderJob> {
    let path = scene.job_path();
    let integrator = args
        .integrator
        .as_ref()
        .map(|s| {
            s.parse()
                .map_err(|e| rt_err(format!("integrator={s}: {e}")))
        })
        .transpose()?;
    let accel = args
        .accel
        .as_ref()
        .map(|s| s.parse().map_err(|e| rt_err(format!("accel={s}: {e}"))))
        .transpose()?;
    let settings = Overrides {
        integrator,
        max_depth: args.max_depth,
        ao_distance: None,
        spp: args.spp,
        threads: args.threads,
        seed: args.seed,
        accel,
        aovs: args.aovs.clone(),
        output: None,
        // GREE chooses among its own bank, as `render --gree` does.
        denoiser: if args.gree.is_some() {
            if args.denoiser.is_some() {
                return Err(value_err(
                    "denoiser and gree cannot be combined: GREE is the denoiser",
                ));
            }
            Some("none".into())
        } else {
            args.denoiser.clone()
        },
    }
    .resolve(&scene.loaded, path)
    .map_err(rt_err)?;
    let mut job = RenderJob::new(path, settings);
    job.camera = args.camera.clone();
    job.frames = match (&args.frames, args.frame) {
        (Some(_), Some(_)) => return Err(value_err("give frames or frame, not both")),
        (Some(r), None) => rt_session::Frames::Range(r.clone()),
        (None, Some(f)) => rt_session::Frames::One(f),
        (None, None) => rt_session::Frames::Still,
    };
    if let Some(text) = &args.gree {
        job.gree = Some(rt_session::GreeJob {
            options: text
                .parse()
                .map_err(|e| rt_err(format!("gree={text}: {e}")))?,
            bank: args.bank.clone(),
            labels: None,
            error_maps: None,
        });
    }
    if let Some((w, h)) = args.size {
        job.size = rt_session::ImageSize::Pixels(w, h);
    }
    if args.error.is_some() || args.time_limit.is_some() {
        let cap = args.spp.unwrap_or(MAX_SPP);
        let rule = StopRule::new(args.error, args.time_limit, cap)
            .map_err(|e| rt_err(e.named("error", "time_limit")))?;
        job.stop = Some(rule);
    }
    job.interruptible = true;
    job.delivery = Delivery::Sink;
    job.check().map_err(rt_err)?;
    if args.inputs && (job.settings.denoiser.is_none() || job.gree.is_some()) {
        return Err(value_err(
            "inputs=True hands over what the denoiser read, and this render has no denoiser (GREE's input is its own bank's renders)",
        ));
    }
    Ok(job)
}

/// What the job reports, kept for the waiting thread.
#[derive(Default)]
struct Sink {
    /// The fraction done, as `f64` bits.
    done: AtomicU64,
    warnings: Mutex<Vec<String>>,
    /// The frames' images, in the order rendered.
    images: PerFrame<ExrImage>,
    /// What the denoiser read for each frame, when asked for (`inputs=True`).
    inputs: Option<PerFrame<Input>>,
}

/// What the job hands over for each frame (`None`: a still), in the order rendered.
type PerFrame<T> = Mutex<Vec<(Option<u32>, T)>>;

impl JobSink for Sink {
    fn progress(&self, done: f64) {
        self.done.store(done.to_bits(), Ordering::Relaxed);
    }

    fn warning(&self, text: &str) {
        if let Ok(mut w) = self.warnings.lock() {
            w.push(text.to_string());
        }
    }

    fn image(&self, frame: Option<u32>, image: ExrImage) {
        if let Ok(mut i) = self.images.lock() {
            i.push((frame, image));
        }
    }

    fn denoiser_input(&self, frame: Option<u32>, input: &rt_temporal::TemporalFrame<'_>) {
        if let Some(Ok(mut i)) = self.inputs.as_ref().map(Mutex::lock) {
            i.push((frame, Input::of(input)));
        }
    }
}

/// Renders `scene` as `args` say and returns the frame dict (`arrays.rs`), or with `frames`
/// a list of them.
pub fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    args: &RenderArgs,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    if progress.as_ref().is_some_and(|p| !p.is_callable()) {
        return Err(value_err(
            "progress: expected a callable taking the fraction done",
        ));
    }
    let job = job(scene, args)?;
    let loaded = JobScene {
        loaded: rt_scene::LoadedScene {
            scene: scene.loaded.scene.clone(),
            render: scene.loaded.render.clone(),
            warnings: Vec::new(),
        },
        access: scene.access.clone(),
    };
    let sink = Sink {
        inputs: args.inputs.then(Mutex::default),
        ..Sink::default()
    };
    let stop = AtomicBool::new(false);
    let progress = progress.map(Bound::unbind);
    // The first Python error raised while waiting (KeyboardInterrupt, the callback's).
    let mut raised: Option<PyErr> = None;
    let result = py.detach(|| {
        std::thread::scope(|s| {
            let (done_tx, done_rx) = mpsc::channel();
            let (job, sink, stop) = (&job, &sink, &stop);
            s.spawn(move || {
                let r = job.run_loaded(loaded, Duration::ZERO, sink, stop);
                let _ = done_tx.send(r);
            });
            let mut reported = f64::NAN;
            loop {
                match done_rx.recv_timeout(POLL) {
                    Ok(r) => return Some(r),
                    Err(mpsc::RecvTimeoutError::Disconnected) => return None,
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                }
                if raised.is_some() {
                    continue;
                }
                let done = f64::from_bits(sink.done.load(Ordering::Relaxed));
                Python::attach(|py| {
                    let mut check = py.check_signals();
                    if let (Ok(()), Some(cb)) = (&check, &progress) {
                        if done != reported {
                            reported = done;
                            check = cb.call1(py, (done,)).map(drop);
                        }
                    }
                    if let Err(e) = check {
                        raised = Some(e);
                        stop.store(true, Ordering::Relaxed);
                    }
                });
            }
        })
    });
    if let Some(e) = raised {
        return Err(e);
    }
    let warnings = sink.warnings.into_inner().unwrap_or_default();
    if !warnings.is_empty() {
        let warn = py.import("warnings")?;
        for w in warnings {
            warn.call_method1("warn", (w,))?;
        }
    }
    match result {
        Some(Ok(_report)) => {}
        Some(Err(e)) => return Err(rt_err(e)),
        None => return Err(rt_err("the render thread ended without a result")),
    }
    if let Some(cb) = &progress {
        cb.call1(py, (1.0,))?;
    }
    let images = sink.images.into_inner().unwrap_or_default();
    let rendered: Vec<Option<u32>> = images.iter().map(|(f, _)| *f).collect();
    let expected: Vec<Option<u32>> = match (&args.frames, args.frame) {
        (Some(r), _) => r.clone().map(Some).collect(),
        (None, f) => vec![f],
    };
    if rendered != expected {
        return Err(rt_err(format!(
            "the render handed over frames {rendered:?}, not {expected:?}"
        )));
    }
    let mut dicts = images
        .into_iter()
        .map(|(_, exr)| frame_to_dict(py, exr))
        .collect::<PyResult<Vec<_>>>()?;
    if let Some(inputs) = sink.inputs {
        let inputs = inputs.into_inner().unwrap_or_default();
        let handed: Vec<Option<u32>> = inputs.iter().map(|(f, _)| *f).collect();
        if handed != expected {
            return Err(rt_err(format!(
                "the render handed over denoiser inputs of frames {handed:?}, not {expected:?}"
            )));
        }
        for (d, (_, input)) in dicts.iter().zip(&inputs) {
            d.set_item("input", input_to_dict(py, input)?)?;
        }
    }
    match dicts.pop() {
        Some(one) if args.frames.is_none() => Ok(one.into_any()),
        last => {
            dicts.extend(last);
            Ok(pyo3::types::PyList::new(py, dicts)?.into_any())
        }
    }
}
