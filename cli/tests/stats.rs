//! `render --stats`: the table names what was built and what was skipped, with the bytes held,
//! and asking for outputs changes what is allocated but not the beauty image.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

/// The floor under a small lamp, no `[environment]`, a pinhole camera, 8×6 pixels.
fn lamp() -> String {
    let camera = r#"
[[camera]]
name = "main"
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
resolution = [8, 6]
"#;
    format!("{camera}{}", common::FLOOR_AND_LAMP)
}

const PIXELS: u64 = 8 * 6;

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Runs `render` in `dir`, expects success, returns stdout.
fn render(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// One row of the stats table.
#[derive(Debug)]
struct Row {
    status: String,
    bytes: Option<u64>,
    details: String,
}

/// The row of stage `name`: the name is padded to 28 columns, then status, time and bytes
/// separated by spaces, then details.
fn row(table: &str, name: &str) -> Row {
    let line = table
        .lines()
        .find(|l| l.len() > 28 && l[..28].trim_end() == name)
        .unwrap_or_else(|| panic!("no stage {name:?} in:\n{table}"));
    let mut rest = line[28..].split_whitespace();
    let status = rest.next().unwrap().to_string();
    let (time, bytes) = (rest.next().unwrap(), rest.next().unwrap());
    // "1.234 ms" is two words.
    let bytes = if time != "-" {
        rest.next().unwrap()
    } else {
        bytes
    };
    Row {
        status,
        bytes: bytes.parse().ok(),
        details: rest.collect::<Vec<_>>().join(" "),
    }
}

fn assert_skipped(table: &str, name: &str, why: &str) {
    let r = row(table, name);
    assert_eq!(
        (r.status.as_str(), r.bytes),
        ("skipped", None),
        "{name}: {r:?}"
    );
    assert_eq!(r.details, why, "{name}");
}

fn assert_holds(table: &str, name: &str, status: &str) -> u64 {
    let r = row(table, name);
    assert_eq!(r.status, status, "{name}: {r:?}");
    let b = r
        .bytes
        .unwrap_or_else(|| panic!("{name} has no bytes: {r:?}"));
    assert!(b > 0, "{name}: {r:?}");
    b
}

#[test]
fn stats_show_skipped_stages_for_a_scene_without_environment_map_or_aovs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.toml"), lamp()).unwrap();
    let table = render(dir.path(), &["lamp.toml", "--spp", "2", "-q", "--stats"]);
    // -q silences the summary line but not the requested table.
    assert!(!table.contains("Msamples/s"), "{table}");
    assert!(table.starts_with("stage "), "{table}");

    assert_skipped(&table, "environment importance map", "no environment");
    assert_skipped(&table, "film squares (variance)", "no consumer");
    assert_skipped(&table, "film half-buffers", "no consumer");
    assert_skipped(&table, "film AOV hit count", "no first-hit AOV requested");
    for aov in ["albedo", "normal", "depth", "position"] {
        assert_skipped(&table, &format!("film AOV {aov}"), "not requested");
    }
    assert_skipped(&table, "lens sampling", "pinhole camera");

    assert_holds(&table, "scene load", "done");
    assert_holds(&table, "acceleration structure", "built");
    // Two emitting triangles: their records, two powers and a three-entry cdf.
    assert_eq!(
        assert_holds(&table, "light sampling structure", "built"),
        2 * std::mem::size_of::<rt_core::lights::Emitter>() as u64 + (2 + 3) * 4
    );

    // Ambient occlusion samples no light: the light sampler is not built.
    let ao = render(
        dir.path(),
        &[
            "lamp.toml",
            "--spp",
            "1",
            "-q",
            "--stats",
            "--integrator",
            "ao",
            "-o",
            "ao.exr",
        ],
    );
    assert_skipped(
        &ao,
        "light sampling structure",
        "the integrator samples no lights",
    );
    assert_eq!(
        assert_holds(&table, "film mean + count", "allocated"),
        PIXELS * 52
    );
    let written = assert_holds(&table, "output write", "done");
    assert_eq!(
        written,
        std::fs::metadata(dir.path().join("lamp.exr"))
            .unwrap()
            .len()
    );
    let render_row = row(&table, "render");
    assert!(
        render_row
            .details
            .starts_with(&format!("{} samples", PIXELS * 2)),
        "{render_row:?}"
    );

    // Without emitters the emitter table is skipped too (the sky still lights the scene).
    let sky = lamp().replace("emission = [5.0, 5.0, 5.0]", "color = [0.5, 0.5, 0.5]")
        + "\n[environment]\ncolor = [1, 1, 1]\n";
    std::fs::write(dir.path().join("sky.toml"), sky).unwrap();
    let table = render(dir.path(), &["sky.toml", "--spp", "1", "-q", "--stats"]);
    assert_skipped(
        &table,
        "light sampling structure",
        "no emitters (light samples go to the environment)",
    );
    assert_skipped(&table, "environment importance map", "constant environment");
}

