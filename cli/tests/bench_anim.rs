//! `render bench-anim`: it runs on a tiny animated scene (a box moving over a lit floor) and
//! prints one row per structure and a CSV row per structure and frame; bad arguments are one
//! error line and a non-zero exit.

use std::path::Path;
use std::process::{Command, Output};

mod common;

use common::MOVING_BOX as SCENE;

fn bench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .arg("bench-anim")
        .args(args)
        .output()
        .unwrap()
}

/// The error lines of `out` (clap's closing "For more information" hint is not one).
fn error_lines(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("For more information"))
        .map(str::to_owned)
        .collect()
}

#[test]
fn runs_on_a_tiny_animated_scene() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let out = bench(
        d,
        &[
            "s.toml",
            "--frames",
            "0..3",
            "--fps",
            "1",
            "--size",
            "16x10",
            "--accel",
            "bvh8,two-level,clusters:t=4",
            "--repeat",
            "1",
            "--csv",
            "out.csv",
            "-q",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stderr.is_empty(), "-q: nothing on stderr");
    for name in ["bvh8", "two-level", "clusters:t=4", "update s", "trace s"] {
        assert!(stdout.contains(name), "{name}: {stdout}");
    }
    let csv = std::fs::read_to_string(d.join("out.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("scene,accel,frame,"));
    assert_eq!(lines.len(), 1 + 3 * 3, "{csv}");
}

#[test]
fn bad_arguments_are_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let cases: [(&[&str], i32, &str); 7] = [
        (&["s.toml", "--size", "16"], 2, "WxH"),
        (
            &["s.toml", "--size", "16384x16384"],
            2,
            "at most 67108864 pixels",
        ),
        (&["s.toml", "--frames", "3..1"], 2, "A..B"),
        (&["s.toml", "--accel", "clusters:t=0"], 1, "t must be"),
        (&["s.toml", "--accel", "iosp0"], 1, "reorders"),
        (&["s.toml", "--fps", "0"], 1, "--fps"),
        (&["missing.toml"], 1, "missing.toml"),
    ];
    for (args, code, needle) in cases {
        let out = bench(d, args);
        let lines = error_lines(&out);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {lines:?}");
        assert_eq!(lines.len(), 1, "{args:?}: one error line: {lines:?}");
        assert!(lines[0].contains(needle), "{args:?}: {lines:?}");
    }
}
