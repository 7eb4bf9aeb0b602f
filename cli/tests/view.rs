//! `render view --headless`: frames written, the summary line printed, the same bits on any
//! thread count without a budget, the budget's spp reported; bad budgets, and a window
//! without a display, are one error line.

use std::path::Path;
use std::process::{Command, Output};

mod common;

use common::MOVING_BOX as SCENE;

fn render(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    stdout(o)
}

/// The number after `before` in `text` (up to the next space or `;`).
fn number_after(text: &str, before: &str) -> f64 {
    let at = text
        .find(before)
        .unwrap_or_else(|| panic!("no `{before}` in {text}"))
        + before.len();
    let s: String = text[at..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    s.parse()
        .unwrap_or_else(|_| panic!("no number after `{before}` in {text}"))
}

#[test]
fn headless_writes_frames_and_reports_frames_per_second() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let base = [
        "view",
        "s.toml",
        "--headless",
        "--frames",
        "0..3",
        "--size",
        "16x12",
        "--spp",
        "2",
    ];
    let run = |extra: &[&str]| ok(&render(d, &[&base[..], extra].concat()));
    let out = run(&["-o", "a/f_{frame:02}.exr", "--threads", "2"]);
    let summary = out.lines().last().unwrap();
    assert!(summary.contains("3 frames 16x12, svgf"), "{summary}");
    assert!(summary.contains("frames per second"), "{summary}");
    assert!(number_after(summary, "svgf:") > 0.0, "{summary}");
    let (mean, worst) = (
        number_after(summary, "frame time mean"),
        number_after(summary, "worst"),
    );
    assert!(mean > 0.0 && worst >= mean, "{summary}");
    assert!(summary.contains("mean 2.00 spp per frame"), "{summary}");
    assert_eq!(
        out.lines().filter(|l| l.contains(": frame ")).count(),
        3,
        "{out}"
    );
    let frames: Vec<Vec<u8>> = (0..3)
        .map(|f| std::fs::read(d.join(format!("a/f_{f:02}.exr"))).unwrap())
        .collect();
    assert_ne!(frames[0], frames[1]);
    // Without a budget the frames are deterministic: the same bits on one thread.
    run(&["-o", "b/f_{frame:02}.exr", "--threads", "1", "-q"]);
    for (f, bytes) in frames.iter().enumerate() {
        assert_eq!(
            &std::fs::read(d.join(format!("b/f_{f:02}.exr"))).unwrap(),
            bytes
        );
    }
    // A generous budget takes every pass --spp allows and overruns nothing.
    let out = run(&["--frame-budget", "60000", "-q"]);
    assert_eq!(out.lines().count(), 1, "{out}");
    assert!(out.contains("mean 2.00 spp per frame"), "{out}");
    assert!(
        out.contains("0 of 3 frames over the 60000.0 ms budget"),
        "{out}"
    );
    // A budget no frame can meet still renders one pass per frame, and every frame overruns.
    let out = run(&["--frame-budget", "0.000001", "-q", "--denoiser", "none"]);
    assert!(out.contains("mean 1.00 spp per frame"), "{out}");
    assert!(out.contains("3 of 3 frames over"), "{out}");
}

#[test]
fn bad_view_arguments_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let headless = ["view", "s.toml", "--headless", "--frames", "0..2"];
    for (extra, want) in [
        (
            &["--frame-budget", "0"][..],
            "--frame-budget must be a positive number",
        ),
        (
            &["--frame-budget", "-3"],
            "--frame-budget must be a positive number",
        ),
        (
            &["--frame-budget", "abc"],
            "--frame-budget must be a positive number",
        ),
        (&["--size", "0x4"], "--size"),
        (&["--size", "big"], "--size must be WIDTHxHEIGHT"),
        (&["-o", "f.png"], "must name the frame"),
        (&["--denoiser", "svgf:alpha=7"], "--denoiser svgf:alpha=7"),
        (&["--denoiser", "atrous"], "temporal denoiser"),
        (&["--fps-cap", "0"], "--fps-cap"),
    ] {
        let out = render(d, &[&headless[..], extra].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert!(err.contains(want), "{extra:?}: {err}");
    }
    // A window without a display: one line that points to --headless.
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(d)
        .args(["view", "s.toml"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("DISPLAY") && err.contains("--headless"),
        "{err}"
    );
}