#[test]
fn requested_aovs_are_allocated_and_leave_the_beauty_image_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.toml"), lamp()).unwrap();
    let common = [
        "lamp.toml",
        "--spp",
        "16",
        "-q",
        "--stats",
        "--threads",
        "2",
    ];
    let plain = render(dir.path(), &[&common[..], &["-o", "plain.exr"]].concat());
    let table = render(
        dir.path(),
        &[&common[..], &["-o", "aov.exr", "--aov", "variance,albedo"]].concat(),
    );
    assert_skipped(&plain, "film squares (variance)", "no consumer");
    assert_eq!(
        assert_holds(&table, "film squares (variance)", "allocated"),
        PIXELS * 96
    );
    assert_eq!(
        assert_holds(&table, "film AOV albedo", "allocated"),
        PIXELS * 48
    );
    assert_eq!(
        assert_holds(&table, "film AOV hit count", "allocated"),
        PIXELS * 4
    );
    assert_skipped(&table, "film AOV depth", "not requested");
    assert_skipped(&table, "film half-buffers", "no consumer");

    let a = rt_film::read_exr(&dir.path().join("plain.exr")).unwrap();
    let b = rt_film::read_exr(&dir.path().join("aov.exr")).unwrap();
    assert!(a.channel("variance.R").is_none() && b.channel("variance.R").is_some());
    assert!(b.channel("albedo.G").is_some() && b.channel("depth.Z").is_none());
    for c in ["R", "G", "B"] {
        let bits = |img: &rt_film::output::ExrImage| -> Vec<u32> {
            img.channel(c)
                .unwrap()
                .iter()
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(&a), bits(&b), "channel {c} differs");
    }
}

#[test]
fn shipped_scenes_build_the_importance_map_and_use_the_lens() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = scenes_dir();
    let env = scenes.join("environment.toml");
    let out = dir.path().join("env.exr");
    let args = |scene: &Path, out: &Path| {
        vec![
            scene.to_str().unwrap().to_string(),
            "-o".into(),
            out.to_str().unwrap().to_string(),
            "--spp".into(),
            "1".into(),
            "--max-depth".into(),
            "1".into(),
            "-q".into(),
            "--stats".into(),
        ]
    };
    let a = args(&env, &out);
    let table = render(
        dir.path(),
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let map = assert_holds(&table, "environment importance map", "built");
    assert!(map > 256 * 128 * 4, "{map}");
    assert_eq!(
        row(&table, "environment importance map").details,
        "256x128 map"
    );
    assert_skipped(
        &table,
        "light sampling structure",
        "no emitters (light samples go to the environment)",
    );

    let dof = scenes.join("depth-of-field.toml");
    let out = dir.path().join("dof.exr");
    let a = args(&dof, &out);
    let table = render(
        dir.path(),
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let lens = row(&table, "lens sampling");
    assert_eq!(
        (lens.status.as_str(), lens.details.as_str()),
        ("used", "aperture 0.12")
    );
    let mut a = args(&dof, &out);
    a.extend(["--camera".to_string(), "pinhole".to_string()]);
    let table = render(
        dir.path(),
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    assert_skipped(&table, "lens sampling", "pinhole camera");
}

#[test]
fn partitioned_reports_its_own_stages() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), lamp()).unwrap();
    let table = render(
        dir.path(),
        &[
            "s.toml",
            "--integrator",
            "partitioned:vpls=4:photons=1000",
            "--spp",
            "2",
            "--stats",
            "-q",
            "-o",
            "o.exr",
        ],
    );
    let eye = row(&table, "eye paths and VPLs");
    assert_eq!(eye.status, "done");
    assert!(eye.details.starts_with("2 passes, "), "{}", eye.details);
    // No specular surface, so the caustic stage draws its photons but none lands.
    let caustic = row(&table, "caustic histogram");
    assert!(
        caustic.details.ends_with(", 0 landed in bins"),
        "{}",
        caustic.details
    );
    assert_eq!(row(&table, "projection maps").status, "done");
    // A camera-ray technique has no such stages.
    let path = render(
        dir.path(),
        &["s.toml", "--spp", "1", "--stats", "-q", "-o", "o.exr"],
    );
    assert!(!path.contains("caustic histogram"), "{path}");
}

#[test]
fn stats_give_the_structure_bytes_apart_from_the_triangles() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.toml"), lamp()).unwrap();
    let row = |accel: &str| {
        let table = render(
            dir.path(),
            &["lamp.toml", "--spp", "1", "-q", "--stats", "--accel", accel],
        );
        table
            .lines()
            .find(|l| l.starts_with("acceleration structure"))
            .unwrap_or_else(|| panic!("{table}"))
            .to_string()
    };
    // IOSP-0 is the reordered scene's triangles and nothing else.
    let iosp0 = row("iosp0");
    assert!(
        iosp0.contains("iosp0; structure 0 B (0.00 B/triangle) beyond "),
        "{iosp0}"
    );
    let bvh = row("bvh");
    assert!(
        bvh.contains("; structure ") && bvh.contains(" B of triangles"),
        "{bvh}"
    );
}

#[test]
fn stats_say_which_path_tracer_ran_and_cover_denoised_renders() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.toml"), lamp()).unwrap();
    let table = |out: &str, extra: &[&str]| {
        let mut args = vec!["lamp.toml", "--spp", "2", "--stats", "-o", out];
        args.extend_from_slice(extra);
        render(dir.path(), &args)
    };
    // The default integrator is the wavefront tracer: its row gives the stage shares.
    let w = row(&table("a.exr", &["-q"]), "wavefront batches");
    assert_eq!(w.status, "done");
    assert!(
        w.details.contains("lanes per thread") && w.details.contains("shade"),
        "{w:?}"
    );
    // The lighting split runs on the scalar tracer, and the table says so.
    let split = table("b.exr", &["-q", "--aov", "direct"]);
    let s = row(&split, "scalar path tracer");
    assert!(s.details.contains("lighting-split"), "{s:?}");
    assert!(!split.contains("wavefront batches"), "{split}");
    // `--integrator path` is the scalar tracer alone.
    let scalar = table("c.exr", &["-q", "--integrator", "path"]);
    assert!(!scalar.contains("wavefront batches"), "{scalar}");
    // A denoised render prints the table too.
    let denoised = table("d.exr", &["--denoiser", "box"]);
    assert_eq!(row(&denoised, "wavefront batches").status, "done");
}
