//! Bad parameters of the techniques and the stopping criterion give one clear error line (issue
//! 11): a negative or zero `--error` (and `--time-limit`) given as a separate argument, as a
//! user types it; zero caustic photons and an unknown option of the partitioned renderer, on
//! the command line and in a scene's `[render]` table. `cli.rs` has the `--error=V` spelling
//! and the exit code of the `--integrator` cases; this file checks the line count and the
//! wording.

use std::process::{Command, Output};

mod common;

/// The floor under a lamp, seen by an 8×6 camera.
fn scene() -> String {
    format!(
        "[[camera]]\nname = \"main\"\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 1.0, 0.0]\n\
         fov = 40.0\nresolution = [8, 6]\n{}",
        common::FLOOR_AND_LAMP
    )
}

/// Renders `scene` (written to `scene.toml` in a fresh directory) with `args`.
fn render(scene: &str, args: &[&str]) -> (Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir.path())
        .arg("scene.toml")
        .args(["-o", "out.exr", "-q"])
        .args(args)
        .output()
        .unwrap();
    (out, dir)
}

/// The error lines of `out` (clap's closing "For more information" hint is not one).
fn error_lines(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("For more information"))
        .map(str::to_owned)
        .collect()
}

/// Expects exit code `code`, one error line containing every needle, and no image.
fn expect_one_line(scene: &str, args: &[&str], code: i32, needles: &[&str]) {
    let (out, dir) = render(scene, args);
    let lines = error_lines(&out);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {lines:?}");
    assert_eq!(
        lines.len(),
        1,
        "{args:?}: expected one error line: {lines:?}"
    );
    for n in needles {
        assert!(
            lines[0].contains(n),
            "{args:?}: should mention {n:?}: {lines:?}"
        );
    }
    assert!(!dir.path().join("out.exr").exists(), "{args:?}: no image");
}

#[test]
fn negative_and_zero_error_thresholds_are_one_line() {
    for bad in ["-1", "0", "-2e-4"] {
        expect_one_line(&scene(), &["--error", bad], 1, &["--error", "positive"]);
        expect_one_line(
            &scene(),
            &["--time-limit", bad],
            1,
            &["--time-limit", "positive"],
        );
    }
}

#[test]
fn bad_partitioned_options_are_one_line() {
    // Zero photons: the option, what it must be.
    let zero = ["photons=0", "1 to"];
    expect_one_line(
        &scene(),
        &["--integrator", "partitioned:photons=0"],
        2,
        &zero,
    );
    // An unknown option: named, with the options there are.
    let unknown = ["gather=2", "does not apply", "photons=N"];
    expect_one_line(
        &scene(),
        &["--integrator", "partitioned:gather=2"],
        2,
        &unknown,
    );
    // The same in the scene's `[render]` table: a scene error, naming the file and the key.
    for (spec, needles) in [
        ("partitioned:photons=0", &zero[..]),
        ("partitioned:gather=2", &unknown[..]),
    ] {
        let scene = format!("{}\n[render]\nintegrator = \"{spec}\"\n", scene());
        let mut with_file = vec!["scene.toml", "integrator"];
        with_file.extend(needles);
        expect_one_line(&scene, &[], 1, &with_file);
    }
}

/// Every integrator renders point, spot and directional lights (a technique that could not
/// would refuse them in one line, `Technique::delta_lights`).
#[test]
fn delta_lights_render_with_every_integrator() {
    let s = format!(
        "{}\n[[light]]\ntype = \"point\"\nposition = [0.0, 1.5, 0.0]\nintensity = [2.0, 2.0, 2.0]\n",
        scene()
    );
    for integrator in [
        "path",
        "wavefront",
        "direct",
        "light",
        "bdpt",
        "partitioned",
    ] {
        let (out, _dir) = render(&s, &["--integrator", integrator, "--spp", "1"]);
        assert!(out.status.success(), "{integrator}: {out:?}");
    }
}
