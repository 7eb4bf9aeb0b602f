//! A render as one typed, serialisable value: [`RenderJob`], the scene, its resolved
//! [`Settings`], the frames, the slice (sample range and region) a part holds, the stop rule,
//! checkpointing, the outputs, the denoiser (single-frame, temporal or GREE) and the
//! world-space cache. [`RenderJob::run`] loads the scene and renders every frame, reporting to
//! a [`JobSink`] and stopping at a pass boundary when its stop flag is set.
//!
//! `render` builds a job from its flags and runs it; `render part` runs a job from a plan with
//! the part's slice; `render --resume` runs the job a checkpoint holds; `render reference` and
//! an experiment's references run reference jobs ([`Stream::Reference`]), and an experiment's
//! methods run jobs that hand it the film at each budget ([`RenderJob::render_stops`]). Plans and
//! checkpoints store the job as JSON with a format version ([`RenderJob::to_json`],
//! [`RenderJob::from_json`]); a file written by another format is refused with one line.
//!
//! The render loop: per frame the scene moves to the frame's time and the structure follows
//! (updated in place when it can, rebuilt otherwise); the image is rendered in one pass, in
//! passes of one sample per pixel (checkpointing), or until the stop rule says (adaptive);
//! then it is written as an image, a denoised image or a part file, or handed to the sink
//! as the channels its EXR would hold ([`Delivery::Sink`]). Passes add up to the bits
//! of one pass, and the film's sums are exact, so a part, a checkpoint or a resumed render
//! merges to the very bytes of the whole render.

mod each_frame;
mod gree;
mod parts;
mod report;
mod run;
mod sequence;
mod stops;

pub use each_frame::JobFrame;
pub use parts::{merge, read_parts, MergeReport};
pub use report::{AdaptiveSummary, FrameReport, GreeSummary, JobReport, JobSink, Rendered};
pub use run::{thread_pool, INTERRUPTIBLE_PASS};
pub use stops::FilmStop;

use crate::text;
use crate::{ImageSize, SessionError, Settings, SettingsError, StopRule};
use rt_film::Rect;
use rt_scene::{FileAccess, LoadedScene};
use rt_temporal::TemporalSpec;
use rt_worldcache::CacheSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Version of a job's JSON ([`RenderJob::to_json`]): plans and checkpoints of another
/// version are refused.
pub const JOB_FORMAT: u32 = 1;

/// Frames per second when nothing says.
pub const DEFAULT_FPS: f64 = 24.0;

/// Which frames of the scene's animation to render.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Frames {
    /// The scene at time 0, not a frame of a sequence.
    #[default]
    Still,
    /// One frame (time `f / fps`).
    One(u32),
    /// Frames `a..b`, each written to the output pattern's file for it.
    Range(Range<u32>),
}

/// The random streams a job draws from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stream {
    /// Those of a normal render.
    #[default]
    Render,
    /// The reference family, independent of any normal render's
    /// ([`rt_core::SampleStream::Reference`]).
    Reference,
}

impl Stream {
    /// The sampler's stream.
    pub fn sample_stream(self) -> rt_core::SampleStream {
        match self {
            Stream::Render => rt_core::SampleStream::Render,
            Stream::Reference => rt_core::SampleStream::Reference,
        }
    }
}

/// Where a job's images go.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Delivery {
    /// To the job's output: image files (a pattern naming the frame for a sequence) or part
    /// files.
    #[default]
    Files,
    /// To the sink ([`JobSink::image`]), each the channels an EXR output would hold
    /// ([`rt_film::ExrImage`]), bit for bit, and no file written: for callers that want the
    /// images in memory (the Python module). The job's output path is then not used; parts
    /// and checkpoints, which are files, are refused.
    Sink,
}

/// The part of a render a part file holds (a job whose output ends in `.rpart`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Slice {
    /// Sample indices of every pixel (`None`: all, `0..spp`).
    pub samples: Option<Range<u32>>,
    /// Pixels `[x0, y0, x1, y1]` (`None`: the whole image).
    pub region: Option<[u32; 4]>,
}

impl Slice {
    /// Sample indices `samples` of every pixel.
    pub fn samples(samples: Range<u32>) -> Slice {
        Slice {
            samples: Some(samples),
            region: None,
        }
    }

