//! Parts and merges: any split of a render into sample ranges and regions merges to the very
//! bytes of the single render, for camera and light-path techniques, with AOVs and with a
//! denoiser; parts that do not belong together are refused with one line naming them.

mod common;
use common::{one_error_line, render, FLOOR_AND_LAMP};
use std::path::Path;

/// The floor and lamp, with an OBJ box whose file the scene hash must cover.
fn scene(dir: &Path) {
    let text = format!(
        "{FLOOR_AND_LAMP}\n[[camera]]\nname = \"cam\"\nposition = [0, 1, 3]\nlook_at = [0, 0.5, 0]\nresolution = [24, 16]\n\n[[geometry]]\nname = \"tri\"\nfile = \"tri.obj\"\nmaterial = \"white\"\n"
    );
    std::fs::write(dir.join("s.toml"), text).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v -0.5 0 0\nv 0.5 0 0\nv 0 0.8 0.2\nf 1 2 3\n",
    )
    .unwrap();
}

fn ok(out: std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn bytes(dir: &Path, f: &str) -> Vec<u8> {
    std::fs::read(dir.join(f)).unwrap()
}

/// Renders the whole image and the given slices of it, merges the slices, and checks the bytes.
fn check_split(dir: &Path, settings: &[&str], out: &str, slices: &[(&str, Option<&str>)]) {
    let mut whole = vec!["s.toml", "-q", "-o", out];
    whole.extend(settings);
    ok(render(dir, &whole));
    let mut files = Vec::new();
    for (k, (samples, region)) in slices.iter().enumerate() {
        let file = format!("p{k}.rpart");
        let mut a = vec!["s.toml", "-q", "--sample-range", samples, "-o", &file];
        if let Some(r) = region {
            a.extend(["--region", r]);
        }
        a.extend(settings);
        ok(render(dir, &a));
        files.push(file);
    }
    let merged = format!("merged-{out}");
    let mut m = vec!["merge", "-q", "-o", &merged];
    m.extend(files.iter().map(String::as_str));
    ok(render(dir, &m));
    assert!(
        bytes(dir, out) == bytes(dir, &merged),
        "{settings:?}: the merged image differs from the single render"
    );
    for f in files {
        std::fs::remove_file(dir.join(f)).unwrap();
    }
}

/// Sample ranges of unequal length, and regions that cut rows and columns unevenly.
const SPLITS: [(&str, Option<&str>); 5] = [
    ("0..3", None),
    ("3..4", Some("0,0,7,16")),
    ("3..4", Some("7,0,24,5")),
    ("3..4", Some("7,5,24,16")),
    ("4..9", None),
];

#[test]
fn any_split_merges_to_the_single_render_byte_for_byte() {
    let d = tempfile::tempdir().unwrap();
    scene(d.path());
    // A camera technique with every AOV (sums of squares, halves, features, lighting split).
    check_split(
        d.path(),
        &["--spp", "9", "--aov", "denoise"],
        "path.exr",
        &SPLITS,
    );
    // Light tracing and BDPT: splats land anywhere, regions keep those inside.
    check_split(
        d.path(),
        &["--spp", "9", "--integrator", "light"],
        "light.exr",
        &SPLITS,
    );
    check_split(
        d.path(),
        &["--spp", "9", "--integrator", "bdpt:max-depth=4"],
        "bdpt.exr",
        &SPLITS,
    );
    // Denoised after the merge, and a PNG with exposure.
    check_split(
        d.path(),
        &["--spp", "9", "--denoiser", "atrous"],
        "den.exr",
        &SPLITS,
    );
    check_split(
        d.path(),
        &["--spp", "9", "--exposure", "1.5"],
        "img.png",
        &SPLITS,
    );
}

#[test]
fn plans_run_part_by_part_merge_to_the_single_render() {
    let d = tempfile::tempdir().unwrap();
    scene(d.path());
    let out = ok(render(
        d.path(),
        &[
            "plan",
            "s.toml",
            "--tiles",
            "10x6",
            "--sample-splits",
            "3",
            "-o",
            "plan.json",
            "--",
            "--spp",
            "7",
            "-o",
            "planned.exr",
        ],
    ));
    // 3 columns x 3 rows x 3 ranges.
    assert!(out.starts_with("27 parts, 1 outputs"), "{out}");
    for i in 0..27 {
        ok(render(
            d.path(),
            &[
                "part",
                "plan.json",
                "--index",
                &i.to_string(),
                "-o",
                "parts",
                "-q",
            ],
        ));
    }
    // A retried part replaces its file whole.
    ok(render(
        d.path(),
        &["part", "plan.json", "--index", "5", "-o", "parts", "-q"],
    ));
    ok(render(
        d.path(),
        &["merge", "--plan", "plan.json", "parts", "-q"],
    ));
    ok(render(
        d.path(),
        &["s.toml", "--spp", "7", "-o", "whole.exr", "-q"],
    ));
    assert!(bytes(d.path(), "planned.exr") == bytes(d.path(), "whole.exr"));
    // One part missing: the merge names the gap.
    std::fs::remove_file(d.path().join("parts/part-000004.rpart")).unwrap();
    let e = one_error_line(&render(
        d.path(),
        &["merge", "--plan", "plan.json", "parts"],
    ));
    assert!(
        e.contains("part-000004.rpart") && e.contains("cannot read"),
        "{e}"
    );
    let e = one_error_line(&render(
        d.path(),
        &["part", "plan.json", "--index", "27", "-o", "parts"],
    ));
    assert!(e.contains("--index 27 but the plan has parts 0..27"), "{e}");
}

#[test]
fn parts_that_do_not_belong_together_are_refused_with_one_line() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let part = |range: &str, extra: &[&str], file: &str| {
        let mut a = vec![
            "s.toml",
            "-q",
            "--spp",
            "4",
            "--sample-range",
            range,
            "-o",
            file,
        ];
        a.extend(extra);
        ok(render(dir, &a));
    };
    part("0..2", &[], "a.rpart");
    part("2..4", &[], "b.rpart");
    part("1..4", &[], "over.rpart");
    part("2..4", &["--seed", "3"], "seed.rpart");
    part("2..4", &["--aov", "albedo"], "aov.rpart");
    let merge = |files: &[&str]| {
        let mut a = vec!["merge", "-o", "m.exr"];
        a.extend(files);
        one_error_line(&render(dir, &a))
    };
    assert!(merge(&["a.rpart"]).contains("no part renders samples 2..4"));
    let e = merge(&["a.rpart", "over.rpart"]);
    assert!(
        e.contains("a.rpart and over.rpart overlap: both render samples 1..2"),
        "{e}"
    );
    let e = merge(&["a.rpart", "seed.rpart"]);
    assert!(
        e.contains("seed.rpart does not belong with a.rpart: its setting seed"),
        "{e}"
    );
    assert!(merge(&["a.rpart", "aov.rpart"]).contains("its AOV set is albedo"));
    // The scene's mesh changed between the parts.
    std::fs::write(
        dir.join("tri.obj"),
        "v -0.5 0 0\nv 0.5 0 0\nv 0 0.9 0.2\nf 1 2 3\n",
    )
    .unwrap();
    part("2..4", &[], "moved.rpart");
    let e = merge(&["a.rpart", "moved.rpart"]);
    assert!(e.contains("its scene content (hash) is"), "{e}");
    // A damaged or foreign file.
    let mut b = bytes(dir, "b.rpart");
    let k = b.len() / 2;
    b[k] ^= 0x40;
    std::fs::write(dir.join("bad.rpart"), b).unwrap();
    assert!(merge(&["a.rpart", "bad.rpart"]).contains("bad.rpart: damaged"));
    std::fs::write(dir.join("text.rpart"), "hello").unwrap();
    assert!(merge(&["text.rpart"]).contains("text.rpart: not a part file"));
    // What a part cannot be.
    let refuse = |a: &[&str]| one_error_line(&render(dir, a));
    let e = refuse(&["s.toml", "--spp", "4", "--error", "0.01", "-o", "x.rpart"]);
    assert!(
        e.contains("a part file cannot hold an adaptive render"),
        "{e}"
    );
    let e = refuse(&[
        "s.toml",
        "--spp",
        "4",
        "--denoiser",
        "sbmf",
        "-o",
        "x.rpart",
    ]);
    assert!(e.contains("per-sample records"), "{e}");
    std::fs::write(dir.join("m.toml"), common::MOVING_BOX).unwrap();
    let e = refuse(&[
        "m.toml",
        "--frames",
        "0..2",
        "--denoiser",
        "svgf",
        "-o",
        "p_{frame}.rpart",
    ]);
    assert!(
        e.contains("cannot hold a temporally denoised sequence"),
        "{e}"
    );
    let e = refuse(&["s.toml", "--sample-range", "0..2", "-o", "x.exr"]);
    assert!(e.contains("-o must end in .rpart"), "{e}");
    let e = refuse(&[
        "s.toml",
        "--spp",
        "4",
        "--sample-range",
        "2..5",
        "-o",
        "x.rpart",
    ]);
    assert!(e.contains("the render takes samples 0..4"), "{e}");
    let e = refuse(&["s.toml", "--region", "0,0,25,3", "-o", "x.rpart"]);
    assert!(e.contains("outside the 24x16 image"), "{e}");
    // A malformed value is a usage error (status 2), still one line before clap's hint.
    let out = render(dir, &["s.toml", "--region", "3,0,3,3", "-o", "x.rpart"]);
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        e.lines()
            .next()
            .unwrap()
            .contains("--region must be x0,y0,x1,y1"),
        "{e}"
    );
}

