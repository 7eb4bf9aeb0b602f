//! Acceleration-structure benchmarks, the machinery behind `render bench-accel` and
//! `render bench-anim`, usable without the CLI.
//!
//! - [`input`]: the geometry (a TOML scene, a bare mesh with an automatic camera and light, or
//!   `gen:NAME`).
//! - [`accel`]: per structure, build it, check its answers against the binary BVH, time every
//!   ray set of `rt_accel::bench` on 1 and N threads and count traversal work; [`accel::Row`]s
//!   out, [`accel::table`] and [`accel::csv`] to show them.
//! - [`anim`]: seconds per frame of an animated scene (update and trace) for each contender of
//!   `rt_accel::bench::anim`; [`anim::table`] and [`anim::csv`].
//!
//! Progress lines go to a caller's closure; nothing here prints.

pub mod accel;
pub mod anim;
pub mod input;
mod table;

use std::path::PathBuf;

/// Why a benchmark could not run. Each message is one line naming the input.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BenchError {
    /// The input cannot be used (unknown type, no triangles, no camera, not a mesh).
    #[error("{input}: {message}")]
    Input {
        /// The input as given.
        input: String,
        /// What is wrong with it.
        message: String,
    },
    /// A scene that does not load, or a camera it lacks.
    #[error(transparent)]
    Job(#[from] rt_session::JobError),
    /// A camera the scene lacks.
    #[error(transparent)]
    Session(#[from] rt_session::SessionError),
    /// A mesh that does not load.
    #[error(transparent)]
    Scene(#[from] rt_scene::SceneError),
    /// A ray file that cannot be read or written.
    #[error(transparent)]
    RayFile(#[from] rt_accel::bench::RayFileError),
    /// A camera asked of a mesh file, which has none.
    #[error("a mesh file has no cameras (an automatic one is used)")]
    MeshCamera,
    /// The automatic view asked of a scene that has its own camera.
    #[error("{input} is not a mesh file; it is seen through its own camera")]
    ViewOfScene {
        /// The input as given.
        input: String,
    },
    /// A primary ray grid that is empty or too large.
    #[error(
        "{width}x{height} primary rays: each side must be in [1, {}] and width*height at most {}",
        input::MAX_SIDE,
        input::MAX_PIXELS
    )]
    Resolution {
        /// Columns asked for.
        width: u32,
        /// Rows asked for.
        height: u32,
    },
    /// A structure that does not build on this input.
    #[error("{input}: {spec}: {message}")]
    Build {
        /// The input as given.
        input: String,
        /// The structure's spec.
        spec: String,
        /// Why.
        message: String,
    },
    /// A structure whose answers disagree with the binary BVH's.
    #[error(
        "{spec}: {mismatches} of {checked} checked rays disagree with bvh (more than {percent}%)"
    )]
    Check {
        /// The structure's spec.
        spec: String,
        /// Rays that disagree.
        mismatches: usize,
        /// Rays checked.
        checked: usize,
        /// The allowed percentage.
        percent: f64,
    },
    /// The animation measurement refused its settings.
    #[error("{input}: {source}")]
    Anim {
        /// The input as given.
        input: String,
        /// Why.
        #[source]
        source: rt_accel::bench::anim::AnimError,
    },
    /// A file that cannot be written.
    #[error("{}: cannot write: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// An output file that cannot be written.
    #[error(transparent)]
    Film(#[from] rt_film::FilmError),
}
