//! `render --frames A..B --denoiser svgf`: frames filtered in order with their history, the
//! same bytes for any thread count, steadier than the noisy frames, and one error line for
//! every combination a temporal denoiser cannot honour.

use std::path::Path;
use std::process::{Command, Output};

mod common;

use common::one_error_line;

fn render(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A lit floor seen from above, 32 × 24 pixels, nothing moving.
fn still_scene(dir: &Path) {
    let camera = "[[camera]]\nname = \"c\"\nposition = [0.0, 1.5, 1.5]\nlook_at = [0.0, 0.0, 0.0]\nfov = 50.0\nresolution = [32, 24]\n";
    std::fs::write(
        dir.join("s.toml"),
        format!("{camera}{}", common::FLOOR_AND_LAMP),
    )
    .unwrap();
}

fn luminance_frames(dir: &Path, pattern: &str, n: u32) -> Vec<Vec<f32>> {
    (0..n)
        .map(|f| {
            let img = rt_film::read_rgb(&dir.join(pattern.replace("{f}", &f.to_string()))).unwrap();
            img.pixels()
                .iter()
                .map(|c| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z)
                .collect()
        })
        .collect()
}

/// Mean absolute luminance change between consecutive frames.
fn temporal_change(frames: &[Vec<f32>]) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for pair in frames.windows(2) {
        for (a, b) in pair[0].iter().zip(&pair[1]) {
            sum += (a - b).abs() as f64;
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn svgf_sequences_are_deterministic_and_steadier_than_their_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    still_scene(d);
    let base = ["s.toml", "--frames", "0..8", "--spp", "1", "-q"];
    let svgf = |threads: &str, out: &str| {
        let mut a = base.to_vec();
        a.extend_from_slice(&["--denoiser", "svgf", "--threads", threads, "-o", out]);
        ok(&render(d, &a));
    };
    svgf("1", "a_{frame}.exr");
    svgf("2", "b_{frame}.exr");
    for f in 0..8 {
        assert_eq!(
            std::fs::read(d.join(format!("a_{f}.exr"))).unwrap(),
            std::fs::read(d.join(format!("b_{f}.exr"))).unwrap(),
            "frame {f} differs between 1 and 2 threads"
        );
    }
    let mut noisy = base.to_vec();
    noisy.extend_from_slice(&["-o", "n_{frame}.exr"]);
    ok(&render(d, &noisy));
    let filtered = temporal_change(&luminance_frames(d, "a_{f}.exr", 8)[4..]);
    let raw = temporal_change(&luminance_frames(d, "n_{f}.exr", 8)[4..]);
    assert!(
        filtered * 5.0 < raw,
        "svgf changes {filtered} per frame, the noisy frames {raw}"
    );
    // A per-frame denoiser runs on every frame alone.
    let mut atrous = base.to_vec();
    atrous.extend_from_slice(&["--denoiser", "atrous:demodulate=off", "-o", "t_{frame}.exr"]);
    ok(&render(d, &atrous));
    assert!(d.join("t_7.exr").exists());
}

#[test]
fn what_a_temporal_denoiser_cannot_honour_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    still_scene(d);
    let run = |extra: &[&str]| {
        let mut a = vec![
            "s.toml",
            "--frames",
            "0..2",
            "--spp",
            "1",
            "-o",
            "f_{frame}.exr",
        ];
        a.extend_from_slice(extra);
        one_error_line(&render(d, &a))
    };
    assert!(run(&["--denoiser", "svgf:alpha=3"]).contains("svgf: alpha: must be in (0, 1], got 3"));
    assert!(run(&["--denoiser", "svgf:sigma-q=1"]).contains("unknown option `sigma-q`"));
    assert!(
        run(&["--denoiser", "svgf", "--aov", "albedo"]).contains("writes the denoised image only")
    );
    assert!(run(&["--denoiser", "svgf", "--error", "0.01"])
        .contains("--error and --time-limit do not apply"));
    assert!(run(&["--denoiser", "svgf", "--shutter", "0.5"]).contains("motion blur"));
    let e = run(&["--denoiser", "svgf", "--integrator", "ao"]);
    assert!(e.contains("lighting split") && e.contains("s.toml"), "{e}");
}
