//! End-to-end tests of `render compare --frames`: numbered sequences written with the
//! renderer's own EXR writer, per-frame and temporal metrics against hand-computed values (text
//! and JSON), the lag after `--event`, and one clean error line for each kind of bad input.

use rt_core::Rgb;
use std::path::PathBuf;
use std::process::Output;

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }

    /// Writes a constant grey linear EXR (grey luminance equals the value).
    fn grey(&self, name: &str, size: usize, value: f32) {
        let image = rt_core::RgbImage::from_fn(size, size, |_, _| Rgb::splat(value));
        rt_film::write_rgb(&self.path(name), &image, &Default::default()).unwrap();
    }

    fn compare(&self, args: &[&str]) -> Output {
        std::process::Command::new(env!("CARGO_BIN_EXE_render"))
            .current_dir(self.0.path())
            .args([&["compare"], args].concat())
            .output()
            .unwrap()
    }

    /// Runs `render compare ARGS`, expects success and returns stdout.
    fn ok(&self, args: &[&str]) -> String {
        let out = self.compare(args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    }

    /// Runs `render compare ARGS` and expects exit code 1, one error line containing each of
    /// `needles`, and nothing on stdout.
    fn fails(&self, args: &[&str], needles: &[&str]) {
        let out = self.compare(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "stderr: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.lines().count(), 1, "expected one error line: {err}");
        assert!(err.starts_with("error: "), "{err}");
        for n in needles {
            assert!(err.contains(n), "error should mention {n:?}: {err}");
        }
        assert!(out.stdout.is_empty());
    }
}

/// The value of `key` in a text output's `name value` line.
fn line_value(text: &str, key: &str) -> String {
    text.lines()
        .find_map(|l| l.strip_prefix(&format!("{key} ")))
        .unwrap_or_else(|| panic!("no {key} in {text}"))
        .to_string()
}

fn value(text: &str, key: &str) -> f64 {
    line_value(text, key).parse().unwrap()
}

/// `name value` pairs of the line `frame F ...`.
fn frame_line(text: &str, frame: u32) -> Vec<(String, f64)> {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix(&format!("frame {frame} ")))
        .unwrap_or_else(|| panic!("no frame {frame} in {text}"));
    let words: Vec<&str> = line.split(' ').collect();
    words
        .chunks(2)
        .map(|kv| (kv[0].to_string(), kv[1].parse().unwrap()))
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

/// A alternates between grey 0.25 and 0.5 over frames 3..7; B is grey 0.375 throughout.
fn alternating(d: &Dir) {
    for f in 3..7 {
        d.grey(
            &format!("a_{f}.exr"),
            4,
            if f % 2 == 0 { 0.25 } else { 0.5 },
        );
        d.grey(&format!("b_{f:04}.exr"), 4, 0.375);
    }
}

#[test]
fn an_alternating_sequence_gives_the_hand_computed_metrics() {
    let d = Dir::new();
    alternating(&d);
    let text = d.ok(&["a_{frame}.exr", "b_{frame:04}.exr", "--frames", "3..7"]);
    // Each frame is 0.125 from the reference: MSE 0.015625, relMSE 0.015625 / (0.140625 + 0.01).
    let rel = 0.015625 / (0.140625 + 0.01);
    let first = frame_line(&text, 3);
    let keys: Vec<&str> = first.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, ["mse", "relmse", "rmse", "psnr", "ssim"]);
    assert_eq!(first[0].1, 0.015625);
    assert!(close(first[1].1, rel), "{text}");
    for f in 4..7 {
        let row = frame_line(&text, f);
        let keys: Vec<&str> = row.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys[5..],
            ["temporal_error_a", "temporal_error_b", "temporal_relmse"]
        );
        // Luminance changes by 0.25 at every step in A and not at all in B; the difference
        // 0.25 against a reference difference of 0 gives 0.0625 / 0.01 in every channel.
        assert!(close(row[5].1, 0.25), "{text}");
        assert_eq!(row[6].1, 0.0);
        assert!(close(row[7].1, 6.25), "{text}");
    }
    assert!(text.lines().all(|l| !l.starts_with("frame 7")));
    assert!(close(value(&text, "temporal_error_a"), 0.25), "{text}");
    assert_eq!(value(&text, "temporal_error_b"), 0.0);
    assert!(close(value(&text, "temporal_relmse"), 6.25), "{text}");
    assert_eq!(value(&text, "mean_mse"), 0.015625);
    assert!(close(value(&text, "mean_relmse"), rel));
    assert_eq!(value(&text, "relmse_epsilon"), 0.01);
    assert!(!text.contains("lag"), "{text}");
    // Epsilon is relMSE's and the temporal relMSE's: 0.0625 / 0.0625 = 1.
    let text = d.ok(&[
        "a_{frame}.exr",
        "b_{frame:04}.exr",
        "--frames",
        "3..7",
        "--epsilon",
        "0.0625",
    ]);
    assert!(close(value(&text, "temporal_relmse"), 1.0), "{text}");
    // A reference without a placeholder serves every frame: the same numbers.
    let fixed = d.ok(&["a_{frame}.exr", "b_0003.exr", "--frames", "3..7"]);
    assert_eq!(
        fixed,
        d.ok(&["a_{frame}.exr", "b_{frame:04}.exr", "--frames", "3..7"])
    );
}

