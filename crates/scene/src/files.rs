//! Which files a scene may read: every file the loaders open (the scene file, meshes, material
//! libraries, textures, glTF buffers and images, `.ra2` companions, environment maps) is
//! checked here first. With a confinement directory (`render --confine DIR`, for farms that
//! render scenes they did not write), a file whose real path (symbolic links resolved) lies
//! outside it is refused before it is read.

use crate::error::SceneError;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The loaders' file policy, and the record of every file they opened (for a part file's
/// scene hash: [`FileAccess::files_used`]). Clones share the record.
#[derive(Clone, Debug, Default)]
pub struct FileAccess {
    /// Canonical directory every file must lie in; `None`: any file.
    confine: Option<PathBuf>,
    /// Files checked so far, in order, each once.
    used: Arc<Mutex<Vec<PathBuf>>>,
}

impl FileAccess {
    /// Any file may be read.
    pub fn open() -> Self {
        Self::default()
    }

    /// Only files inside `dir` (which must exist) may be read.
    pub fn confined_to(dir: &Path) -> Result<Self, SceneError> {
        let root = std::fs::canonicalize(dir).map_err(|e| {
            SceneError::file(dir, format!("--confine: cannot open the directory: {e}"))
        })?;
        if !root.is_dir() {
            return Err(SceneError::file(dir, "--confine: not a directory"));
        }
        Ok(Self {
            confine: Some(root),
            used: Arc::default(),
        })
    }

    /// The confinement directory, if any.
    pub fn confinement(&self) -> Option<&Path> {
        self.confine.as_deref()
    }

    /// Refuses `path` if it lies outside the confinement directory. A file that does not
    /// exist is let through: opening it gives the loader's own error.
    pub fn check(&self, path: &Path) -> Result<(), SceneError> {
        self.record(path);
        let Some(root) = &self.confine else {
            return Ok(());
        };
        let Ok(real) = std::fs::canonicalize(path) else {
            return Ok(());
        };
        if real.starts_with(root) {
            Ok(())
        } else {
            Err(SceneError::file(
                path,
                format!(
                    "refused: the file is outside {} (--confine){}",
                    root.display(),
                    if real.as_path() != path {
                        format!("; it is {}", real.display())
                    } else {
                        String::new()
                    }
                ),
            ))
        }
    }

    fn record(&self, path: &Path) {
        let mut used = self.used.lock().unwrap_or_else(|e| e.into_inner());
        if !used.iter().any(|p| p == path) {
            used.push(path.to_path_buf());
        }
    }

    /// Every file the loaders have checked (and so opened or tried to), in the order of first
    /// use: what a scene's content consists of.
    pub fn files_used(&self) -> Vec<PathBuf> {
        self.used.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// The bytes of `path` after [`FileAccess::check`]; `what` names the file in the error
    /// when it cannot be opened (e.g. "material library").
    pub fn read(&self, path: &Path, what: &str) -> Result<Vec<u8>, SceneError> {
        self.check(path)?;
        std::fs::read(path).map_err(|e| {
            let what = if what.is_empty() {
                String::new()
            } else {
                format!(" {what}")
            };
            SceneError::file(path, format!("cannot open{what}: {e}"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_outside_the_directory_and_links_out_of_it_are_refused() {
        let outer = tempfile::tempdir().unwrap();
        let inside = outer.path().join("farm");
        std::fs::create_dir(&inside).unwrap();
        std::fs::write(inside.join("a.obj"), "v 0 0 0\n").unwrap();
        std::fs::write(outer.path().join("secret.png"), "x").unwrap();
        let access = FileAccess::confined_to(&inside).unwrap();
        assert!(access.check(&inside.join("a.obj")).is_ok());
        assert!(access.read(&inside.join("a.obj"), "").is_ok());
        // `..` out of the directory.
        let e = access
            .check(&inside.join("../secret.png"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("refused: the file is outside"), "{e}");
        assert!(e.contains("secret.png"), "{e}");
        // A symbolic link inside that points outside.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(outer.path().join("secret.png"), inside.join("l.png"))
                .unwrap();
            assert!(access.read(&inside.join("l.png"), "texture").is_err());
        }
        // Unconfined, anything goes; a missing file is the reader's error.
        assert!(FileAccess::open()
            .check(&inside.join("../secret.png"))
            .is_ok());
        let e = access
            .read(&inside.join("none.png"), "texture")
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot open texture"), "{e}");
        assert!(FileAccess::confined_to(&inside.join("nope")).is_err());
        // Every file checked is recorded once, in order, refused ones included.
        let used = access.files_used();
        assert_eq!(used.first(), Some(&inside.join("a.obj")));
        assert_eq!(used.iter().filter(|p| p.ends_with("a.obj")).count(), 1);
        assert!(used.iter().any(|p| p.ends_with("none.png")));
    }
}
