//! The reference cache: high-sample references stored on disk under a key that changes with
//! anything that changes the image, so that each is rendered once.
//!
//! The key is the SHA-256 of a short text listing:
//! - a format version ([`CACHE_VERSION`]);
//! - the SHA-256 of the scene file's bytes;
//! - the SHA-256 of the loaded scene: every triangle, normal, UV, material, texture texel,
//!   environment texel and camera as the renderer sees them, floats by their bits
//!   ([`rt_core::ContentHash`]). This is how the content of every file the scene references
//!   (meshes with their `.mtl`s and buffers, textures, environment maps) enters the key,
//!   whatever loader read it;
//! - the camera actually rendered (after any resolution override), the integrator, bounce
//!   limit, ao distance, samples per pixel, seed and stream.
//!
//! The acceleration structure and thread count are not in it: they do not change the image.
//! Renderer code is not either: bump [`CACHE_VERSION`] when a change alters what a scene
//! renders to, or delete the cache directory. SHA-256 rather than `std`'s `DefaultHasher`,
//! whose output may change between Rust releases.
//!
//! Each entry is `<scene>-<key>.exr` (R, G, B and `variance.*`, the variance of each pixel
//! mean) and `<scene>-<key>.json` (what went into the key, and the render's time). An entry
//! counts only when both exist and the sidecar's key matches, so an interrupted store is
//! re-rendered rather than trusted.

use crate::error::{io, ExperimentError, Result};
use rt_core::{Camera, ContentHash, Scene};
use rt_film::Film;
use rt_integrators::IntegratorSpec;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Bump when the renderer's output for the same settings changes, to retire old entries.
pub const CACHE_VERSION: u32 = 3;

/// The default cache directory, relative to the working directory.
pub const DEFAULT_CACHE_DIR: &str = ".render-cache/references";

/// Everything that determines a reference image.
pub struct ReferenceRequest<'a> {
    /// The scene file as named by the user (or `gen:NAME`).
    pub scene_path: &'a Path,
    /// The loaded scene.
    pub scene: &'a Scene,
    /// The camera to render, already resized.
    pub camera: &'a Camera,
    /// Integrator and parameters.
    pub estimator: IntegratorSpec,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the reference stream.
    pub seed: u32,
}

/// A cache key and the description it was made from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Key {
    /// Hex SHA-256 of `description`.
    pub hex: String,
    /// The text that was hashed, one `name value` per line.
    pub description: String,
}

/// The sidecar file of a cache entry.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Sidecar {
    /// The full key.
    pub key: String,
    /// What went into the key, one `name value` per line.
    pub description: String,
    /// The scene file as named when the reference was rendered.
    pub scene: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Render time in seconds.
    pub seconds: f64,
    /// Camera samples per second of that render.
    pub samples_per_second: f64,
}

/// The SHA-256 of `value`'s content.
fn content_digest(value: &impl ContentHash) -> String {
    let mut hash = Sha256::new();
    value.content_hash(&mut |bytes: &[u8]| hash.update(bytes));
    hex(&hash.finalize())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

impl ReferenceRequest<'_> {
    /// The cache key. Reads the scene file (a `gen:` scene hashes its name).
    pub fn key(&self) -> Result<Key> {
        let name = self.scene_path.to_string_lossy();
        let file_bytes = if name.starts_with("gen:") {
            name.as_bytes().to_vec()
        } else {
            std::fs::read(self.scene_path).map_err(|e| {
                ExperimentError::Run(format!("{}: cannot open: {e}", self.scene_path.display()))
            })?
        };
        let e = &self.estimator;
        let description = format!(
            "version {CACHE_VERSION}\nscene-file {}\nscene-data {}\ncamera {} {}x{} {}\n\
             integrator {}\nmax-depth {}\nao-distance {}\nspp {}\nseed {}\nstream reference\n",
            hex(&Sha256::digest(&file_bytes)),
            content_digest(self.scene),
            self.camera.name,
            self.camera.width,
            self.camera.height,
            content_digest(self.camera),
            e.kind,
            e.depth(),
            e.ao_distance,
            self.spp,
            self.seed,
        );
        Ok(Key {
            hex: hex(&Sha256::digest(description.as_bytes())),
            description,
        })
    }
}