#[test]
fn json_has_frames_with_null_steps_first() {
    let d = Dir::new();
    alternating(&d);
    let text = d.ok(&[
        "a_{frame}.exr",
        "b_{frame:04}.exr",
        "--frames",
        "3..6",
        "--json",
    ]);
    assert_eq!(text.lines().count(), 1);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[0]["frame"].as_u64(), Some(3));
    assert!(frames[0]["temporal_error_a"].is_null());
    assert!(frames[0]["temporal_relmse"].is_null());
    assert!(close(frames[2]["temporal_error_a"].as_f64().unwrap(), 0.25));
    assert_eq!(frames[1]["mse"].as_f64(), Some(0.015625));
    assert!(close(v["temporal_relmse"].as_f64().unwrap(), 6.25));
    assert!(close(v["temporal_error_a"].as_f64().unwrap(), 0.25));
    assert_eq!(v["temporal_error_b"].as_f64(), Some(0.0));
    assert_eq!(v["mean_mse"].as_f64(), Some(0.015625));
    assert!(v["lag"].is_null());
    assert_eq!(v["relmse_epsilon"].as_f64(), Some(0.01));
}

/// B is grey 1 over frames 0..20; A is 1.1 before frame 10 and `1.1 + 0.8 · 0.5^k` at frame
/// 10 + k. Per-frame relMSE is `d² / 1.01` with `d` = A − 1, so the steady state is
/// `0.01 / 1.01` and the error is within 2× of it when `d² ≤ 0.02`, `d ≤ 0.1414`:
/// d = 0.9, 0.5, 0.3, 0.2, 0.15, 0.125 for k = 0..5, so the lag is 5.
fn light_toggle(d: &Dir) {
    for f in 0..20u32 {
        let a = if f < 10 {
            1.1
        } else {
            1.1 + 0.8 * 0.5f32.powi(f as i32 - 10)
        };
        d.grey(&format!("a_{f:02}.exr"), 3, a);
        d.grey(&format!("b_{f:02}.exr"), 3, 1.0);
    }
}

