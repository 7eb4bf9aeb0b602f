//! `rt-scene`: the scene file format and the mesh loaders.
//!
//! This is the only crate that knows scene and mesh file formats. It turns a scene file
//! (TOML, documented key by key in `docs/scene-format.md`, or Mitsuba's XML, translated into
//! TOML by [`mitsuba`]) into the plain runtime
//! [`rt_core::Scene`] that the accelerators and integrators read, plus the optional `[render]`
//! defaults ([`RenderDesc`]) that the `render` CLI merges with its flags. Nothing downstream
//! sees a file format, so a new format is a new module here and nothing else.
//!
//! The pipeline is: parse the text into serde `*Desc` structs (`desc`, which denies unknown
//! keys everywhere), then build the scene section by section (`load`): environment (EXR maps in
//! `image_io`), cameras, materials (`material`, textures in `image_io`), geometry (`geometry`,
//! which dispatches to `shapes`, `obj`, `gltf` and `raw`, then places, checks and appends the
//! triangles in file order), material assignments, and finally the light sampler.
//!
//! Every failure is a [`SceneError`] whose `Display` is one line naming the file and the
//! problem, with `line:col` when the problem is in the TOML:
//!
//! ```
//! use std::path::Path;
//! let toml = r#"
//! [[camera]]
//! name = "main"
//! position = [0, 1, 4]
//! look_at = [0, 1, 0]
//!
//! [[material]]
//! name = "light"
//! emission = [10, 10, 10]
//!
//! [[geometry]]
//! name = "lamp"
//! shape = "quad"
//! vertices = [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]]
//! material = "light"
//!
//! [[geometry]]
//! name = "floor"
//! shape = "quad"
//! vertices = [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]]
//! material = "white"
//! "#;
//! let err = rt_scene::load_str(toml, Path::new("."), Path::new("demo.toml")).unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "demo.toml:21:12: material \"white\" used by geometry \"floor\" is not defined"
//! );
//! let fixed = toml.replace("\"white\"", "\"light\"");
//! let loaded = rt_scene::load_str(&fixed, Path::new("."), Path::new("demo.toml")).unwrap();
//! assert_eq!(loaded.scene.triangle_count(), 4);
//! assert_eq!(loaded.scene.lights().emitter_count(), 4);
//! ```
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod blend;
mod desc;
mod error;
mod files;
mod geometry;
mod gltf;
mod image_io;
mod instances;
mod lights;
mod load;
mod material;
mod microfacet;
pub mod mitsuba;
mod obj;
mod param_desc;
mod ply;
pub mod procedural;
pub mod raw;
mod serialized;
mod shapes;
mod texture_desc;
pub mod views;

pub use error::{LineCol, SceneError};
pub use files::FileAccess;

use std::path::Path;

/// A loaded scene: the runtime scene, the `[render]` defaults and non-fatal remarks.
#[derive(Debug)]
pub struct LoadedScene {
    /// The runtime scene, ready to render (its light sampler is built on first use).
    pub scene: rt_core::Scene,
    /// Defaults from the optional `[render]` table; command-line flags take precedence.
    pub render: RenderDesc,
    /// Things worth telling the user that do not stop loading (zero-area triangles, unused
    /// materials, a scene without lights, ...), one line each.
    pub warnings: Vec<String>,
}

/// The optional `[render]` table: defaults for the `render` command's options. A missing key
/// is `None`; the CLI decides what that means. Only ranges are checked here (`spp >= 1`,
/// `threads >= 1`, a non-empty `denoiser`): the names of integrators, accelerators, AOVs and
/// denoisers belong to the crates that build them, checked when settings are resolved.
#[derive(Default, Clone, Debug)]
pub struct RenderDesc {
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Integrator name (`path`, `direct`, `ao`, ...).
    pub integrator: Option<String>,
    /// Acceleration structure name (`bvh`, ...).
    pub accel: Option<String>,
    /// Maximum path depth in bounces.
    pub max_depth: Option<u32>,
    /// Seed of the sample streams.
    pub seed: Option<u64>,
    /// Worker threads.
    pub threads: Option<usize>,
    /// Extra output layers (`albedo`, `normal`, `depth`, `position`, `variance`).
    pub aov: Option<Vec<String>>,
    /// Output image path, as `-o` would take it.
    pub output: Option<String>,
    /// Denoiser spec (`nlm`, `atrous:iterations=4`, ...) the `render` command filters its
    /// image with, as `--denoiser` would take it; its name and options are checked where
    /// settings are resolved (`rt_session`).
    pub denoiser: Option<String>,
}

