//! End-to-end tests of the `render` binary: every kind of bad input gives one clear error line
//! naming the file and the problem and exit code 1 (never a panic, which would exit with 101),
//! and a good scene renders to an image.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GOOD: &str = r#"
[[camera]]
name = "main"
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0
resolution = [8, 6]

[[material]]
name = "white"
type = "diffuse"
color = [0.7, 0.7, 0.7]

[[material]]
name = "lamp"
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [5.0, 5.0, 5.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.3, 2, -0.3], [0.3, 2, -0.3], [0.3, 2, 0.3], [-0.3, 2, 0.3]]
material = "lamp"
"#;

struct Run {
    dir: tempfile::TempDir,
}

impl Run {
    fn new() -> Self {
        Self {
            dir: tempfile::tempdir().unwrap(),
        }
    }

    fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn render(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_render"))
            .current_dir(self.dir.path())
            .args(args)
            .output()
            .unwrap()
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
}

/// Runs `render` on `scene_text` and expects exit code 1 and a one-line error containing all of
/// `needles`.
fn expect_error(scene_text: &str, extra: &[&str], needles: &[&str]) {
    let r = Run::new();
    r.write("scene.toml", scene_text);
    let mut args = vec!["scene.toml", "-o", "out.exr", "-q"];
    if !extra.contains(&"--spp") {
        args.extend_from_slice(&["--spp", "1"]);
    }
    args.extend_from_slice(extra);
    let out = r.render(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.starts_with("warning")).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    for n in needles {
        assert!(err.contains(n), "error should mention {n:?}: {err}");
    }
    assert!(!r.path("out.exr").exists(), "no image after an error");
}

fn replace(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "test bug: {from}");
    GOOD.replacen(from, to, 1)
}

