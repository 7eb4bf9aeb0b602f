//! The shared test meshes (Stanford bunny, conference room, ...), which are not in the
//! repository but in `../shared/data` next to it. Every test and stress case that needs one
//! finds it here, so that a missing file is handled one way:
//!
//! - present: its path;
//! - missing, with `RT_REQUIRE_DATA=1` in the environment (`.ci/run` sets it): an error
//!   ([`MissingData`]); the tests panic with it, the stress case fails;
//! - missing otherwise: a skip, announced by one line on the process's real standard error.
//!   libtest captures only the `print!`/`eprint!` family, so the line shows in `cargo test`'s
//!   output even for a passing test.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The environment variable that turns a missing data file into a failure.
pub const REQUIRE_VAR: &str = "RT_REQUIRE_DATA";

/// A data file that is required (`RT_REQUIRE_DATA=1`) but missing.
#[derive(Debug, thiserror::Error)]
#[error("{} not found, and {REQUIRE_VAR}=1 requires it (the shared test data is at ../shared/data)", path.display())]
pub struct MissingData {
    /// The path looked for.
    pub path: PathBuf,
}

/// True if `RT_REQUIRE_DATA=1`.
pub fn required() -> bool {
    std::env::var(REQUIRE_VAR).is_ok_and(|v| v == "1")
}

/// The data directory of a checkout: `../shared/data` beside the workspace root.
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// `dir/relative` if it exists; `Ok(None)` if it does not and data is optional; an error if
/// it does not and `RT_REQUIRE_DATA=1`.
pub fn locate(dir: &Path, relative: &str) -> Result<Option<PathBuf>, MissingData> {
    let path = dir.join(relative);
    if path.exists() {
        Ok(Some(path))
    } else if required() {
        Err(MissingData { path })
    } else {
        Ok(None)
    }
}

/// For tests: `relative` in [`default_dir`], or `None` after printing one visible skip line;
/// panics if it is missing and `RT_REQUIRE_DATA=1`.
pub fn file(relative: &str) -> Option<PathBuf> {
    match locate(&default_dir(), relative) {
        Ok(Some(path)) => Some(path),
        Ok(None) => {
            skip(&format!(
                "{} not found",
                default_dir().join(relative).display()
            ));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Prints `skipping: {why}` to the real standard error, past libtest's capture.
pub fn skip(why: &str) {
    let line = format!("skipping: {why} (set {REQUIRE_VAR}=1 to make this a failure)\n");
    // Ignored: nothing else can be reported if standard error itself is gone.
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}
