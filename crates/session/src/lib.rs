//! `rt-session`: rendering, as a library. The `render` CLI is one client of it; a program
//! that wants images, frames, parts, checkpoints or the memory check uses the same types.
//!
//! - [`job`]: [`RenderJob`], a render as one typed, serialisable value (scene, settings,
//!   frames, slice, stop rule, checkpointing, outputs, denoiser, cache), with one
//!   [`RenderJob::run`] that takes a progress sink and a stop flag; plans and checkpoints store
//!   it; [`job::merge`] merges its parts. [`RenderJob::render_stops`] renders a job into a film
//!   the caller keeps and hands it over at every stop ([`FilmStop`]), as experiments record
//!   their budgets; [`RenderJob::render_sequence`] renders its frames over a scene the caller
//!   holds and hands each over with its guide buffers, as sequence experiments record them;
//!   [`RenderJob::each_frame`] is the frame loop they all walk, with [`following`]: the
//!   structure that follows a moving scene.
//! - [`settings`]: the one place settings are resolved (given values, then the scene's
//!   `[render]` table, then defaults), with their limits ([`rt_core::limits`]) and the
//!   combinations they cannot honour.
//! - [`camera`]: which camera renders ([`pick_camera`]) and at what size ([`ImageSize`]).
//! - [`adaptive`]: rendering until a [`StopRule`] says stop.
//! - [`progressive`]: a list of budgets, samples per pixel or seconds, rendered pass after pass
//!   into one film ([`Session`], [`Budgets`], [`Checkpoint`]), what a job's
//!   [`RenderJob::render_stops`] runs for an experiment's budgets.
//! - [`sequence`]: an animation rendered frame after frame, denoised by a denoiser that may
//!   remember earlier frames (SVGF), with the guide pass in between ([`SequenceRenderer`]);
//!   [`viewer`]: the same frame after frame under a user's hand ([`viewer::LiveView`], the
//!   orbit camera, window pixels).
//! - [`gree`]: GREE over the renderer; [`worldcache`]: the world-space cache behind the
//!   integrators' cache seam; [`memory`]: the memory estimate a job checks; [`frames`]: frame
//!   file names.
//! - [`report`]: what a render built and skipped, with time and bytes ([`RenderReport`], the
//!   table `render --stats` prints).
//!
//! Depends on `rt-core`, `rt-accel` ([`rt_accel::AccelSpec`]), `rt-film`, `rt-scene` (the
//! `[render]` table), `rt-integrators` ([`rt_integrators::IntegratorSpec`]), the denoisers
//! (`rt-denoise`, `rt-temporal`, `rt-gree`), `rt-worldcache` and `rt-parts` (part files).
//!
//! Render a scene at 4 spp into a 16x12 EXR, without the CLI (`examples/job.rs` renders two
//! frames in parts, merges them and resumes a checkpoint):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use rt_session::{load_scene, ImageSize, Overrides, RenderJob};
//! let path = std::path::Path::new("gen:worst-case");
//! let scene = load_scene(path, None, &[])?;
//! let overrides = Overrides { spp: Some(4), ..Overrides::default() };
//! let mut job = RenderJob::new(path, overrides.resolve(&scene.loaded, path)?);
//! job.size = ImageSize::Pixels(16, 12);
//! job.output = std::env::temp_dir().join("rt-session-doc.exr");
//! let report = job.run(&(), &std::sync::atomic::AtomicBool::new(false))?;
//! assert_eq!(report.frames, 1);
//! assert_eq!(rt_film::read_rgb(&job.output)?.width(), 16);
//! # Ok(()) }
//! ```
#![forbid(unsafe_code)]

pub mod adaptive;
pub mod camera;
pub mod following;
pub mod frames;
pub mod gree;
pub mod job;
pub mod memory;
pub mod progressive;
pub mod report;
pub mod sequence;
pub mod settings;
pub mod signals;
mod text;
pub mod viewer;
pub mod worldcache;

pub use adaptive::{
    render_adaptive, render_adaptive_until, Adaptive, StopReason, StopRule, StopRuleError,
    FIRST_DECISION_SPP,
};
pub use camera::{parse_resolution, pick_camera, split_size, ImageSize, MAX_SIDE};
pub use gree::{gree_aovs, render_gree, GreeRun, GreeRunError, GreeSpec};
pub use job::{
    load_scene, Checkpointing, Delivery, FilmStop, FrameReport, Frames, GreeJob, JobError,
    JobFrame, JobReport, JobScene, JobSink, RenderJob, Rendered, Slice, Stream,
};
pub use progressive::{Budgets, Checkpoint, Session};
pub use report::{RenderReport, ReportInputs, Stage, Status};
pub use sequence::{FrameTimes, RunSummary, SequenceError, SequenceFrame, SequenceRenderer};
pub use settings::{
    fold_seed, frame_seed, Origin, Overrides, Settings, SettingsError, DEFAULT_SPP, MAX_SPP,
    MAX_THREADS,
};

use std::path::PathBuf;

/// Why a configuration cannot be rendered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SessionError {
    /// A setting is bad.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// `--camera NAME` names no camera of the scene.
    #[error("{}: no camera named \"{name}\" (cameras: {})", file.display(), cameras.join(", "))]
    NoSuchCamera {
        /// The scene file.
        file: PathBuf,
        /// The name asked for.
        name: String,
        /// The scene's cameras.
        cameras: Vec<String>,
    },
    /// The scene has no camera at all.
    #[error("{}: the scene has no camera", file.display())]
    NoCamera {
        /// The scene file.
        file: PathBuf,
    },
    /// A bad image size.
    #[error("{what}: {reason}")]
    BadSize {
        /// Where the size came from.
        what: String,
        /// What is wrong.
        reason: String,
    },
}