    /// True when it limits nothing.
    pub fn is_whole(&self) -> bool {
        self.samples.is_none() && self.region.is_none()
    }

    /// The region as a rectangle.
    pub fn rect(&self) -> Option<Rect> {
        self.region.map(|[x0, y0, x1, y1]| Rect { x0, y0, x1, y1 })
    }
}

/// Where and how often a long render saves its state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Checkpointing {
    /// The checkpoint file (`.rpart`), written atomically and removed when the render ends.
    pub path: PathBuf,
    /// Seconds between checkpoints (0: after every pass).
    pub every: f64,
}

/// Seconds between checkpoints when nothing says.
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 60.0;

impl Checkpointing {
    /// Checkpoints to `path` every [`DEFAULT_CHECKPOINT_EVERY`] seconds, and when the stop
    /// flag stops the render.
    pub fn new(path: PathBuf) -> Self {
        Self {
            path,
            every: DEFAULT_CHECKPOINT_EVERY,
        }
    }
}

/// GREE (Bauszat, thesis ch. 5) instead of a denoiser: its options, its filter bank and the
/// extra outputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GreeJob {
    /// The options (`fraction`, `sparsity`, ...), over the budget `spp`.
    #[serde(with = "text")]
    pub options: crate::GreeSpec,
    /// A bank file (`denoisers = [...]`); `None`: the default bank.
    pub bank: Option<PathBuf>,
    /// Write the chosen filter per pixel as a colour-coded PNG here.
    pub labels: Option<PathBuf>,
    /// Write each filter's error map (EXR and false-colour PNG) into this directory.
    pub error_maps: Option<PathBuf>,
}

/// A render, complete: what to render, how, and where to write it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderJob {
    /// The scene file, or `gen:NAME`.
    pub scene: PathBuf,
    /// Refuse any file the scene refers to outside this directory.
    pub confine: Option<PathBuf>,
    /// Parameters of a Mitsuba scene file (`render -D name=value`), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub defines: Vec<(String, String)>,
    /// Integrator, structure, samples, seed, AOVs, threads and denoiser, resolved.
    pub settings: Settings,
    /// The camera by name (`None`: the scene's first).
    pub camera: Option<String>,
    /// The image size relative to the camera's.
    pub size: ImageSize,
    /// The frames.
    pub frames: Frames,
    /// Frames per second: frame `f` is at time `f / fps`.
    pub fps: f64,
    /// Motion blur: the shutter is open this fraction of a frame from the frame's time.
    pub shutter: f64,
    /// Adaptive stopping (`None`: exactly `settings.spp` samples per pixel).
    pub stop: Option<StopRule>,
    /// The image (`.exr` or `.png`), or part file (`.rpart`); with several frames a pattern
    /// naming the frame (`{frame}`, `{frame:04}`).
    pub output: PathBuf,
    /// Exposure in stops of a PNG output.
    pub exposure: f32,
    /// The slice a part file holds.
    pub slice: Slice,
    /// Checkpointing of a long render.
    pub checkpoint: Option<Checkpointing>,
    /// A world-space shading cache kept across passes and frames.
    #[serde(with = "text::option")]
    pub cache: Option<CacheSpec>,
    /// GREE instead of a denoiser.
    pub gree: Option<GreeJob>,
    /// Normal or reference streams.
    pub stream: Stream,
    /// Settings the caller adds to part headers, so that only parts that agree on them merge
    /// (a reference's cache key).
    pub labels: BTreeMap<String, String>,
    /// Refuse the render if its estimated memory exceeds this many bytes (`None`: what the
    /// system reports available).
    pub max_memory: Option<u64>,
    /// The checkpoint to continue from ([`RenderJob::resume`]); not part of the job's file.
    #[serde(skip)]
    pub resume: Option<PathBuf>,
    /// Stop a render without a checkpoint at the next pass when the stop flag is set: a
    /// fixed render's samples are then rendered in passes of about
    /// [`INTERRUPTIBLE_PASS`] (which add up to the bits of one pass), an adaptive render
    /// stops after its current pass, and a stopped render writes nothing and returns
    /// [`JobError::Stopped`]. For callers that interrupt renders they do not checkpoint (the
    /// Python module's Ctrl-C); not part of the job's file.
    #[serde(skip)]
    pub interruptible: bool,
    /// Where the images go (files by default); not part of the job's file.
    #[serde(skip)]
    pub delivery: Delivery,
}

