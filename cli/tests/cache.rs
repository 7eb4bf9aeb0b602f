//! `render --cache`: a cached render is the same image for any thread count, a cache carries
//! over a sequence's frames (SVGF's too), and bad options give one error line naming the option.

mod common;

use common::{one_error_line, render};

fn scene(dir: &std::path::Path) {
    let camera = "[[camera]]\nname = \"c\"\nposition = [0.0, 1.0, 2.5]\nlook_at = [0.0, 0.0, 0.0]\nfov = 50.0\nresolution = [24, 16]\n";
    std::fs::write(
        dir.join("s.toml"),
        format!("{camera}{}", common::FLOOR_AND_LAMP),
    )
    .unwrap();
}

fn pixels(path: &std::path::Path) -> Vec<f32> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| vec![[0f32; 3]; res.width() * res.height()],
        |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * 24 + pos.x()] = [r, g, b]
        },
    )
    .unwrap();
    img.layer_data.channel_data.pixels.concat()
}

#[test]
fn cached_renders_do_not_depend_on_the_thread_count() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    for (threads, out) in [("1", "a.exr"), ("2", "b.exr")] {
        let o = render(
            dir,
            &[
                "s.toml",
                "--spp",
                "6",
                "--threads",
                threads,
                "--cache",
                "worldspace:lod=4",
                "-q",
                "-o",
                out,
            ],
        );
        assert!(o.status.success(), "{o:?}");
    }
    let (a, b) = (pixels(&dir.join("a.exr")), pixels(&dir.join("b.exr")));
    assert!(a.iter().all(|v| v.is_finite()));
    assert_eq!(
        a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // The cache changes the image (paths end at cached vertices after the first pass).
    let o = render(dir, &["s.toml", "--spp", "6", "-q", "-o", "c.exr"]);
    assert!(o.status.success());
    assert_ne!(a, pixels(&dir.join("c.exr")));
    // Grid and AO variants run too; a sequence keeps one cache over its frames.
    for args in [
        &[
            "s.toml",
            "--spp",
            "2",
            "--cache",
            "grid:jitter=1",
            "-q",
            "-o",
            "g.exr",
        ][..],
        &[
            "s.toml",
            "--spp",
            "2",
            "--integrator",
            "ao",
            "--cache",
            "worldspace",
            "-q",
            "-o",
            "ao.exr",
        ],
        &[
            "s.toml",
            "--spp",
            "1",
            "--frames",
            "0..2",
            "--cache",
            "worldspace",
            "-q",
            "-o",
            "f_{frame}.exr",
        ],
    ] {
        let o = render(dir, args);
        assert!(o.status.success(), "{args:?}: {o:?}");
    }
    assert!(dir.join("f_1.exr").exists());
    // The second frame's cache has merged both frames' passes.
    let o = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "2",
            "--frames",
            "0..2",
            "--cache",
            "worldspace",
            "--stats",
            "-o",
            "h_{frame}.exr",
        ],
    );
    let stats =
        String::from_utf8_lossy(&o.stderr).into_owned() + &String::from_utf8_lossy(&o.stdout);
    let passes: Vec<&str> = stats
        .lines()
        .filter(|l| l.starts_with("radiance cache"))
        .filter_map(|l| l.split(": ").nth(1)?.split(" passes").next())
        .collect();
    assert_eq!(passes, ["2", "4"], "{stats}");
}

#[test]
fn a_temporally_denoised_sequence_uses_the_cache() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let run = |extra: &[&str], out: &str| {
        let mut args = vec![
            "s.toml",
            "--spp",
            "4",
            "--frames",
            "0..3",
            "--denoiser",
            "svgf",
            "-q",
            "-o",
            out,
        ];
        args.extend_from_slice(extra);
        let o = render(dir, &args);
        assert!(o.status.success(), "{args:?}: {o:?}");
    };
    run(&["--cache", "worldspace:lod=4"], "c_{frame}.exr");
    run(&[], "p_{frame}.exr");
    let (c, p) = (pixels(&dir.join("c_2.exr")), pixels(&dir.join("p_2.exr")));
    assert!(c.iter().all(|v| v.is_finite()));
    assert_ne!(
        c, p,
        "--cache must not be ignored by a temporal denoiser's sequence"
    );
    // A technique without a cache is refused there as in a plain render.
    let o = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "1",
            "--frames",
            "0..2",
            "--denoiser",
            "svgf",
            "--integrator",
            "direct",
            "--cache",
            "worldspace",
            "-o",
            "x_{frame}.exr",
        ],
    );
    let e = one_error_line(&o);
    assert!(e.contains("--cache worldspace"), "{e}");
}

#[test]
fn bad_cache_options_are_one_line_naming_the_option() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let err = |spec: &str, extra: &[&str]| {
        let mut args = vec!["s.toml", "--spp", "1", "-o", "x.exr", "--cache", spec];
        args.extend_from_slice(extra);
        one_error_line(&render(dir, &args))
    };
    assert!(err("worldspace:lod=x", &[]).contains("worldspace: lod: `x` is not an integer"));
    assert!(err("octree", &[]).contains("unknown cache `octree`"));
    assert!(err("grid:bogus=1", &[]).contains("unknown option `bogus`"));
    assert!(err("worldspace:capacity=100", &[]).contains("capacity: `100`"));
    assert!(err("worldspace:lod=3,lod=4", &[]).contains("option `lod` given twice"));
    assert!(err("worldspace", &["--integrator", "light"]).contains("cannot use a cache"));
    assert!(!dir.join("x.exr").exists());
}
