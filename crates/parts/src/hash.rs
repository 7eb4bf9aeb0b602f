//! Identities: of a scene's content and of the renderer's build.

use sha2::{Digest, Sha256};
use std::path::Path;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 over the content of `files`, in order (each preceded by its length, so that
/// content cannot shift from one file to the next), and over `extra` (for a procedural scene
/// with no file, its name). Paths are left out: the same scene under another mount point of a
/// farm's nodes hashes the same. A file that cannot be read hashes as its error.
pub fn content_hash(files: &[impl AsRef<Path>], extra: &str) -> String {
    let mut h = Sha256::new();
    h.update(extra.as_bytes());
    for f in files {
        match std::fs::read(f) {
            Ok(b) => {
                h.update((b.len() as u64).to_le_bytes());
                h.update(&b);
            }
            Err(e) => h.update(format!("unreadable: {}", e.kind()).as_bytes()),
        }
    }
    hex(&h.finalize())
}

/// The running executable's identity: its version and the SHA-256 of its file (so a part
/// rendered by another build, which may round differently, is told apart). Computed once.
pub fn binary_id(version: &str) -> String {
    static ID: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ID.get_or_init(|| {
        let exe = std::env::current_exe().and_then(std::fs::read);
        match exe {
            Ok(b) => format!("{version}+{}", &hex(&Sha256::digest(&b))[..16]),
            Err(_) => format!("{version}+unknown"),
        }
    })
    .clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_not_paths() {
        let d = tempfile::tempdir().unwrap();
        let (a, b, c) = (d.path().join("a"), d.path().join("b"), d.path().join("c"));
        std::fs::write(&a, "xy").unwrap();
        std::fs::write(&b, "xy").unwrap();
        std::fs::write(&c, "xz").unwrap();
        assert_eq!(content_hash(&[&a], ""), content_hash(&[&b], ""));
        assert_ne!(content_hash(&[&a], ""), content_hash(&[&c], ""));
        assert_ne!(content_hash(&[&a, &b], ""), content_hash(&[&a], ""));
        assert_ne!(
            content_hash(&[] as &[&Path], "gen:a"),
            content_hash(&[] as &[&Path], "gen:b")
        );
        assert!(binary_id("1").starts_with("1+"));
    }
}