#[test]
fn lag_after_an_event() {
    let d = Dir::new();
    light_toggle(&d);
    let args = ["a_{frame:02}.exr", "b_{frame:02}.exr", "--event", "10"];
    let text = d.ok(&[&args[..], &["--frames", "0..20"]].concat());
    assert_eq!(line_value(&text, "lag"), "5", "{text}");
    assert_eq!(value(&text, "lag_event"), 10.0);
    let d1 = f64::from(1.1f32) - 1.0;
    let steady = d1 * d1 / 1.01;
    assert!(close(value(&text, "lag_steady_state"), steady), "{text}");
    assert!(close(value(&text, "lag_threshold"), 2.0 * steady), "{text}");
    assert_eq!(value(&text, "lag_window"), 10.0);
    assert_eq!(value(&text, "lag_factor"), 2.0);
    // A looser factor: d² ≤ 0.1, d ≤ 0.316 at k = 2 (d = 0.3).
    let text = d.ok(&[&args[..], &["--frames", "0..20", "--lag-factor", "10"]].concat());
    assert_eq!(line_value(&text, "lag"), "2", "{text}");
    // The sequence ends before the error recovers.
    let text = d.ok(&[&args[..], &["--frames", "0..14"]].concat());
    assert_eq!(line_value(&text, "lag"), "none", "{text}");
    let json = d.ok(&[&args[..], &["--frames", "0..14", "--json"]].concat());
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(v["lag"]["frames"].is_null(), "{json}");
    assert_eq!(v["lag"]["event"].as_u64(), Some(10));
    let json = d.ok(&[&args[..], &["--frames", "0..20", "--json"]].concat());
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["lag"]["frames"].as_u64(), Some(5), "{json}");
    // A shorter window after a later start.
    let text = d.ok(&[&args[..], &["--frames", "5..20", "--lag-window", "5"]].concat());
    assert_eq!(line_value(&text, "lag"), "5", "{text}");
    d.fails(
        &[&args[..], &["--frames", "5..20"]].concat(),
        &["--event 10", "--lag-window 10", "--frames 5..20 has 5"],
    );
    d.fails(
        &[&args[..], &["--frames", "0..10"]].concat(),
        &["--event 10 is not one of --frames 0..10"],
    );
}

#[test]
fn error_images_are_written_per_frame() {
    let d = Dir::new();
    alternating(&d);
    d.ok(&[
        "a_{frame}.exr",
        "b_{frame:04}.exr",
        "--frames",
        "3..5",
        "--error-image",
        "err_{frame}.png",
    ]);
    assert!(d.path("err_3.png").exists() && d.path("err_4.png").exists());
    assert!(!d.path("err_5.png").exists());
    d.fails(
        &[
            "a_{frame}.exr",
            "b_{frame:04}.exr",
            "--frames",
            "3..5",
            "--error-image",
            "err.png",
        ],
        &["err.png", "must name the frame"],
    );
}

#[test]
fn bad_sequences_are_one_error_line_naming_the_file() {
    let d = Dir::new();
    alternating(&d);
    let pats = ["a_{frame}.exr", "b_{frame:04}.exr"];
    // A missing frame.
    d.fails(
        &[&pats[..], &["--frames", "3..8"]].concat(),
        &["a_7.exr", "No such file"],
    );
    std::fs::remove_file(d.path("b_0005.exr")).unwrap();
    d.fails(
        &[&pats[..], &["--frames", "3..7"]].concat(),
        &["b_0005.exr", "No such file"],
    );
    // A frame whose size differs from its reference, then from the frame before it.
    d.grey("b_0005.exr", 3, 0.375);
    d.fails(
        &[&pats[..], &["--frames", "3..7"]].concat(),
        &["a_5.exr is 4x4 but b_0005.exr is 3x3"],
    );
    d.grey("a_5.exr", 3, 0.5);
    d.fails(
        &[&pats[..], &["--frames", "3..7"]].concat(),
        &["a_5.exr is 3x3 but a_4.exr is 4x4"],
    );
    // Arguments that cannot give a result.
    d.fails(
        &["a_3.exr", "b_{frame:04}.exr", "--frames", "3..7"],
        &["a_3.exr", "names the frame"],
    );
    d.fails(
        &[&pats[..], &["--frames", "3..4"]].concat(),
        &["--frames 3..4", "at least two"],
    );
    // A pattern without --frames says what is missing; plain images are unchanged.
    d.fails(&pats, &["a_{frame}.exr", "--frames"]);
    let plain = d.ok(&["a_3.exr", "b_0003.exr"]);
    assert!(plain.starts_with("mse 0.015625\n"), "{plain}");
    // --event without --frames and a zero window are usage errors.
    assert_eq!(
        d.compare(&["a_3.exr", "b_0003.exr", "--event", "2"])
            .status
            .code(),
        Some(2)
    );
    let zero = [
        &pats[..],
        &["--frames", "3..7", "--event", "5", "--lag-window", "0"],
    ]
    .concat();
    assert_eq!(d.compare(&zero).status.code(), Some(2));
    // Lag settings without --event would be ignored, so they are refused.
    let no_event = [&pats[..], &["--frames", "3..7", "--lag-factor", "3"]].concat();
    assert_eq!(d.compare(&no_event).status.code(), Some(2));
}