/// Why a job could not run, or stopped. Each is one line naming what it is about.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// A setting is bad.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// No such camera, or a bad size.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The scene did not load.
    #[error("{0}")]
    Scene(String),
    /// Settings the job cannot honour together, or a file it cannot use.
    #[error("{0}")]
    Refused(String),
    /// Rendering, denoising or writing failed.
    #[error("{0}")]
    Failed(String),
    /// A plan or checkpoint holding a job of another format.
    #[error("{0}")]
    Format(String),
    /// The stop flag stopped a checkpointed render: the image so far and the checkpoint are
    /// written.
    #[error("interrupted after {samples} of {spp} samples per pixel: wrote {} and the checkpoint {} (render --resume {} continues)", output.display(), checkpoint.display(), checkpoint.display())]
    Interrupted {
        /// Samples per pixel taken.
        samples: u32,
        /// Samples per pixel of the whole render.
        spp: u32,
        /// The image written.
        output: PathBuf,
        /// The checkpoint written.
        checkpoint: PathBuf,
    },
    /// The stop flag stopped an interruptible render ([`RenderJob::interruptible`]): nothing
    /// was written.
    #[error("stopped after {samples} of {spp} samples per pixel: nothing written")]
    Stopped {
        /// Samples per pixel taken.
        samples: u32,
        /// Samples per pixel of the whole render.
        spp: u32,
    },
}

pub(crate) fn refuse<T>(message: String) -> Result<T, JobError> {
    Err(JobError::Refused(message))
}

/// A scene loaded for a job, with the files it read (for the content hash of parts and
/// checkpoints).
pub struct JobScene {
    /// The scene and its `[render]` table.
    pub loaded: LoadedScene,
    /// What the loader read.
    pub access: FileAccess,
}

/// Loads `path` (or `gen:NAME`), reading only files inside `confine` if given; `defines`
/// are a Mitsuba scene's `-D name=value` parameters.
pub fn load_scene(
    path: &Path,
    confine: Option<&Path>,
    defines: &[(String, String)],
) -> Result<JobScene, JobError> {
    let access = match confine {
        Some(dir) => FileAccess::confined_to(dir).map_err(|e| JobError::Scene(e.to_string()))?,
        None => FileAccess::open(),
    };
    let loaded = rt_scene::load_any_defined(path, &access, defines)
        .map_err(|e| JobError::Scene(e.to_string()))?;
    Ok(JobScene { loaded, access })
}

/// The extension of `path`, lower case.
pub(crate) fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

impl RenderJob {
    /// A still render of `scene` with `settings`, written to `settings.output` or the
    /// scene's file name with `.exr`; everything else at its default.
    pub fn new(scene: &Path, settings: Settings) -> RenderJob {
        let output = settings.output.clone().unwrap_or_else(|| {
            PathBuf::from(scene.file_stem().unwrap_or_default()).with_extension("exr")
        });
        RenderJob {
            scene: scene.to_path_buf(),
            confine: None,
            settings,
            camera: None,
            size: ImageSize::Native,
            frames: Frames::Still,
            fps: DEFAULT_FPS,
            shutter: 0.0,
            stop: None,
            output,
            exposure: 0.0,
            slice: Slice::default(),
            checkpoint: None,
            cache: None,
            gree: None,
            stream: Stream::Render,
            labels: BTreeMap::new(),
            max_memory: None,
            defines: Vec::new(),
            resume: None,
            interruptible: false,
            delivery: Delivery::Files,
        }
    }

    /// True if the job writes a part file (its output ends in `.rpart`).
    pub fn writes_part(&self) -> bool {
        self.delivery == Delivery::Files && extension(&self.output).as_deref() == Some("rpart")
    }