/// A directory of references.
pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    /// The cache in `dir` (created when the first entry is stored).
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
        }
    }

    /// Where the entry for `scene_path` and `key` lives: its EXR and its sidecar. The scene's
    /// file stem is only there for people browsing the directory; 32 hex digits (128 bits) of
    /// the key name the file, and the sidecar holds all of it.
    fn paths(&self, scene_path: &Path, key: &Key) -> (PathBuf, PathBuf) {
        let stem: String = scene_path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let base = format!("{stem}-{}", &key.hex[..32]);
        (
            self.dir.join(format!("{base}.exr")),
            self.dir.join(format!("{base}.json")),
        )
    }

    /// The cached EXR for `key` and its sidecar, if there is a complete entry.
    pub fn lookup(&self, scene_path: &Path, key: &Key) -> Option<(PathBuf, Sidecar)> {
        let (exr, json) = self.paths(scene_path, key);
        let sidecar: Sidecar = serde_json::from_slice(&std::fs::read(&json).ok()?).ok()?;
        (sidecar.key == key.hex && exr.is_file()).then_some((exr, sidecar))
    }

    /// Stores a rendered reference (the film must keep the `variance` AOV) and returns the
    /// EXR's path. The image first, the sidecar last: an entry without its sidecar is a miss.
    pub fn store(
        &self,
        scene_path: &Path,
        key: &Key,
        film: &Film,
        sidecar: &Sidecar,
    ) -> Result<PathBuf> {
        std::fs::create_dir_all(&self.dir).map_err(io(&self.dir))?;
        let (exr, json) = self.paths(scene_path, key);
        rt_film::write_image(&exr, film, &rt_film::OutputOptions::default())?;
        let text = serde_json::to_string_pretty(sidecar).expect("a sidecar always serialises");
        rt_film::write_bytes_atomic(&json, text.as_bytes())?;
        Ok(exr)
    }

    /// Merges the parts of one reference (a reference job's parts, `render reference
    /// --sample-range/--region` or a plan's) and stores it under the cache key their headers
    /// carry; returns the EXR's path and the sidecar. Refuses parts of a normal render.
    /// `limit`: the most bytes the merged film may hold.
    pub fn store_parts(
        &self,
        parts: &[(String, rt_parts::Part)],
        limit: Option<u64>,
    ) -> Result<(PathBuf, Sidecar)> {
        let merged =
            rt_parts::merge(parts, limit).map_err(|e| ExperimentError::Run(e.to_string()))?;
        let h = &merged.header;
        let first = &parts[0].0;
        let setting = |k: &str| {
            h.settings.get(k).cloned().ok_or_else(|| {
                ExperimentError::Run(format!("{first}: not a reference's part (no {k})"))
            })
        };
        if setting("stream")? != "reference" {
            return Err(ExperimentError::Run(format!(
                "{first}: not a reference's part"
            )));
        }
        let key = Key {
            hex: setting("cache key")?,
            description: setting("cache description")?,
        };
        let seconds: f64 = parts.iter().map(|(_, p)| p.header.seconds).sum();
        let samples = u64::from(h.width) * u64::from(h.height) * u64::from(h.spp);
        let sidecar = Sidecar {
            key: key.hex.clone(),
            description: key.description.clone(),
            scene: h.scene.clone(),
            width: h.width,
            height: h.height,
            spp: h.spp,
            seconds,
            samples_per_second: samples as f64 / seconds.max(1e-9),
        };
        let path = self.store(Path::new(&h.scene), &key, &merged.film, &sidecar)?;
        Ok((path, sidecar))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::glam::Vec3;
    use rt_integrators::IntegratorKind;

    const SCENE: &str = r#"
[[camera]]
name = "main"
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
resolution = [8, 6]

[[material]]
name = "lamp"
emission = [5.0, 5.0, 5.0]

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.3, 2, -0.3], [0.3, 2, -0.3], [0.3, 2, 0.3], [-0.3, 2, 0.3]]
material = "lamp"
"#;

    fn key_of(dir: &Path, text: &str, tweak: impl Fn(&mut ReferenceRequest)) -> Key {
        let path = dir.join("s.toml");
        std::fs::write(&path, text).unwrap();
        let loaded = rt_scene::load(&path).unwrap();
        let camera = loaded.scene.cameras[0].clone();
        let mut req = ReferenceRequest {
            scene_path: &path,
            scene: &loaded.scene,
            camera: &camera,
            estimator: IntegratorSpec::new(IntegratorKind::Path)
                .with_max_depth(8)
                .unwrap(),
            spp: 64,
            seed: 0,
        };
        tweak(&mut req);
        req.key().unwrap()
    }

    #[test]
    fn key_follows_everything_that_changes_the_image_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let base = key_of(d, SCENE, |_| {});
        assert_eq!(base.hex.len(), 64);
        assert_eq!(base, key_of(d, SCENE, |_| {}), "not deterministic");
        assert!(base.description.contains("spp 64\n"));
        // The file's bytes count, even when the scene is the same.
        assert_ne!(base.hex, key_of(d, &format!("# note\n{SCENE}"), |_| {}).hex);
        // So does the scene's content.
        let brighter = SCENE.replace("[5.0, 5.0, 5.0]", "[6.0, 5.0, 5.0]");
        assert_ne!(base.hex, key_of(d, &brighter, |_| {}).hex);
        // And every setting.
        assert_ne!(base.hex, key_of(d, SCENE, |r| r.spp = 128).hex);
        assert_ne!(base.hex, key_of(d, SCENE, |r| r.seed = 1).hex);
        assert_ne!(
            base.hex,
            key_of(d, SCENE, |r| r.estimator.max_depth = Some(4)).hex
        );
        assert_ne!(
            base.hex,
            key_of(d, SCENE, |r| r.estimator.kind = IntegratorKind::PathBsdf).hex
        );
    }

    #[test]
    fn referenced_files_enter_the_key_through_the_loaded_scene() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let with_mesh =
            format!("{SCENE}\n[[geometry]]\nname = \"m\"\nfile = \"m.obj\"\nmaterial = \"lamp\"\n");
        std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let a = key_of(d, &with_mesh, |_| {});
        std::fs::write(d.join("m.obj"), "v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let b = key_of(d, &with_mesh, |_| {});
        assert_ne!(a.hex, b.hex);
    }

    #[test]
    fn entries_need_their_sidecar_and_matching_key() {
        let dir = tempfile::tempdir().unwrap();
        let cache = Cache::new(&dir.path().join("cache"));
        let key = Key {
            hex: "ab".repeat(32),
            description: "x".into(),
        };
        let scene = Path::new("scenes/my scene.toml");
        assert!(cache.lookup(scene, &key).is_none());
        let mut film = Film::new(2, 2, rt_film::AovSet::default());
        film.add_sample(0, 0, 0, Vec3::ONE, None);
        let sidecar = Sidecar {
            key: key.hex.clone(),
            description: key.description.clone(),
            scene: scene.display().to_string(),
            width: 2,
            height: 2,
            spp: 1,
            seconds: 0.5,
            samples_per_second: 8.0,
        };
        let exr = cache.store(scene, &key, &film, &sidecar).unwrap();
        assert!(exr.ends_with(format!("my_scene-{}.exr", "ab".repeat(16))));
        assert_eq!(cache.lookup(scene, &key), Some((exr.clone(), sidecar)));
        let other = Key {
            hex: format!("{}{}", "ab".repeat(16), "cd".repeat(16)),
            ..key.clone()
        };
        assert!(
            cache.lookup(scene, &other).is_none(),
            "same file name, other key"
        );
        std::fs::remove_file(exr.with_extension("json")).unwrap();
        assert!(cache.lookup(scene, &key).is_none());
    }
}