/// Loads the scene file at `path`, or generates the procedural scene `gen:NAME`
/// ([`procedural::generate`], with an empty `[render]` table): what every command that takes
/// a scene argument accepts.
pub fn load_any(path: &Path) -> Result<LoadedScene, SceneError> {
    load_any_with(path, &FileAccess::open())
}

/// [`load_any`] reading files only as `access` allows (`render --confine DIR`).
pub fn load_any_with(path: &Path, access: &FileAccess) -> Result<LoadedScene, SceneError> {
    load_any_defined(path, access, &[])
}

/// [`load_any_with`] with a Mitsuba scene's `$name` parameters ([`load_defined`]).
pub fn load_any_defined(
    path: &Path,
    access: &FileAccess,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    if let Some(name) = path.to_str().and_then(|p| p.strip_prefix("gen:")) {
        let scene = procedural::generate(name).map_err(|e| SceneError::File {
            file: path.to_path_buf(),
            message: e.to_string(),
        })?;
        return Ok(LoadedScene {
            scene,
            render: RenderDesc::default(),
            warnings: Vec::new(),
        });
    }
    load_defined(path, access, defines)
}

/// Loads a bare mesh file (OBJ, glTF, .ra2) as a scene through the scene format: one grey
/// material, a white sky and a placeholder camera named `auto` (see [`views`] for real ones);
/// the mesh's own materials do not matter to the callers (benchmarks, stress cases).
pub fn load_mesh(path: &Path) -> Result<LoadedScene, SceneError> {
    let cannot = |e: std::io::Error| SceneError::File {
        file: path.to_path_buf(),
        message: format!("cannot open: {e}"),
    };
    let abs = std::fs::canonicalize(path).map_err(cannot)?;
    let Some(text) = abs.to_str() else {
        return Err(SceneError::File {
            file: path.to_path_buf(),
            message: "the path is not valid UTF-8".into(),
        });
    };
    let quoted = text.replace('\\', "\\\\").replace('"', "\\\"");
    let toml = format!(
        "[environment]\ncolor = [1, 1, 1]\n\n\
         [[camera]]\nname = \"auto\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n\n\
         [[material]]\nname = \"grey\"\n\n\
         [[geometry]]\nname = \"mesh\"\nfile = \"{quoted}\"\nmaterial = \"grey\"\n"
    );
    load_str(&toml, abs.parent().unwrap_or(Path::new("/")), path)
}

/// Loads the scene file at `path`. Relative paths inside it (meshes, textures, environment
/// maps) are resolved against the file's directory, and errors name `path` as given.
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    load_with(path, &FileAccess::open())
}

/// [`load`] reading files (the scene file too) only as `access` allows.
pub fn load_with(path: &Path, access: &FileAccess) -> Result<LoadedScene, SceneError> {
    load_defined(path, access, &[])
}

/// [`load_with`] with `$name` parameters of a Mitsuba scene file (`render -D name=value`):
/// a `.xml` file is read as a Mitsuba scene ([`mitsuba`]), anything else as TOML (where
/// parameters are refused: the format has none).
pub fn load_defined(
    path: &Path,
    access: &FileAccess,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    if is_mitsuba(path) {
        return mitsuba::load(path, access, defines);
    }
    if let Some((name, _)) = defines.first() {
        return Err(SceneError::file(
            path,
            format!("-D {name}=...: only Mitsuba scene files (.xml) take parameters"),
        ));
    }
    access.check(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| {
        let why = if e.kind() == std::io::ErrorKind::InvalidData {
            "cannot read: the file is not UTF-8 text".to_string()
        } else {
            format!("cannot open: {e}")
        };
        SceneError::file(path, why)
    })?;
    let base = path.parent().unwrap_or(Path::new(""));
    load::load(&text, base, path, access)
}

/// The mesh file extensions `[[geometry]] file` and [`load_mesh`] read (lower case).
pub const MESH_EXTENSIONS: [&str; 6] = ["obj", "ply", "serialized", "gltf", "glb", "ra2"];

/// Whether `path` names a Mitsuba scene file (`.xml`, any case).
pub fn is_mitsuba(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// Loads a scene from TOML text. Relative paths inside it are resolved against `base_dir`;
/// errors in the text are reported against `name_for_errors`.
pub fn load_str(
    toml: &str,
    base_dir: &Path,
    name_for_errors: &Path,
) -> Result<LoadedScene, SceneError> {
    load::load(toml, base_dir, name_for_errors, &FileAccess::open())
}
