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

/// The outputs exist with their channels and no temporary file is left behind. (Whether a
/// write is atomic, i.e. an interrupted one leaves no half-written image, is not seen from
/// here: it is the temporary-name-and-rename of `rt_film`'s writer and `cli/src/atomic.rs`.)
#[test]
fn good_scene_renders_exr_and_png_and_leaves_no_temporary_files() {
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
        summary.contains("Mrays/s")
            && summary.contains("Msamples/s")
            && summary.contains(", 0 invalid samples discarded"),
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
        "--frames",
        "--frame",
        "--fps",
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
    // Finite but beyond what the film can accumulate: rejected, not rendered to infinities.
    expect_error(
        &replace("emission = [5.0, 5.0, 5.0]", "emission = [1e30, 5.0, 5.0]"),
        &[],
        &["scene.toml", "emission", "1e15"],
    );
}

#[test]
fn sky_environment_renders_and_bad_sky_values_are_one_line_errors() {
    // The shipped sky scene renders (one sample per pixel, a PNG) without invalid samples.
    let r = Run::new();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/sky.toml");
    let out = r.render(&[scene.to_str().unwrap(), "-o", "sky.png", "--spp", "1"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stdout.contains(" 0 invalid samples discarded"), "{stdout}");
    assert!(r.path("sky.png").exists());
    let sky = |keys: &str| format!("{GOOD}\n[environment]\nsky = {{ {keys} }}\n");
    expect_error(
        &sky("sun_direction = [0, 1, 0], turbidity = 20"),
        &[],
        &["scene.toml", "turbidity must be in [1.7, 10]", "20"],
    );
    expect_error(
        &sky("latitude = 47.4, day = 172, solar_time = 23"),
        &[],
        &["scene.toml", "below the horizon"],
    );
    expect_error(
        &sky("latitude = 47.4, day = 172, hour = 12"),
        &[],
        &["scene.toml", "longitude"],
    );
}

#[test]
fn stress_command_reports_one_line_per_case_and_fails_on_bad_arguments() {
    let r = Run::new();
    let out = r.render(&[
        "stress",
        "--only",
        "bad/nan-texels",
        "--spp",
        "2",
        "--threads",
        "2",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = text
        .lines()
        .find(|l| l.starts_with("bad/nan-texels"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains(" pass ") && line.contains("discarded 0") && line.ends_with(" s"),
        "{line}"
    );
    assert!(text.contains("1 passed, 0 failed"), "{text}");
    let out = r.render(&["stress", "--only", "no-such-case"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no stress case"));
    let out = r.render(&["stress", "--spp", "0"]);
    assert_eq!(out.status.code(), Some(1));
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
        &format!("{GOOD}\n[render]\nintegrator = \"vcm\"\n"),
        &[],
        &["scene.toml", "vcm"],
    );
    let r = Run::new();
    r.write("scene.toml", GOOD);
    let out = r.render(&["scene.toml", "-o", "x.jpg"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("x.jpg"));
    // Bad partitioned options (zero photons, an unknown culling, an unknown option) are
    // usage errors naming the option.
    for bad in [
        "partitioned:photons=0",
        "partitioned:cull=sometimes",
        "partitioned:gather=2",
    ] {
        let out = r.render(&["scene.toml", "--integrator", bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        let option = bad.split(':').nth(1).unwrap();
        assert!(err.contains(option), "{bad}: {err}");
    }
    // Usage errors (clap) exit with 2.
    assert_eq!(
        r.render(&["scene.toml", "--integrator", "vcm"])
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

#[test]
fn accel_specs_from_the_command_line_and_the_render_table() {
    let r = Run::new();
    r.write("scene.toml", GOOD);
    for spec in ["qbvh", "qbvh:evh=14:compact", "bvh:leaf=8", "brute-force"] {
        let out = r.render(&["scene.toml", "-o", "q.exr", "--spp", "1", "--accel", spec]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "--accel {spec}: {err}");
        let summary = String::from_utf8_lossy(&out.stdout);
        assert!(summary.contains(spec), "{summary}");
    }
    let table = format!("{GOOD}\n[render]\naccel = \"qbvh:order=distance\"\n");
    r.write("table.toml", &table);
    let out = r.render(&["table.toml", "-o", "t.exr", "--spp", "1"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("qbvh:order=distance"));
    // The command line wins over the table.
    let out = r.render(&["table.toml", "-o", "t.exr", "--spp", "1", "--accel", "bvh"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains(" bvh ("));

    expect_error(
        GOOD,
        &["--accel", "qbvh:bogus"],
        &["--accel", "qbvh:bogus", "bogus"],
    );
    expect_error(GOOD, &["--accel", "kd"], &["--accel", "kd"]);
    expect_error(
        &format!("{GOOD}\n[render]\naccel = \"kd\"\n"),
        &[],
        &["scene.toml", "accel", "\"kd\""],
    );
    expect_error(
        &format!("{GOOD}\n[render]\naccel = \"qbvh:leaf=99\"\n"),
        &[],
        &["scene.toml", "leaf=99"],
    );
}

#[test]
fn procedural_scene_names() {
    let r = Run::new();
    let out = r.render(&["gen:nope", "-o", "x.exr", "-q"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("gen:nope") && err.contains("worst-case"),
        "{err}"
    );
    // gen-scene writes the triangles as OBJ, which bench-accel (and anything else) can read.
    let out = r.render(&["gen-scene", "worst-case", "-o", "wc.obj"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let obj = std::fs::read_to_string(r.path("wc.obj")).unwrap();
    // 4,100 triangles: the size `rt_scene::procedural` documents for gen:worst-case (a
    // specification: benchmark results are reported for that size).
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 4_100);
    assert_eq!(
        obj.lines().filter(|l| l.starts_with("v ")).count(),
        3 * 4_100
    );
}

/// Runs `render bench-accel ARGS -q` and expects exit code 1 and one error line containing all
/// of `needles`.
fn expect_bench_error(r: &Run, args: &[&str], needles: &[&str]) {
    let mut all = vec!["bench-accel", "-q", "--width", "8", "--repeat", "1"];
    all.extend_from_slice(args);
    let out = r.render(&all);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        err.lines().count(),
        1,
        "{args:?}: expected one line, got: {err}"
    );
    assert!(out.stdout.is_empty(), "{args:?}: no table after an error");
    for n in needles {
        assert!(
            err.contains(n),
            "{args:?}: error should mention {n:?}: {err}"
        );
    }
}

#[test]
fn bench_accel_bad_input() {
    let r = Run::new();
    r.write("scene.toml", GOOD);
    r.write("empty.obj", "# nothing\nv 0 0 0\nv 1 0 0\n");
    r.write("mesh.stl", "solid x\n");
    r.write("odd.bin", &"x".repeat(25));
    r.write("empty.bin", "");
    expect_bench_error(&r, &["nope.obj"], &["nope.obj"]);
    expect_bench_error(&r, &["nope.toml"], &["nope.toml"]);
    expect_bench_error(&r, &["mesh.stl"], &["mesh.stl", "unknown input"]);
    expect_bench_error(&r, &["empty.obj"], &["empty.obj"]);
    expect_bench_error(&r, &["gen:teapot"], &["gen:teapot", "million"]);
    expect_bench_error(
        &r,
        &["scene.toml", "--accel", "bvh,qbvh:bogus"],
        &["qbvh:bogus"],
    );
    expect_bench_error(&r, &["scene.toml", "--accel", "kd"], &["--accel", "kd"]);
    expect_bench_error(
        &r,
        &["scene.toml", "--rays", "primary,diffuse"],
        &["--rays", "diffuse"],
    );
    expect_bench_error(&r, &["scene.toml", "--rays", "file"], &["--ray-file"]);
    expect_bench_error(
        &r,
        &["scene.toml", "--ray-file", "odd.bin"],
        &["odd.bin", "multiple of 24"],
    );
    expect_bench_error(
        &r,
        &["scene.toml", "--ray-file", "empty.bin"],
        &["empty.bin", "empty"],
    );
    expect_bench_error(&r, &["scene.toml", "--ray-file", "none.bin"], &["none.bin"]);
    expect_bench_error(&r, &["scene.toml", "--threads", "0"], &["thread"]);
    expect_bench_error(
        &r,
        &["scene.toml", "--camera", "side"],
        &["scene.toml", "side"],
    );
    expect_bench_error(
        &r,
        &["scene.toml", "--height", "0"],
        &["--width/--height", "0"],
    );
    expect_bench_error(
        &r,
        &["scene.toml", "--view", "inside"],
        &["--view", "scene.toml"],
    );
}

fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(
        header.starts_with(
            "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,leaves_per_ray,tris_per_ray"
        ),
        "{header}"
    );
    let names: Vec<&str> = header.split(',').collect();
    lines
        .map(|l| {
            let row: Vec<String> = l.split(',').map(str::to_string).collect();
            assert_eq!(row.len(), names.len(), "{l}");
            row
        })
        .collect()
}

#[test]
fn bench_accel_on_a_procedural_scene_writes_the_csv() {
    let r = Run::new();
    let out = r.render(&[
        "bench-accel",
        "gen:worst-case",
        "--accel",
        "bvh,qbvh,bvh8,brute-force",
        "--width",
        "24",
        "--height",
        "16",
        "--threads",
        "2",
        "--repeat",
        "1",
        "--csv",
        "out.csv",
        "--dump-rays",
        "rays",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("0 mismatches"), "{err}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("Mrays/s") && table.contains("brute-force"),
        "{table}"
    );
    let rows = csv_rows(&r.path("out.csv"));
    // One row per (accel, rays, threads).
    let mut keys: Vec<(String, String, String)> = rows
        .iter()
        .map(|r| (r[0].clone(), r[1].clone(), r[2].clone()))
        .collect();
    // Four structures, four ray sets (the default sets: primary, incoherent, shadow, uniform),
    // one and two threads.
    assert_eq!(keys.len(), 4 * 4 * 2);
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), 4 * 4 * 2);
    for row in &rows {
        assert!(["bvh", "qbvh", "bvh8", "brute-force"].contains(&row[0].as_str()));
        assert!(["primary", "incoherent", "shadow", "uniform"].contains(&row[1].as_str()));
        assert!(["1", "2"].contains(&row[2].as_str()));
        assert!(row[5].parse::<f64>().unwrap() > 0.0, "{row:?}");
        assert_eq!(row[15], "0", "check mismatches: {row:?}");
        assert_eq!(row[10], "gen:worst-case");
        assert_eq!(row[11], "4100");
    }
    // Every structure finds the same number of hits on the same rays.
    let hits = |accel: &str, rays: &str| -> String {
        rows.iter().find(|r| r[0] == accel && r[1] == rays).unwrap()[6].clone()
    };
    for rays in ["primary", "incoherent", "shadow", "uniform"] {
        assert_eq!(hits("qbvh", rays), hits("bvh", rays));
        assert_eq!(hits("bvh8", rays), hits("bvh", rays));
        assert_eq!(hits("brute-force", rays), hits("bvh", rays));
    }
    let primary: usize = rows.iter().find(|r| r[1] == "primary").unwrap()[13]
        .parse()
        .unwrap();
    assert_eq!(primary, 24 * 16);

    // The dumped rays, read back, give the same answers.
    for (file, rays, extra) in [
        ("rays/primary.bin", "primary", None),
        ("rays/shadow.bin", "shadow", Some("--ray-file-occlusion")),
    ] {
        let mut args = vec![
            "bench-accel",
            "gen:worst-case",
            "-q",
            "--threads",
            "1",
            "--repeat",
            "1",
            "--ray-file",
            file,
            "--csv",
            "file.csv",
        ];
        args.extend(extra);
        let out = r.render(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let file_rows = csv_rows(&r.path("file.csv"));
        assert_eq!(
            file_rows.len(),
            3,
            "bvh, qbvh and bvh8, one thread, one set"
        );
        for row in &file_rows {
            assert_eq!(row[1], "file");
            assert_eq!(row[6], hits(&row[0], rays), "{file} {row:?}");
        }
    }
}

#[test]
fn bench_accel_on_a_mesh_and_a_scene() {
    let r = Run::new();
    // A closed octahedron.
    r.write(
        "octa.obj",
        "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
         f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n",
    );
    let out = r.render(&[
        "bench-accel",
        "octa.obj",
        "--width",
        "16",
        "--threads",
        "1",
        "--repeat",
        "1",
        "--csv",
        "o.csv",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("point light"), "{err}");
    let rows = csv_rows(&r.path("o.csv"));
    assert_eq!(
        rows.len(),
        3 * 4,
        "three structures, four sets, one thread count"
    );
    // The automatic camera sees the mesh.
    let primary = rows.iter().find(|r| r[1] == "primary").unwrap();
    assert!(primary[6].parse::<u32>().unwrap() > 16, "{primary:?}");

    // Standing inside the closed octahedron, every primary ray hits.
    let out = r.render(&[
        "bench-accel",
        "octa.obj",
        "--view",
        "inside",
        "--width",
        "16",
        "--threads",
        "1",
        "--repeat",
        "1",
        "--rays",
        "primary",
        "--csv",
        "inside.csv",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = csv_rows(&r.path("inside.csv"));
    assert_eq!(rows.len(), 3);
    for row in &rows {
        assert_eq!(row[6], row[13], "hits = rays: {row:?}");
    }

    r.write("scene.toml", GOOD);
    let out = r.render(&[
        "bench-accel",
        "scene.toml",
        "--rays",
        "shadow",
        "--threads",
        "1",
        "--repeat",
        "1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("2 emissive triangles"), "{err}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("shadow") && !table.contains("primary"),
        "{table}"
    );
}

/// `--error` and `--time-limit` take positive numbers; light tracing takes no AOVs.
#[test]
fn bad_stopping_and_technique_arguments_are_one_error_line() {
    for bad in ["0", "-1", "nan", "inf"] {
        expect_error(GOOD, &[&format!("--error={bad}")], &["--error"]);
        expect_error(GOOD, &[&format!("--time-limit={bad}")], &["--time-limit"]);
    }
    expect_error(
        GOOD,
        &["--integrator", "light", "--aov", "albedo"],
        &["light", "AOV"],
    );
}

/// An adaptive render says why it stopped and how many samples it took.
#[test]
fn adaptive_render_reports_its_stop() {
    let r = Run::new();
    r.write("scene.toml", GOOD);
    let out = r.render(&[
        "scene.toml",
        "-o",
        "a.exr",
        "--error",
        "1e-1",
        "--spp",
        "64",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("adaptive: "), "{text}");
    assert!(text.contains(" samples, "), "{text}");
    assert!(r.path("a.exr").exists());
}
