//! Checkpoints: a render stopped by SIGINT or SIGTERM writes its image so far and a checkpoint
//! and fails with one line; one killed by SIGKILL keeps its last checkpoint; `render --resume`
//! finishes either to the very bytes of a render never stopped, and traces only the samples
//! the checkpoint does not hold (a resume that rendered everything again would give the same
//! bytes too: a checkpoint whose sums were zeroed shows which samples the resumed process
//! traced).

mod common;
use common::{one_error_line, render, FLOOR_AND_LAMP};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Enough samples that the render is still running when the signal arrives.
const SPP: &str = "6000";

fn scene(dir: &Path) {
    let text = format!(
        "{FLOOR_AND_LAMP}\n[[camera]]\nname = \"cam\"\nposition = [0, 1, 3]\nlook_at = [0, 0.5, 0]\nresolution = [16, 12]\n"
    );
    std::fs::write(dir.join("s.toml"), text).unwrap();
}

fn start(dir: &Path, out: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .args(["s.toml", "--spp", SPP, "-q", "-o", out])
        .args(["--checkpoint", "ck.rpart", "--checkpoint-every", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until the render has written a checkpoint.
fn wait_for_checkpoint(dir: &Path) {
    let t = Instant::now();
    while !dir.join("ck.rpart").exists() {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "no checkpoint after a minute"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(100));
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

fn resume_and_compare(dir: &Path, out: &str) {
    let r = render(dir, &["--resume", "ck.rpart", "--threads", "1"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(
        std::fs::read(dir.join(out)).unwrap() == std::fs::read(dir.join("whole.exr")).unwrap(),
        "the resumed render differs from the uninterrupted one"
    );
    assert!(
        !dir.join("ck.rpart").exists(),
        "a finished render removes its checkpoint"
    );
}

#[test]
fn interrupted_and_killed_renders_resume_to_the_same_bytes() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let whole = render(dir, &["s.toml", "--spp", SPP, "-q", "-o", "whole.exr"]);
    assert!(whole.status.success());

    for sig in ["-INT", "-TERM"] {
        let child = start(dir, "int.exr");
        wait_for_checkpoint(dir);
        signal(&child, sig);
        let out = child.wait_with_output().unwrap();
        let line = one_error_line(&out);
        let name = if sig == "-INT" { "SIGINT" } else { "SIGTERM" };
        assert!(
            line.contains(&format!("interrupted by {name} after ")),
            "{line}"
        );
        assert!(
            line.contains(&format!(" of {SPP} samples per pixel: wrote int.exr")),
            "{line}"
        );
        assert!(
            line.contains("render --resume ck.rpart continues"),
            "{line}"
        );
        // The image so far was written (a readable EXR).
        assert!(rt_film::read_exr(&dir.join("int.exr")).is_ok());
        resume_and_compare(dir, "int.exr");
        std::fs::remove_file(dir.join("int.exr")).unwrap();
    }

    // A second signal ends the process at once (status 130), in the middle of writing the
    // image and the checkpoint at the latest: both signals are sent microseconds apart, while
    // those writes take milliseconds. What is on disk is still whole.
    let child = start(dir, "twice.exr");
    wait_for_checkpoint(dir);
    let pid = child.id();
    let both = Command::new("sh")
        .args(["-c", &format!("kill -INT {pid}; kill -TERM {pid}")])
        .status()
        .unwrap();
    assert!(both.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "a second signal ends the render at once: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Whether the image was written depends on where the second signal fell; if it was, it
    // is whole. The checkpoint is there in any case (written before the signals, replaced
    // atomically) and whole.
    if dir.join("twice.exr").exists() {
        assert!(rt_film::read_exr(&dir.join("twice.exr")).is_ok());
    }
    let ck = rt_parts::Part::read(&dir.join("ck.rpart")).expect("a whole checkpoint");
    assert!(ck.header.samples[1] > 0, "an empty checkpoint");
    resume_and_compare(dir, "twice.exr");

    // SIGKILL: no image, but the last checkpoint is whole (written atomically).
    let mut child = start(dir, "killed.exr");
    wait_for_checkpoint(dir);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!dir.join("killed.exr").exists());
    resume_and_compare(dir, "killed.exr");
}

/// Mean of the R, G and B channels of an EXR.
fn exr_mean(path: &Path) -> f64 {
    let img = rt_film::read_exr(path).unwrap();
    let rgb: Vec<f64> = ["R", "G", "B"]
        .iter()
        .flat_map(|c| img.channel(c).unwrap().iter().map(|&v| f64::from(v)))
        .collect();
    rgb.iter().sum::<f64>() / rgb.len() as f64
}

/// The resumed process traces the samples after the checkpoint's range and only those: with
/// the checkpoint's colour sums set to zero (its counts kept), the resumed image is the
/// uninterrupted one times the share of samples after the checkpoint, `1 − k / spp`, within
/// the noise of a 16 × 12 image at 6000 samples per pixel (the bound is 2 %). Rendering
/// everything again instead gives the factor 1, and a resume that also skipped the remaining
/// samples gives 0.
#[test]
fn a_resumed_render_traces_only_the_samples_after_the_checkpoint() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let whole = render(dir, &["s.toml", "--spp", SPP, "-q", "-o", "whole.exr"]);
    assert!(whole.status.success());
    let spp: u32 = SPP.parse().unwrap();
    let path = dir.join("ck.rpart");
    // Interrupted once the checkpoint (rewritten every pass) holds a tenth of the samples: a
    // resume that traced everything again would then be 10 % off, five times the bound.
    let child = start(dir, "int.exr");
    let t = Instant::now();
    while rt_parts::Part::read(&path).map_or(true, |p| p.header.samples[1] < spp / 10) {
        assert!(t.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(20));
    }
    signal(&child, "-INT");
    child.wait_with_output().unwrap();
    let mut ck = rt_parts::Part::read(&path).unwrap();
    let range = ck.header.sample_range();
    assert!(
        range.start == 0 && range.end >= spp / 10 && range.end < spp,
        "checkpoint of samples {range:?}"
    );
    // Layout (rt_film::raw): flags byte, discarded count (u64), a u32 count per pixel, then
    // the colour sums (three i128 per pixel).
    assert_eq!(
        ck.sums[0], 0,
        "no light-path splats in a path-traced checkpoint"
    );
    let area = (ck.header.width * ck.header.height) as usize;
    let sums = 1 + 8 + 4 * area;
    ck.sums[sums..sums + 48 * area].fill(0);
    ck.write(&path).unwrap();
    let r = render(dir, &["--resume", "ck.rpart"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let ratio = exr_mean(&dir.join("int.exr")) / exr_mean(&dir.join("whole.exr"));
    let expected = 1.0 - f64::from(range.end) / f64::from(spp);
    assert!(
        (ratio - expected).abs() < 0.02,
        "resumed / uninterrupted = {ratio:.4}, but the samples after the checkpoint's \
         {range:?} are {expected:.4} of {spp}"
    );
}

#[test]
fn resuming_refuses_a_changed_scene_and_checkpoints_refuse_what_they_cannot_keep() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let child = start(dir, "int.exr");
    wait_for_checkpoint(dir);
    signal(&child, "-INT");
    child.wait_with_output().unwrap();
    let text = std::fs::read_to_string(dir.join("s.toml")).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        text.replace("0.7, 0.7, 0.7", "0.6, 0.7, 0.7"),
    )
    .unwrap();
    let e = one_error_line(&render(dir, &["--resume", "ck.rpart"]));
    assert!(
        e.contains("--resume: this render does not belong with ck.rpart: its scene content"),
        "{e}"
    );
    let e = one_error_line(&render(dir, &["--resume", "s.toml"]));
    assert!(e.contains("s.toml: not a part file"), "{e}");
    for (extra, want) in [
        (
            &["--error", "0.01"][..],
            "cannot checkpoint an adaptive render",
        ),
        (&["--gree"][..], "cannot checkpoint GREE"),
        (&["-o", "p.rpart"][..], "cannot checkpoint a part"),
    ] {
        let mut a = vec!["s.toml", "--spp", "4", "--checkpoint", "c.rpart"];
        a.extend(extra);
        let e = one_error_line(&render(dir, &a));
        assert!(e.contains(want), "{extra:?}: {e}");
    }
}
