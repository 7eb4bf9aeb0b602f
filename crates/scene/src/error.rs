//! [`SceneError`]: every way loading a scene can fail, as one line that names the file.
//!
//! Problems in the TOML carry the line and column of the offending value (computed from the
//! `toml` span), problems in a mesh, texture or environment file carry that file's path. The
//! message is always a single line, so the CLI can print it as is.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A line and column in a text file, both 1-based (the column counts characters, not bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineCol {
    /// Line, from 1.
    pub line: usize,
    /// Column in characters, from 1.
    pub col: usize,
}

impl LineCol {
    /// The position of byte `offset` in `text` (clamped to the text; an offset inside a
    /// multi-byte character counts as that character).
    pub fn of_offset(text: &str, offset: usize) -> Self {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        Self { line, col }
    }
}

impl fmt::Display for LineCol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.col)
    }
}

/// Why a scene could not be loaded. `Display` gives one line that starts with the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A problem in the scene description itself: malformed TOML, an unknown key, a value out
    /// of range, an undefined name. `at` is the position of the offending value when known.
    #[error("{}{}: {message}", file.display(), at.map(|p| format!(":{p}")).unwrap_or_default())]
    Scene {
        /// The TOML file (as the caller named it).
        file: PathBuf,
        /// Line and column of the problem.
        at: Option<LineCol>,
        /// What is wrong.
        message: String,
    },
    /// A problem with a file: the scene file or a file it refers to (mesh, texture,
    /// environment map) is missing, unreadable or malformed.
    #[error("{}: {message}", file.display())]
    File {
        /// The file with the problem.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Joins the lines of a message so that errors stay one line whatever a dependency says.
fn one_line(s: impl Into<String>) -> String {
    let s = s.into();
    if !s.contains('\n') {
        return s;
    }
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

impl SceneError {
    /// A problem with `file` (missing, unreadable, malformed).
    pub fn file(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::File {
            file: file.into(),
            message: one_line(message),
        }
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Scene { file, .. } | Self::File { file, .. } => file,
        }
    }

    /// The problem, without the file name and position.
    pub fn message(&self) -> &str {
        match self {
            Self::Scene { message, .. } | Self::File { message, .. } => message,
        }
    }
}

/// Where errors about the TOML text point: the file name for messages and the text for turning
/// byte spans into line:col.
#[derive(Clone, Copy)]
pub(crate) struct Source<'a> {
    pub name: &'a Path,
    pub text: &'a str,
}

impl Source<'_> {
    /// An error at byte span `span` of the TOML text.
    pub fn error_at(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::Scene {
            file: self.name.to_path_buf(),
            at: Some(LineCol::of_offset(self.text, span.start)),
            message: one_line(message),
        }
    }

    /// An error about the scene as a whole (no position).
    pub fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError::Scene {
            file: self.name.to_path_buf(),
            at: None,
            message: one_line(message),
        }
    }

    /// Converts a `toml` deserialisation error, keeping its position. Serde's type errors do
    /// not say which key they are about ("invalid type: string \"wide\", expected f32"), so
    /// the key (or table header) at the position is put in front, with a hint for the
    /// common mix-up of `[table]` and `[[table]]`.
    pub fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        let Some(span) = e.span() else {
            return self.error(e.message());
        };
        let msg = e.message();
        let at = &self.text[span.start.min(self.text.len())..];
        let names_key = ["unknown field", "missing field", "duplicate key"]
            .iter()
            .any(|k| msg.contains(k));
        let message = if at.starts_with('[')
            && at
                .lines()
                .next()
                .is_some_and(|l| l.trim_end().ends_with(']'))
            && !names_key
        {
            let header = at.lines().next().unwrap_or_default().trim();
            let name = header.trim_matches(|c| c == '[' || c == ']').trim();
            let hint = match (header.starts_with("[["), name) {
                (true, "environment" | "render") => {
                    format!(" (`{name}` is a single table: write [{name}])")
                }
                (false, "camera" | "material" | "geometry" | "assign") => {
                    format!(" (`{name}` is an array of tables: write [[{name}]])")
                }
                _ => String::new(),
            };
            format!("{header}: {msg}{hint}")
        } else {
            match key_before(self.text, span.start) {
                Some(key) if !names_key => format!("`{key}`: {msg}"),
                _ => msg.to_string(),
            }
        };
        self.error_at(span, message)
    }
}

