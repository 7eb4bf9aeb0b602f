//! `render --frames A..B` and `--frame F`: numbered outputs, one frame alone equals the same
//! frame of a sequence byte for byte (for any thread count), moving geometry moves the image,
//! frames get their own noise, and bad frame arguments are one error line.

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

/// The R, G and B channels of the EXR at `path`.
fn pixels(path: &Path) -> Vec<Vec<f32>> {
    let img = rt_film::read_exr(path).unwrap();
    ["R", "G", "B"]
        .map(|c| img.channel(c).unwrap().to_vec())
        .to_vec()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn frames_render_to_numbered_files_and_one_frame_alone_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let common = ["--spp", "4", "--fps", "1", "-q"];
    let mut args = vec!["s.toml", "--frames", "0..3", "-o", "f_{frame:03}.exr"];
    args.extend_from_slice(&common);
    ok(&render(d, &[&args[..], &["--threads", "2"]].concat()));
    let frames: Vec<Vec<u8>> = (0..3)
        .map(|f| std::fs::read(d.join(format!("f_{f:03}.exr"))).unwrap())
        .collect();
    // Frame 1 alone, on another thread count, gives the same bytes.
    let mut one = vec!["s.toml", "--frame", "1", "-o", "one.exr", "--threads", "1"];
    one.extend_from_slice(&common);
    ok(&render(d, &one));
    assert_eq!(std::fs::read(d.join("one.exr")).unwrap(), frames[1]);
    // The box moves, and the noise is new every frame.
    assert_ne!(frames[0], frames[1]);
    assert_ne!(frames[1], frames[2]);
    // Without motion, consecutive frames still differ: their noise is their own.
    let still = SCENE.split("[[animation]]").next().unwrap();
    std::fs::write(d.join("still.toml"), still).unwrap();
    let mut args = vec!["still.toml", "--frames", "0..2", "-o", "s_{frame}.exr"];
    args.extend_from_slice(&common);
    ok(&render(d, &args));
    assert_ne!(
        std::fs::read(d.join("s_0.exr")).unwrap(),
        std::fs::read(d.join("s_1.exr")).unwrap(),
        "frames of a still scene share their noise"
    );
    // Frame 0 is the scene at time 0 with the plain render's streams.
    let mut plain = vec!["s.toml", "-o", "plain.exr"];
    plain.extend_from_slice(&common);
    ok(&render(d, &plain));
    assert_eq!(std::fs::read(d.join("plain.exr")).unwrap(), frames[0]);
}

#[test]
fn bad_frame_arguments_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    for (args, want) in [
        (vec!["--frames", "3..3", "-o", "f_{frame}.exr"], "A < B"),
        (vec!["--frames", "x..2", "-o", "f_{frame}.exr"], "A..B"),
        (vec!["--frames", "0..2", "-o", "f.exr"], "names the frame"),
        (
            vec!["--frame", "1", "--fps", "0", "-o", "f.exr"],
            "--fps must be a positive",
        ),
        (
            vec!["--frame", "1", "--frames", "0..2", "-o", "f_{frame}.exr"],
            "cannot be used with",
        ),
    ] {
        let out = render(d, &[&["s.toml", "--spp", "1"][..], &args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        assert_ne!(out.status.code(), Some(101), "panic: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
}

#[test]
fn shutter_blurs_what_moves_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let common = ["--spp", "8", "--fps", "1", "-q", "--frame", "1"];
    let run = |extra: &[&str], out: &str| {
        ok(&render(
            d,
            &[&["s.toml", "-o", out][..], &common, extra].concat(),
        ));
        std::fs::read(d.join(out)).unwrap()
    };
    // Clusters are chosen for the moving box; the image is the same on any thread count.
    let blurred = run(&["--shutter", "0.5", "--threads", "2"], "b2.exr");
    assert_eq!(
        run(&["--shutter", "0.5", "--threads", "1"], "b1.exr"),
        blurred
    );
    assert_ne!(
        run(&[], "sharp.exr"),
        blurred,
        "the shutter changed nothing"
    );
    // The cluster structure built for the shutter finds the same hits: the same image.
    run(&["--shutter", "0.5", "--accel", "clusters"], "c.exr");
    assert_eq!(
        pixels(&d.join("c.exr")),
        pixels(&d.join("b2.exr")),
        "--accel clusters renders another image"
    );
    // Nothing moves in a still scene: the same bytes as without a shutter, with any structure.
    let still = SCENE.split("[[animation]]").next().unwrap();
    std::fs::write(d.join("still.toml"), still).unwrap();
    let still_run = |extra: &[&str], out: &str| {
        ok(&render(
            d,
            &[&["still.toml", "-o", out][..], &common, extra].concat(),
        ));
        std::fs::read(d.join(out)).unwrap()
    };
    assert_eq!(
        still_run(&["--shutter", "0.5", "--accel", "bvh8"], "s1.exr"),
        still_run(&[], "s0.exr")
    );
}

#[test]
fn shutter_refusals_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let lamp_moves = format!(
        "{SCENE}\n[[animation]]\ntarget = \"light\"\nkeys = [ {{ time = 0.0, translate = [0, 0, 0] }}, {{ time = 2.0, translate = [0, 0.2, 0] }} ]\n"
    );
    std::fs::write(d.join("lamp.toml"), lamp_moves).unwrap();
    for (scene, args, want) in [
        ("s.toml", vec!["--shutter=-0.5"], "--shutter must be"),
        ("s.toml", vec!["--shutter", "NaN"], "--shutter must be"),
        (
            "s.toml",
            vec!["--shutter", "0.5", "--accel", "bvh8"],
            "motion blur needs two-level or clusters",
        ),
        (
            "s.toml",
            vec!["--shutter", "0.5", "--integrator", "bdpt"],
            "cannot motion blur",
        ),
        (
            "lamp.toml",
            vec!["--shutter", "0.5"],
            "`light` emits light and moves",
        ),
    ] {
        let out = render(
            d,
            &[
                &[scene, "--spp", "1", "--frame", "1", "-o", "x.exr"][..],
                &args,
            ]
            .concat(),
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        assert_ne!(out.status.code(), Some(101), "panic: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(scene) || want.starts_with("--"), "{err}");
    }
}

#[test]
fn moving_instances_choose_clusters_unless_told_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    std::fs::write(
        d.join("still.toml"),
        SCENE.split("[[animation]]").next().unwrap(),
    )
    .unwrap();
    let summary = |scene: &str, extra: &[&str]| {
        let out = render(
            d,
            &[&[scene, "--spp", "1", "-o", "x.exr"][..], extra].concat(),
        );
        ok(&out);
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    };
    assert!(summary("s.toml", &[]).contains(" clusters "));
    assert!(summary("still.toml", &[]).contains(" bvh8 "));
    assert!(summary("s.toml", &["--accel", "bvh"]).contains(" bvh "));
}
