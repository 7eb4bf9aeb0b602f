//! `rt-fuzzing`: every file format the renderer reads, behind one function that takes the
//! file's bytes, loads them with the shipped loader and drops the result. The cargo-fuzz
//! targets in `fuzz/` call these (a campaign, outside CI: docs/testing.md, "Fuzzing"), and
//! `tests/replay.rs` runs them over the committed seeds (`fuzz/seeds/<target>/`, with every
//! crash found as `crash-*`) and corpus (`fuzz/corpus/<target>/`) in CI, so every input a
//! campaign kept, and every crash it found, stays a test.
//!
//! An input passes when its loader returns, `Ok` or `Err`; a panic, a hang or an allocation
//! the fuzzer's memory limit refuses is a failure. Depends on rt-scene, rt-film,
//! rt-experiment and rt-parts (the loaders) and tempfile. Dev-only, like rt-testkit: no shipped crate
//! depends on it.
//!
//! ```
//! // A scene file with a stray byte is an error, not a panic.
//! rt_fuzzing::scene_toml(b"[[camera]]\nname = \"c\"\x00");
//! ```

use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// A fuzz target: the bytes of one input file.
pub type Target = fn(&[u8]);

/// The fuzz targets by name, as in `fuzz/fuzz_targets/`, `fuzz/seeds/` and `fuzz/corpus/`.
pub const TARGETS: [(&str, Target); 12] = [
    ("scene_toml", scene_toml),
    ("mitsuba_xml", mitsuba_xml),
    ("experiment_toml", experiment_toml),
    ("obj", obj),
    ("gltf", gltf),
    ("glb", glb),
    ("ra2", ra2),
    ("ply", ply),
    ("exr", exr),
    ("image", image),
    ("part", part),
    ("plan", plan),
];

thread_local! {
    /// One scratch directory per thread for the loaders that read a path.
    static SCRATCH: RefCell<Option<tempfile::TempDir>> = const { RefCell::new(None) };
}

/// Writes `data` to `name` in this thread's scratch directory and calls `load` on the path.
fn with_file(name: &str, data: &[u8], load: impl FnOnce(&Path)) {
    let path: PathBuf = SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        let dir = s.get_or_insert_with(|| tempfile::tempdir().expect("a scratch directory"));
        dir.path().join(name)
    });
    std::fs::write(&path, data).expect("the scratch directory is writable");
    load(&path);
}

/// A scene file (`rt_scene::load`), read from a directory holding nothing else, so that the
/// files it names are missing (their loaders have targets of their own).
pub fn scene_toml(data: &[u8]) {
    with_file("scene.toml", data, |p| {
        let _ = rt_scene::load(p);
    });
}

/// A Mitsuba scene file (`rt_scene::load` of a `.xml`), alone in its directory like
/// [`scene_toml`]'s.
pub fn mitsuba_xml(data: &[u8]) {
    with_file("scene.xml", data, |p| {
        let _ = rt_scene::load(p);
    });
}

/// An experiment file (`rt_experiment::config::load`, which also loads the scenes it names).
pub fn experiment_toml(data: &[u8]) {
    with_file("experiment.toml", data, |p| {
        let _ = rt_experiment::config::load(p);
    });
}

/// An OBJ mesh with its materials (`rt_scene::load_mesh`).
pub fn obj(data: &[u8]) {
    with_file("mesh.obj", data, |p| {
        let _ = rt_scene::load_mesh(p);
    });
}

/// A glTF file (JSON).
pub fn gltf(data: &[u8]) {
    with_file("mesh.gltf", data, |p| {
        let _ = rt_scene::load_mesh(p);
    });
}

/// A binary glTF file.
pub fn glb(data: &[u8]) {
    with_file("mesh.glb", data, |p| {
        let _ = rt_scene::load_mesh(p);
    });
}

/// A `.ra2` triangle file.
pub fn ra2(data: &[u8]) {
    with_file("mesh.ra2", data, |p| {
        let _ = rt_scene::load_mesh(p);
    });
}

/// A Stanford PLY mesh.
pub fn ply(data: &[u8]) {
    with_file("mesh.ply", data, |p| {
        let _ = rt_scene::load_mesh(p);
    });
}

/// An EXR image, as `render compare` reads it (`rt_film::read_rgb`) and as `render denoise`
/// reads a saved frame (`NoisyFrame::from_exr`).
pub fn exr(data: &[u8]) {
    with_file("image.exr", data, |p| {
        let _ = rt_film::read_rgb(p);
        let _ = rt_film::NoisyFrame::from_exr(p);
    });
}

/// A PNG or JPEG image (`rt_film::decode_srgb`, the decoder of image files and of images
/// inside glTF files).
pub fn image(data: &[u8]) {
    let _ = rt_film::decode_srgb(data);
}

/// A part file or checkpoint (`rt_parts::Part::from_bytes`), merged alone into a film of its
/// header's size (refused above 64 MiB, as `render merge --max-memory 64M` would) and read.
/// Twice: as given (so damage is caught by the checksum), and with the checksum made right
/// for the bytes before it, so that mutations reach the header and the sums behind it.
pub fn part(data: &[u8]) {
    part_bytes(data);
    if let Some(body) = data.len().checked_sub(32).map(|n| &data[..n]) {
        use sha2::Digest;
        let mut fixed = body.to_vec();
        fixed.extend_from_slice(&sha2::Sha256::digest(body));
        part_bytes(&fixed);
    }
}

fn part_bytes(data: &[u8]) {
    if let Ok(p) = rt_parts::Part::from_bytes(data) {
        if let Ok(m) = rt_parts::merge(&[("fuzz".to_string(), p)], Some(64 << 20)) {
            let _ = m.film.mean_image();
        }
    }
}

/// A plan (`rt_parts::Plan::from_json`), as `render part` and `render merge --plan` read it.
pub fn plan(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = rt_parts::Plan::from_json(text);
    }
}