/// The key whose value contains byte `offset`: the bare key before the last `=` ahead of it
/// (ignoring `=` in comments). A heuristic for messages only.
fn key_before(text: &str, offset: usize) -> Option<&str> {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let mut end = before.len();
    loop {
        let eq = before[..end].rfind('=')?;
        let line_start = before[..eq].rfind('\n').map_or(0, |i| i + 1);
        if before[line_start..eq].contains('#') {
            end = eq;
            continue;
        }
        let lhs = before[..eq].trim_end();
        // The character before the key may be several bytes long (found by fuzzing).
        let start = lhs
            .char_indices()
            .rfind(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
            .map_or(0, |(i, c)| i + c.len_utf8());
        let key = &lhs[start..];
        return (!key.is_empty()).then_some(key);
    }
}

/// The crate's result type.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_after_a_multibyte_character_is_found() {
        // fuzz/seeds/scene_toml/crash-key-after-multibyte: a key right after a four-byte
        // character sliced the text inside it.
        let text = "name =\"\u{10968b}rceis =";
        assert_eq!(key_before(text, text.len()), Some("rceis"));
        let bytes = std::fs::read(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../fuzz/seeds/scene_toml/crash-key-after-multibyte"),
        )
        .unwrap();
        let e = crate::load_str(
            &String::from_utf8_lossy(&bytes),
            Path::new("."),
            Path::new("f.toml"),
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("f.toml:"), "{e}");
    }

    #[test]
    fn line_col_counts_lines_and_characters_from_one() {
        let t = "a = 1\nbé = [1, 2]\n";
        assert_eq!(LineCol::of_offset(t, 0), LineCol { line: 1, col: 1 });
        assert_eq!(LineCol::of_offset(t, 6), LineCol { line: 2, col: 1 });
        // "bé = " is 6 bytes but 5 characters: '[' is column 6.
        let at = t.find('[').unwrap();
        assert_eq!(LineCol::of_offset(t, at), LineCol { line: 2, col: 6 });
        assert_eq!(LineCol::of_offset(t, 1000).line, 3);
    }

    fn toml_err(text: &str) -> String {
        let e = toml::from_str::<crate::desc::SceneDesc>(text).unwrap_err();
        Source {
            name: Path::new("x.toml"),
            text,
        }
        .toml_error(&e)
        .to_string()
    }

    #[test]
    fn toml_type_errors_name_the_key_or_the_table() {
        let cam = "[[camera]]\nname = \"c\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n";
        assert_eq!(
            toml_err(&format!("{cam}fov = \"wide\"\n")),
            "x.toml:5:7: `fov`: invalid type: string \"wide\", expected f32"
        );
        assert_eq!(
            toml_err(
                "[[geometry]]\nname = \"g\" # a = b\nvertices = [\n  [0, 0, 0],\n  [1, 0],\n]\n"
            ),
            "x.toml:5:3: `vertices`: invalid length 2, expected an array of 3 numbers"
        );
        assert_eq!(
            toml_err("[[geometry]]\nname = \"g\"\ntransform = { scale = \"big\" }\n"),
            "x.toml:3:23: `scale`: invalid type: string \"big\", expected a number or an array of 3 numbers"
        );
        let e = toml_err("[camera]\nname = \"x\"\n");
        assert!(
            e.starts_with("x.toml:1:1: [camera]: invalid type: map, expected a sequence"),
            "{e}"
        );
        assert!(
            e.ends_with("(`camera` is an array of tables: write [[camera]])"),
            "{e}"
        );
        let e = toml_err("[[environment]]\ncolor = [0, 0, 0]\n");
        assert!(e.starts_with("x.toml:1:1: [[environment]]: "), "{e}");
        assert!(
            e.ends_with("(`environment` is a single table: write [environment])"),
            "{e}"
        );
        // Messages that name their key are left alone.
        assert_eq!(
            toml_err("[render]\nsamples = 4\n"),
            "x.toml:2:1: unknown field `samples`, expected one of `spp`, `integrator`, `accel`, `max_depth`, `seed`, `threads`, `aov`, `output`, `denoiser`"
        );
    }

    #[test]
    fn display_is_one_line_with_file_and_position() {
        let src = Source {
            name: Path::new("scenes/x.toml"),
            text: "\n\n  material = \"red\"",
        };
        let e = src.error_at(15..20, "material \"red\"\nis not defined");
        assert_eq!(
            e.to_string(),
            "scenes/x.toml:3:14: material \"red\"; is not defined"
        );
        let e = SceneError::file("m/a.obj", "cannot open: gone");
        assert_eq!(e.to_string(), "m/a.obj: cannot open: gone");
        assert_eq!(
            src.error("no camera").to_string(),
            "scenes/x.toml: no camera"
        );
    }
}
