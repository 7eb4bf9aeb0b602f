//! File names of numbered frames: `{frame}` and `{frame:0N}` in a path, as a job with several
//! frames writes them ([`crate::RenderJob::output`]) and `render compare --frames` reads them.

use std::path::{Path, PathBuf};

/// Whether `pattern` has a frame placeholder (`{frame` followed by anything).
pub fn names_frame(pattern: &Path) -> bool {
    pattern.to_string_lossy().contains("{frame")
}

/// `pattern` with `{frame}` replaced by the frame number and `{frame:0N}` by it padded to N
/// digits. Anything else in braces, and an unclosed `{frame`, is kept as written.
pub fn frame_path(pattern: &Path, frame: u32) -> PathBuf {
    let text = pattern.to_string_lossy();
    let mut out = String::new();
    let mut rest = text.as_ref();
    while let Some(i) = rest.find("{frame") {
        out.push_str(&rest[..i]);
        let tail = &rest[i + "{frame".len()..];
        let Some(end) = tail.find('}') else {
            out.push_str(&rest[i..]);
            rest = "";
            break;
        };
        let spec = &tail[..end];
        match spec
            .strip_prefix(":0")
            .and_then(|w| w.parse::<usize>().ok())
        {
            Some(width) => out.push_str(&format!("{frame:0width$}")),
            None if spec.is_empty() => out.push_str(&frame.to_string()),
            None => out.push_str(&rest[i..i + "{frame".len() + end + 1]),
        }
        rest = &tail[end + 1..];
    }
    out.push_str(rest);
    PathBuf::from(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(pattern: &str, frame: u32) -> String {
        frame_path(Path::new(pattern), frame)
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn placeholders_are_replaced() {
        assert_eq!(p("out/f_{frame}.exr", 7), "out/f_7.exr");
        assert_eq!(p("f_{frame:04}.exr", 7), "f_0007.exr");
        assert_eq!(p("f_{frame:02}.exr", 123), "f_123.exr");
        assert_eq!(p("{frame}/{frame:03}.png", 5), "5/005.png");
        assert_eq!(p("plain.exr", 5), "plain.exr");
    }

    #[test]
    fn other_braces_are_kept() {
        assert_eq!(p("f_{frame:x}.exr", 1), "f_{frame:x}.exr");
        assert_eq!(p("f_{frame.exr", 1), "f_{frame.exr");
        assert_eq!(p("{name}_{frame}.exr", 2), "{name}_2.exr");
        assert!(names_frame(Path::new("a_{frame:04}.exr")));
        assert!(!names_frame(Path::new("a.exr")));
    }
}