#[test]
fn good_scene_renders_exr_and_png_atomically() {
    let r = Run::new();
    r.write("scene.toml", GOOD);
    let out = r.render(&[
        "scene.toml",
        "-o",
        "img.exr",
        "--spp",
        "4",
        "--aov",
        "albedo,normal,depth,position,variance",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        summary.contains("Mrays/s") && summary.contains("Msamples/s"),
        "{summary}"
    );
    let img = rt_film::read_exr(&r.path("img.exr")).unwrap();
    assert_eq!((img.width, img.height), (8, 6));
    for c in [
        "R",
        "albedo.R",
        "normal.X",
        "depth.Z",
        "position.Y",
        "variance.G",
    ] {
        assert!(img.channel(c).is_some(), "missing channel {c}");
    }
    let out = r.render(&[
        "scene.toml",
        "-o",
        "img.png",
        "--spp",
        "2",
        "-q",
        "--integrator",
        "ao",
    ]);
    assert!(out.status.success());
    assert!(r.path("img.png").exists());
    // Only the scene and the two images: no temporary files left behind.
    assert_eq!(std::fs::read_dir(r.dir.path()).unwrap().count(), 3);
}

#[test]
fn help_explains_every_flag() {
    let out = Run::new().render(&["--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for flag in [
        "--output",
        "--spp",
        "--integrator",
        "--accel",
        "--max-depth",
        "--threads",
        "--seed",
        "--camera",
        "--aov",
        "--exposure",
    ] {
        assert!(help.contains(flag), "--help lacks {flag}");
    }
}

#[test]
fn missing_scene_file() {
    let r = Run::new();
    let out = r.render(&["nope.toml", "-q"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("nope.toml"), "{err}");
}

#[test]
fn malformed_toml() {
    expect_error("[[camera]\nname = ", &[], &["scene.toml"]);
}

#[test]
fn unknown_key() {
    expect_error(
        &replace("fov = 40.0", "fov = 40.0\nzoom = 2.0"),
        &[],
        &["scene.toml", "zoom"],
    );
}

#[test]
fn unknown_material_name() {
    expect_error(
        &replace("material = \"white\"", "material = \"chalk\""),
        &[],
        &["scene.toml", "chalk"],
    );
}

#[test]
fn unknown_material_type() {
    expect_error(
        &replace("type = \"diffuse\"", "type = \"velvet\""),
        &[],
        &["scene.toml", "velvet"],
    );
}

#[test]
fn nan_and_negative_numbers() {
    expect_error(
        &replace("fov = 40.0", "fov = nan"),
        &[],
        &["scene.toml", "fov"],
    );
    expect_error(
        &replace("fov = 40.0", "fov = 40.0\naperture = -0.1"),
        &[],
        &["scene.toml", "aperture"],
    );
    expect_error(
        &replace("emission = [5.0, 5.0, 5.0]", "emission = [5.0, -5.0, 5.0]"),
        &[],
        &["scene.toml", "emission"],
    );
}

#[test]
fn zero_and_absurd_resolution() {
    expect_error(
        &replace("resolution = [8, 6]", "resolution = [0, 6]"),
        &[],
        &["scene.toml", "resolution"],
    );
    expect_error(
        &replace("resolution = [8, 6]", "resolution = [1000000, 1000000]"),
        &[],
        &["scene.toml", "resolution"],
    );
}

#[test]
fn empty_and_degenerate_meshes() {
    let empty = format!(
        "{GOOD}\n[[geometry]]\nname = \"e\"\npositions = []\nindices = []\nmaterial = \"white\"\n"
    );
    expect_error(&empty, &[], &["scene.toml", "\"e\""]);
    let flat = format!(
        "{GOOD}\n[[geometry]]\nname = \"d\"\npositions = [[0,0,0],[1,1,1],[2,2,2]]\nindices = [[0,1,2]]\nmaterial = \"white\"\n"
    );
    expect_error(&flat, &[], &["scene.toml", "\"d\"", "degenerate"]);
    let bad_index = format!(
        "{GOOD}\n[[geometry]]\nname = \"i\"\npositions = [[0,0,0],[1,0,0],[0,1,0]]\nindices = [[0,1,3]]\nmaterial = \"white\"\n"
    );
    expect_error(&bad_index, &[], &["scene.toml", "3"]);
}

#[test]
fn missing_mesh_file() {
    let s = format!(
        "{GOOD}\n[[geometry]]\nname = \"m\"\nfile = \"meshes/none.obj\"\nmaterial = \"white\"\n"
    );
    expect_error(&s, &[], &["none.obj"]);
}

#[test]
fn triangle_range_out_of_bounds() {
    let s = format!(
        "{GOOD}\n[[assign]]\ngeometry = \"floor\"\ntriangles = [0, 3]\nmaterial = \"lamp\"\n"
    );
    expect_error(&s, &[], &["scene.toml", "floor"]);
}

#[test]
fn bad_command_line_values() {
    expect_error(GOOD, &["--spp", "0"], &["samples per pixel"]);
    expect_error(GOOD, &["--camera", "side"], &["scene.toml", "side"]);
    expect_error(GOOD, &["--threads", "0"], &["thread"]);
    expect_error(GOOD, &["--aov", "albedo,gloss"], &["gloss"]);
    // A bad default from the scene's [render] table names the file and the key.
    let table = format!("{GOOD}\n[render]\nspp = 0\n");
    let r = Run::new();
    r.write("scene.toml", &table);
    let out = r.render(&["scene.toml", "-q"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("scene.toml") && err.contains("spp"), "{err}");
    expect_error(
        &format!("{GOOD}\n[render]\nintegrator = \"bdpt\"\n"),
        &[],
        &["scene.toml", "bdpt"],
    );
    let r = Run::new();
    r.write("scene.toml", GOOD);
    let out = r.render(&["scene.toml", "-o", "x.jpg"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("x.jpg"));
    // Usage errors (clap) exit with 2.
    assert_eq!(
        r.render(&["scene.toml", "--integrator", "bdpt"])
            .status
            .code(),
        Some(2)
    );
}

#[test]
fn unwritable_output_leaves_nothing() {
    let r = Run::new();
    r.write("scene.toml", GOOD);
    let out = r.render(&[
        "scene.toml",
        "-o",
        "missing-dir/out.exr",
        "--spp",
        "1",
        "-q",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing-dir/out.exr"));
    assert!(!Path::new(&r.path("missing-dir")).exists());
}
