//! Mitsuba scene files (`.xml`), read as Mitsuba 3 reads them and turned into our scene
//! format: the 0.x dialect (camelCase, `lookAt`) and the 2.x/3.x one (snake_case),
//! `<default>` and `$name` substitution (`-D name=value` wins), `<ref>`, `<include>`,
//! transforms, `rgb`, `srgb` and `spectrum` values reduced to RGB as Mitsuba's RGB variants
//! reduce them.
//!
//! The translation goes through a TOML document of our format ([`to_toml`]), so
//! `render convert` writes exactly what `render scene.xml` renders. Every element and
//! parameter is either translated, refused with one error line naming the file, line and
//! what is missing, or (when it cannot change the image, or changes only the noise) accepted
//! with one warning line. docs/scene-format.md ("Mitsuba scene files") lists what is read.
//!
//! Modules: `xml` (reading, includes, substitution, the old dialect), `props` (typed
//! parameters, transforms), `spectrum` and `cie` (Mitsuba's spectrum-to-RGB reduction and
//! its tables), `bsdf` (materials) and `scene` (sensors, shapes, emitters, integrator).

mod bsdf;
mod cie;
mod props;
mod scene;
mod spectrum;
mod xml;

use std::path::{Path, PathBuf};

use crate::error::SceneError;
use crate::files::FileAccess;
use crate::LoadedScene;

/// A Mitsuba scene translated to our format.
#[derive(Debug)]
pub struct Converted {
    /// The TOML document.
    pub toml: String,
    /// One line per parameter accepted but ignored, or approximated.
    pub warnings: Vec<String>,
}

/// Translates the Mitsuba scene at `path` to a TOML document whose file names are relative to
/// `out_dir` (absolute when either directory cannot be resolved). `defines` are
/// `-D name=value`.
pub fn to_toml(
    path: &Path,
    out_dir: Option<&Path>,
    access: &FileAccess,
    defines: &[(String, String)],
) -> Result<Converted, SceneError> {
    let root = xml::read(path, access, defines)?;
    let scene_dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // The way from the TOML's directory to the scene's: empty beside it.
    let prefix = match out_dir {
        None => Some(PathBuf::new()),
        Some(o) => match (canonical_dir(o), canonical_dir(&scene_dir)) {
            (Some(from), Some(to)) => Some(relative_path(&from, &to)),
            _ => None,
        },
    };
    let absolute_dir = canonical_dir(&scene_dir).unwrap_or_else(|| scene_dir.clone());
    let file_name = |name: &str| -> String {
        let joined = match &prefix {
            _ if Path::new(name).is_absolute() => return name.to_string(),
            Some(p) if p.as_os_str().is_empty() => return name.to_string(),
            Some(p) => p.join(name),
            None => absolute_dir.join(name),
        };
        // Forward slashes: the TOML stays usable on any system.
        joined.to_string_lossy().replace('\\', "/")
    };
    let mut warnings = Vec::new();
    let table = scene::build(&root, &file_name, &mut warnings)?;
    let body = toml::to_string(&table)
        .map_err(|e| SceneError::file(path, format!("cannot write TOML: {e}")))?;
    let toml = format!(
        "# Converted from {} by `render convert`.\n\n{body}",
        path.file_name().unwrap_or_default().to_string_lossy()
    );
    Ok(Converted { toml, warnings })
}

fn canonical_dir(p: &Path) -> Option<PathBuf> {
    std::fs::canonicalize(if p.as_os_str().is_empty() {
        Path::new(".")
    } else {
        p
    })
    .ok()
}

/// The relative path leading from directory `from` to directory `to` (both canonical).
fn relative_path(from: &Path, to: &Path) -> PathBuf {
    let (f, t): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = f.iter().zip(&t).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}

/// Translates the Mitsuba scene at `path` and writes the TOML to `output` atomically
/// (`render convert`); returns the warnings.
pub fn convert_file(
    path: &Path,
    output: &Path,
    defines: &[(String, String)],
) -> Result<Vec<String>, SceneError> {
    if !crate::is_mitsuba(path) {
        return Err(SceneError::file(path, "not a Mitsuba scene file (.xml)"));
    }
    let out_dir = output.parent().unwrap_or(Path::new(""));
    let converted = to_toml(path, Some(out_dir), &FileAccess::open(), defines)?;
    rt_film::write_bytes_atomic(output, converted.toml.as_bytes())
        .map_err(|e| SceneError::file(output, format!("cannot write: {e}")))?;
    Ok(converted.warnings)
}

/// `NAME=VALUE` of `-D` (NAME of ASCII letters, digits and `_`).
pub fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v))
            if !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') =>
        {
            Ok((k.to_string(), v.to_string()))
        }
        _ => Err(format!(
            "`{s}` is not NAME=VALUE (NAME of letters, digits and _)"
        )),
    }
}

/// Loads the Mitsuba scene at `path` (through its TOML translation).
pub fn load(
    path: &Path,
    access: &FileAccess,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    let converted = to_toml(path, None, access, defines)?;
    let base = path.parent().unwrap_or(Path::new(""));
    let mut loaded = crate::load::load(&converted.toml, base, path, access)?;
    let mut warnings = converted.warnings;
    warnings.append(&mut loaded.warnings);
    loaded.warnings = warnings;
    Ok(loaded)
}