#[test]
fn an_experiments_references_are_planned_merged_into_the_cache_and_found_there() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    std::fs::write(
        dir.join("x.toml"),
        "name = \"tiny\"\n\n[[scene]]\nname = \"room\"\npath = \"s.toml\"\nresolution = [12, 8]\nreference = { spp = 16 }\n\n[[method]]\nname = \"nee\"\nintegrator = \"path\"\nspp = [2]\n",
    )
    .unwrap();
    let out = ok(render(
        dir,
        &[
            "plan",
            "x.toml",
            "--experiment",
            "--tiles",
            "5x8",
            "--sample-splits",
            "2",
            "-o",
            "plan.json",
            "--cache",
            "cache",
        ],
    ));
    // 3 tiles x 2 ranges of the one reference.
    assert!(out.starts_with("6 parts, 1 outputs"), "{out}");
    for i in 0..6 {
        ok(render(
            dir,
            &[
                "part",
                "plan.json",
                "--index",
                &i.to_string(),
                "-o",
                "parts",
                "-q",
            ],
        ));
    }
    ok(render(
        dir,
        &["merge", "--plan", "plan.json", "parts", "-q"],
    ));
    // The same bytes as the reference rendered in one go.
    ok(render(
        dir,
        &[
            "reference",
            "s.toml",
            "--spp",
            "16",
            "--resolution",
            "12x8",
            "--no-cache",
            "-o",
            "one.exr",
            "-q",
        ],
    ));
    let cached: Vec<_> = std::fs::read_dir(dir.join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .collect();
    assert_eq!(cached.len(), 1);
    assert!(std::fs::read(&cached[0]).unwrap() == bytes(dir, "one.exr"));
    // The experiment takes it from the cache instead of rendering it.
    let out = render(
        dir,
        &["experiment", "x.toml", "--out", "out", "--cache", "cache"],
    );
    let text =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("room: reference from the cache"), "{text}");
}

