//! The experiment crate's error type. Every message is one line that names the file (or the
//! `[[scene]]` / `[[method]]` entry) it is about.

use std::path::PathBuf;

/// Why an experiment, a reference or one of their files failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// The experiment file is malformed or asks for something impossible; the message names
    /// the entry and the problem.
    #[error("{}: {message}", file.display())]
    Config {
        /// The experiment file.
        file: PathBuf,
        /// What is wrong, starting with the entry (`[[method]] "fast"`: ...).
        message: String,
    },
    /// A problem found while running, with its context (which run, which image).
    #[error("{0}")]
    Run(String),
    /// File-system trouble.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A scene that does not load.
    #[error(transparent)]
    Scene(#[from] rt_scene::SceneError),
    /// A setting, camera or image size that cannot be rendered.
    #[error(transparent)]
    Session(#[from] rt_session::SessionError),
    /// A job (a merge, a reference's render) that failed.
    #[error(transparent)]
    Job(#[from] rt_session::JobError),
    /// An image that cannot be read or written.
    #[error(transparent)]
    Image(#[from] rt_film::FilmError),
    /// Two images that cannot be compared.
    #[error(transparent)]
    Metrics(#[from] rt_metrics::MetricsError),
    /// A plot that cannot be drawn.
    #[error("{}: cannot draw the plot: {message}", path.display())]
    Plot {
        /// The plot file.
        path: PathBuf,
        /// What the plotting library said.
        message: String,
    },
}

impl From<rt_session::SettingsError> for ExperimentError {
    fn from(e: rt_session::SettingsError) -> Self {
        Self::Session(e.into())
    }
}

impl From<rt_core::PixelCountError> for ExperimentError {
    fn from(e: rt_core::PixelCountError) -> Self {
        Self::Metrics(e.into())
    }
}

/// Results of this crate.
pub type Result<T, E = ExperimentError> = std::result::Result<T, E>;

/// An [`ExperimentError::Io`] for `path`.
pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ExperimentError {
    let path = path.into();
    move |source| ExperimentError::Io { path, source }
}
