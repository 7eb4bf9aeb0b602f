//! `rt-session`: rendering one configuration, the part that `render`, `render reference` and
//! `render experiment` share, and that a program using the crates would otherwise copy.
//!
//! - [`settings`]: the one place settings are resolved (given values, then the scene's
//!   `[render]` table, then defaults) and their limits checked.
//! - [`camera`]: which camera renders ([`pick_camera`]) and at what size ([`ImageSize`]).
//! - [`progressive`]: a list of budgets, samples per pixel or seconds, rendered pass after pass
//!   into one film ([`Session`], [`Budgets`], [`Checkpoint`]).
//! - [`sequence`]: an animation rendered frame after frame, denoised by a denoiser that may
//!   remember earlier frames (SVGF), with the guide pass in between ([`SequenceRenderer`]).
//! - [`report`]: what a render built and skipped, with time and bytes ([`RenderReport`], the
//!   table `render --stats` prints).
//!
//! Depends on `rt-core`, `rt-accel` (the default structure and [`rt_accel::AccelSpec`]),
//! `rt-film`, `rt-scene` (the `[render]` table) and `rt-integrators`
//! ([`rt_integrators::IntegratorSpec`]).
//!
//! Render a scene at 16 spp and write it, without the CLI (`examples/render_scene.rs` is the same
//! with a real scene file):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use rt_session::{pick_camera, Budgets, Overrides, Session};
//! let path = std::path::Path::new("gen:worst-case");
//! let loaded = rt_scene::load_any(path)?;
//! let settings = Overrides::default().resolve(&loaded.render, path)?;
//! let camera = rt_session::ImageSize::Pixels(16, 12).apply(pick_camera(&loaded.scene, path, None)?);
//! let accel = settings.accel.build_scene(&loaded.scene);
//! let integrator = settings.integrator.build();
//! let session = Session {
//!     ctx: rt_integrators::Ctx { scene: &loaded.scene, accel: accel.as_ref(), camera: &camera },
//!     integrator: integrator.as_ref(),
//!     seed: settings.seed,
//!     stream: rt_core::SampleStream::Render,
//!     aovs: settings.aovs,
//! };
//! let mut spp_seen = Vec::new();
//! let film = session.render(&Budgets::Spp(vec![4, 16]), &|_| {}, &mut |_, at| {
//!     spp_seen.push(at.spp);
//!     Ok::<(), std::io::Error>(())
//! })?;
//! assert_eq!(spp_seen, [4, 16]);
//! assert_eq!(film.width(), 16);
//! # Ok(()) }
//! ```
#![forbid(unsafe_code)]

pub mod adaptive;
pub mod camera;
pub mod gree;
pub mod progressive;
pub mod report;
pub mod sequence;
pub mod settings;

pub use adaptive::{render_adaptive, Adaptive, StopReason, StopRule, FIRST_DECISION_SPP};
pub use camera::{parse_resolution, pick_camera, ImageSize, MAX_SIDE};
pub use gree::{gree_aovs, parse_gree_options, render_gree, GreeRun, GreeRunError};
pub use progressive::{Budgets, Checkpoint, Session};
pub use report::{RenderReport, ReportInputs, Stage, Status};
pub use sequence::{FrameTimes, SequenceError, SequenceFrame, SequenceRenderer};
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