    /// The job as JSON, with its format: what plans and checkpoints store.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({ "format": JOB_FORMAT, "job": self })
    }

    /// A job from [`RenderJob::to_json`]'s value; another format is refused with one line.
    pub fn from_json(value: &serde_json::Value) -> Result<RenderJob, JobError> {
        let format = value.get("format").and_then(|f| f.as_u64());
        if format != Some(u64::from(JOB_FORMAT)) {
            let found = format.map_or("none".to_string(), |f| f.to_string());
            return Err(JobError::Format(format!(
                "its job has format {found}; this renderer reads format {JOB_FORMAT} (render it again with this renderer)"
            )));
        }
        let job = value.get("job").cloned().unwrap_or_default();
        serde_json::from_value(job)
            .map_err(|e| JobError::Format(format!("its job does not read: {e}")))
    }

    /// The job a checkpoint was written for, set to continue from it.
    pub fn resume(checkpoint: &Path) -> Result<RenderJob, JobError> {
        let p = checkpoint.display();
        let part =
            rt_parts::Part::read(checkpoint).map_err(|e| JobError::Refused(format!("{p}: {e}")))?;
        if part.header.kind != rt_parts::PartKind::Checkpoint {
            return refuse(format!(
                "{p}: a part, not a checkpoint: merge it with render merge"
            ));
        }
        let mut job = RenderJob::from_json(&part.header.job)
            .map_err(|e| JobError::Format(format!("{p}: {e}")))?;
        if job.checkpoint.is_none() {
            return refuse(format!("{p}: its job does not checkpoint"));
        }
        job.resume = Some(checkpoint.to_path_buf());
        Ok(job)
    }

    /// The checks that need no scene: outputs, stop rule, slice, checkpointing, frames and
    /// shutter. [`RenderJob::run`] makes them first; a caller building a job may make them
    /// earlier.
    pub fn check(&self) -> Result<(), JobError> {
        match self.delivery {
            Delivery::Files => self.check_files()?,
            Delivery::Sink => {
                if !self.slice.is_whole() || self.checkpoint.is_some() {
                    return refuse(
                        "a job whose images go to its caller renders whole images: parts and checkpoints are files".into(),
                    );
                }
            }
        }
        if !self.exposure.is_finite() {
            return refuse("--exposure must be a finite number".into());
        }
        if self.settings.aovs.blocks && self.stop.is_none_or(|s| s.error.is_none()) {
            return refuse(
                "--aov blocks writes the stopping criterion's blocks: it needs --error".into(),
            );
        }
        if let Some(c) = &self.checkpoint {
            let p = c.path.display();
            if extension(&c.path).as_deref() != Some("rpart") {
                return refuse(format!("--checkpoint {p}: the file must end in .rpart"));
            }
            let cannot = |what: &str| refuse(format!("--checkpoint {p}: cannot checkpoint {what}"));
            if self.stop.is_some() {
                return cannot(
                    "an adaptive render (--error, --time-limit): its stopping state is not kept",
                );
            }
            if matches!(self.frames, Frames::Range(_)) {
                return cannot("a sequence (--frames): checkpoint each frame's render (--frame F)");
            }
            if self.writes_part() {
                return cannot("a part: render smaller parts instead");
            }
            if self.gree.is_some() || self.cache.is_some() {
                return cannot("GREE or a world-space cache: their state is not kept");
            }
            if !(c.every.is_finite() && c.every >= 0.0) {
                return refuse("--checkpoint-every must be a number of seconds >= 0".into());
            }
        }
        if self.frames != Frames::Still || self.shutter != 0.0 {
            check_fps(self.fps)?;
        }
        if let Frames::Range(r) = &self.frames {
            if r.is_empty() {
                return refuse(format!("frames {}..{}: no frame", r.start, r.end));
            }
        }
        if !(self.shutter.is_finite() && self.shutter >= 0.0) {
            return refuse(format!(
                "--shutter must be a fraction of a frame >= 0, got {}",
                self.shutter
            ));
        }
        self.size.validate("--resolution")?;
        Ok(())
    }

    /// The checks of a job that writes files: its output's format, a part's file, a
    /// sequence's file names.
    fn check_files(&self) -> Result<(), JobError> {
        let out = self.output.display();
        let ext = extension(&self.output);
        match ext.as_deref() {
            Some("exr" | "png" | "rpart") => {}
            _ => {
                return refuse(format!(
                    "{out}: output must end in .exr or .png (or .rpart for a part file)"
                ))
            }
        }
        if self.settings.aovs != rt_film::AovSet::default() && ext.as_deref() == Some("png") {
            return refuse(format!(
                "{out}: AOVs need an .exr output (PNG holds only the beauty image)"
            ));
        }
        if !self.slice.is_whole() && !self.writes_part() {
            return refuse(format!(
                "{out}: --sample-range and --region write a part file: -o must end in .rpart"
            ));
        }
        if matches!(self.frames, Frames::Range(_)) {
            check_frame_pattern(&self.output)?;
        }
        Ok(())
    }

    /// The temporal denoiser, if the job's denoiser is one (`svgf`): its frames are then
    /// rendered in order through [`crate::SequenceRenderer`].
    pub fn temporal(&self) -> Option<&TemporalSpec> {
        self.settings.denoiser.as_ref().filter(|d| d.is_temporal())
    }

    /// The settings a part or checkpoint header names, so that only slices of the same render
    /// merge: every setting that changes the image's bits (`threads`, the output and the
    /// checkpointing do not), with the camera's resolved name.
    pub fn identity(&self, camera: &str) -> BTreeMap<String, String> {
        let s = &self.settings;
        let mut map: BTreeMap<String, String> = [
            ("integrator", s.integrator.to_string()),
            ("accel", s.accel.to_string()),
            ("seed", s.seed.to_string()),
            ("camera", camera.to_string()),
            ("exposure", self.exposure.to_string()),
            (
                "denoiser",
                s.denoiser
                    .as_ref()
                    .map(|d| d.to_string())
                    .unwrap_or_default(),
            ),
            ("shutter", self.shutter.to_string()),
            ("fps", self.fps.to_string()),
            (
                "stream",
                match self.stream {
                    Stream::Render => "render",
                    Stream::Reference => "reference",
                }
                .to_string(),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        map.extend(self.labels.clone());
        map
    }
}

/// Refuses, for a sequence, an output that does not name the frame.
pub(crate) fn check_frame_pattern(output: &Path) -> Result<(), JobError> {
    if crate::frames::names_frame(output) {
        return Ok(());
    }
    refuse(format!(
        "{}: --frames needs an output that names the frame, e.g. -o 'out/frame_{{frame:04}}.exr'",
        output.display()
    ))
}

/// Frames per second: a positive finite number.
pub fn check_fps(fps: f64) -> Result<(), JobError> {
    if !(fps.is_finite() && fps > 0.0) {
        return refuse(format!("--fps must be a positive number, got {fps}"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Overrides;

    fn job() -> RenderJob {
        let path = Path::new("gen:worst-case");
        let loaded = rt_scene::load_any(path).unwrap();
        let settings = Overrides {
            integrator: Some("path:max-depth=3".parse().unwrap()),
            spp: Some(4),
            denoiser: Some("nlm:k=0.3".into()),
            ..Overrides::default()
        }
        .resolve(&loaded, path)
        .unwrap();
        RenderJob::new(path, settings)
    }

    #[test]
    fn a_job_round_trips_through_json_and_refuses_another_format() {
        let mut j = job();
        j.frames = Frames::Range(2..5);
        j.output = "f_{frame:04}.exr".into();
        j.stop = Some(StopRule::new(Some(2e-4), Some(1.5), 64).unwrap());
        j.cache = Some("grid:lod=4,kappa=0.5".parse().unwrap());
        j.gree = Some(GreeJob {
            options: "kappa=0.5:metric=relative".parse().unwrap(),
            bank: None,
            labels: Some("l.png".into()),
            error_maps: None,
        });
        j.slice.region = Some([0, 0, 4, 4]);
        j.labels.insert("cache key".into(), "abc".into());
        let back = RenderJob::from_json(&j.to_json()).unwrap();
        assert_eq!(back, j);
        let mut v = j.to_json();
        v["format"] = serde_json::json!(JOB_FORMAT + 1);
        let e = RenderJob::from_json(&v).unwrap_err().to_string();
        assert!(e.contains("format 2") && !e.contains('\n'), "{e}");
    }

    #[test]
    fn checks_refuse_what_cannot_be_rendered_with_one_line() {
        let refused = |f: &dyn Fn(&mut RenderJob)| {
            let mut j = job();
            f(&mut j);
            j.check().unwrap_err().to_string()
        };
        assert!(refused(&|j| j.output = "x.jpg".into()).contains("must end in .exr or .png"));
        assert!(refused(&|j| j.slice.samples = Some(0..2)).contains("-o must end in .rpart"));
        assert!(refused(&|j| {
            j.checkpoint = Some(Checkpointing {
                path: "c.rpart".into(),
                every: 1.0,
            });
            j.frames = Frames::Range(0..2);
            j.output = "f{frame}.exr".into();
        })
        .contains("cannot checkpoint a sequence"));
        assert!(refused(&|j| j.frames = Frames::Range(0..2)).contains("names the frame"));
        assert!(refused(&|j| j.shutter = -1.0).contains("--shutter"));
        assert!(job().check().is_ok());
    }
}

#[cfg(test)]
mod run_tests {
    //! Jobs run end to end: parts merge, and checkpoints resume, to the bytes of the whole
    //! render; a file holding another job format is refused with one line.
    use super::*;
    use crate::Overrides;
    use std::sync::atomic::AtomicBool;

    /// The moving ball of the sequence tests, 24x16 pixels.
    fn job(dir: &Path, spp: u32) -> RenderJob {
        let path = dir.join("s.toml");
        std::fs::write(&path, crate::sequence::tests::moving_ball()).unwrap();
        let loaded = rt_scene::load_any(&path).unwrap();
        let o = Overrides {
            spp: Some(spp),
            aovs: Some(vec!["variance".into(), "albedo".into()]),
            ..Overrides::default()
        };
        let mut job = RenderJob::new(&path, o.resolve(&loaded, &path).unwrap());
        job.size = ImageSize::Pixels(24, 16);
        job
    }

    fn bytes(p: &Path) -> Vec<u8> {
        std::fs::read(p).unwrap()
    }

    #[test]
    fn an_interruptible_job_gives_the_same_bytes_and_stops_at_a_pass_writing_nothing() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let mut j = job(dir, 5);
        j.output = dir.join("whole.exr");
        j.run(&(), &AtomicBool::new(false)).unwrap();
        j.interruptible = true;
        j.output = dir.join("passes.exr");
        j.run(&(), &AtomicBool::new(false)).unwrap();
        assert!(bytes(&dir.join("passes.exr")) == bytes(&dir.join("whole.exr")));
        // Set before the render: it ends after its first pass.
        j.output = dir.join("stopped.exr");
        let e = j.run(&(), &AtomicBool::new(true)).unwrap_err();
        assert!(matches!(e, JobError::Stopped { samples: 1, spp: 5 }), "{e}");
        assert!(!j.output.exists());
        // Adaptive jobs too; a job that is not interruptible ignores the flag.
        j.stop = Some(crate::StopRule::new(Some(1e-9), None, 64).unwrap());
        let e = j.run(&(), &AtomicBool::new(true)).unwrap_err();
        assert!(
            matches!(
                e,
                JobError::Stopped {
                    samples: 2,
                    spp: 64
                }
            ),
            "{e}"
        );
        j.interruptible = false;
        j.run(&(), &AtomicBool::new(true)).unwrap();
        assert!(j.output.exists());
    }

    /// Keeps the images a job hands over.
    #[derive(Default)]
    struct Images(std::sync::Mutex<Vec<(Option<u32>, rt_film::ExrImage)>>);

    impl JobSink for Images {
        fn image(&self, frame: Option<u32>, image: rt_film::ExrImage) {
            self.0.lock().unwrap().push((frame, image));
        }
    }

    #[test]
    fn a_job_delivering_to_its_sink_hands_over_what_its_files_hold_and_writes_nothing() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        // At the job's size (24x16), a temporally denoised sequence too.
        let mut j = job(dir, 3);
        for denoiser in [None, Some("nlm"), Some("svgf")] {
            j.settings.denoiser = denoiser.map(|d| d.parse().unwrap());
            j.frames = Frames::Range(1..3);
            j.delivery = Delivery::Files;
            j.output = dir.join("f_{frame}.exr");
            j.run(&(), &AtomicBool::new(false)).unwrap();
            j.delivery = Delivery::Sink;
            j.output = dir.join("not-written_{frame}.exr");
            let images = Images::default();
            j.run(&images, &AtomicBool::new(false)).unwrap();
            let images = images.0.into_inner().unwrap();
            assert_eq!(images.len(), 2, "{denoiser:?}");
            for (f, (frame, image)) in (1..3).zip(images) {
                assert_eq!(frame, Some(f));
                assert_eq!((image.width, image.height), (24, 16), "{denoiser:?}");
                let file = rt_film::read_exr(&dir.join(format!("f_{f}.exr"))).unwrap();
                assert!(image == file, "{denoiser:?}, frame {f}");
            }
            assert!(!dir.join("not-written_1.exr").exists());
        }
        j.slice.samples = Some(0..1);
        assert!(j
            .check()
            .unwrap_err()
            .to_string()
            .contains("parts and checkpoints"));
    }

    #[test]
    fn parts_of_two_frames_merge_to_the_bytes_of_each_whole_frame() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let mut j = job(dir, 7);
        j.frames = Frames::Range(0..2);
        j.output = dir.join("whole_{frame}.exr");
        j.run(&(), &AtomicBool::new(false)).unwrap();
        let cuts = [
            (0..3, None),
            (3..7, Some([0, 0, 10, 16])),
            (3..7, Some([10, 0, 24, 16])),
        ];
        for (k, (samples, region)) in cuts.iter().enumerate() {
            j.slice = Slice {
                samples: Some(samples.clone()),
                region: *region,
            };
            j.output = dir.join(format!("p{k}_{{frame}}.rpart"));
            j.run(&(), &AtomicBool::new(false)).unwrap();
        }
        for f in 0..2 {
            let files: Vec<PathBuf> = (0..3)
                .map(|k| dir.join(format!("p{k}_{f}.rpart")))
                .collect();
            let out = dir.join(format!("merged_{f}.exr"));
            merge(&read_parts(&files).unwrap(), &out, None).unwrap();
            assert!(
                bytes(&out) == bytes(&dir.join(format!("whole_{f}.exr"))),
                "frame {f}"
            );
        }
        assert!(bytes(&dir.join("whole_0.exr")) != bytes(&dir.join("whole_1.exr")));
    }

    #[test]
    fn a_stopped_render_resumes_to_the_bytes_of_one_never_stopped() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let mut j = job(dir, 5);
        j.output = dir.join("whole.exr");
        j.run(&(), &AtomicBool::new(false)).unwrap();
        j.output = dir.join("resumed.exr");
        let ck = dir.join("ck.rpart");
        j.checkpoint = Some(Checkpointing::new(ck.clone()));
        let e = j.run(&(), &AtomicBool::new(true)).unwrap_err();
        assert!(
            matches!(
                e,
                JobError::Interrupted {
                    samples: 1,
                    spp: 5,
                    ..
                }
            ),
            "{e}"
        );
        assert!(ck.exists() && dir.join("resumed.exr").exists());
        // The job the checkpoint holds is this one.
        let resumed = RenderJob::resume(&ck).unwrap();
        assert_eq!(
            RenderJob {
                defines: Vec::new(),
                resume: None,
                ..resumed.clone()
            },
            j
        );
        resumed.run(&(), &AtomicBool::new(false)).unwrap();
        assert!(bytes(&dir.join("resumed.exr")) == bytes(&dir.join("whole.exr")));
        assert!(!ck.exists(), "a finished render removes its checkpoint");
    }

    #[test]
    fn a_checkpoint_of_another_job_format_is_refused_with_one_line() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path();
        let mut j = job(dir, 3);
        j.output = dir.join("x.exr");
        let ck = dir.join("ck.rpart");
        j.checkpoint = Some(Checkpointing::new(ck.clone()));
        j.run(&(), &AtomicBool::new(true)).unwrap_err();
        let mut part = rt_parts::Part::read(&ck).unwrap();
        part.header.job["format"] = serde_json::json!(JOB_FORMAT + 7);
        part.write(&ck).unwrap();
        let e = RenderJob::resume(&ck).unwrap_err().to_string();
        assert!(
            e.contains("ck.rpart: its job has format 8; this renderer reads format 1")
                && !e.contains('\n'),
            "{e}"
        );
    }
}