#[test]
fn a_planned_sequence_merges_to_each_frame_of_the_single_render() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(dir.join("m.toml"), common::MOVING_BOX).unwrap();
    let out = ok(render(
        dir,
        &[
            "plan",
            "m.toml",
            "--frames",
            "0..3",
            "--sample-splits",
            "2",
            "--tiles",
            "6x8",
            "-o",
            "plan.json",
            "--",
            "--spp",
            "4",
            "-o",
            "p_{frame}.exr",
        ],
    ));
    assert!(out.starts_with("12 parts, 3 outputs"), "{out}");
    for i in 0..12 {
        ok(render(
            dir,
            &[
                "part",
                "plan.json",
                "--index",
                &i.to_string(),
                "-o",
                "parts",
                "-q",
            ],
        ));
    }
    ok(render(
        dir,
        &["merge", "--plan", "plan.json", "parts", "-q"],
    ));
    ok(render(
        dir,
        &[
            "m.toml",
            "--frames",
            "0..3",
            "--spp",
            "4",
            "-o",
            "s_{frame}.exr",
            "-q",
        ],
    ));
    for f in 0..3 {
        assert!(
            bytes(dir, &format!("p_{f}.exr")) == bytes(dir, &format!("s_{f}.exr")),
            "frame {f}"
        );
    }
    // Frames differ from each other (the box moves), so a mix-up would show.
    assert!(bytes(dir, "s_0.exr") != bytes(dir, "s_2.exr"));
}
