//! End-to-end tests of saved frames and `render denoise`: `--aov denoise` writes every channel
//! and they read back bit for bit; the denoised file is what the library computes from them;
//! bad specs, missing channels and missing files each give one error line and exit code 1.

mod common;

use common::{one_error_line, render};

use rt_denoise::{DenoiserSpec, NoisyFrame};
use rt_film::Channel;

fn scene(dir: &std::path::Path) {
    let camera = "[[camera]]\nname = \"c\"\nposition = [0.0, 1.0, 2.5]\nlook_at = [0.0, 0.0, 0.0]\nfov = 50.0\nresolution = [20, 14]\n";
    std::fs::write(
        dir.join("s.toml"),
        format!("{camera}{}", common::FLOOR_AND_LAMP),
    )
    .unwrap();
}

#[test]
fn saved_frames_denoise_like_the_library_and_bad_input_is_one_line() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let out = render(
        dir,
        &["s.toml", "--spp", "4", "--aov", "denoise", "-o", "f.exr"],
    );
    assert!(out.status.success(), "{out:?}");
    let frame = NoisyFrame::from_exr(&dir.join("f.exr")).unwrap();
    let saved: Vec<Channel> = Channel::ALL
        .into_iter()
        .filter(|&c| c != Channel::Samples)
        .collect();
    assert_eq!(frame.channels(), saved);
    // The lighting split of a diffuse floor: no glossy light, and the parts add up.
    let c = frame.colour.pixels();
    let (e, di, ind) = (
        frame.emission.as_ref().unwrap().pixels(),
        frame.direct.as_ref().unwrap().pixels(),
        frame.indirect.as_ref().unwrap().pixels(),
    );
    for i in 0..c.len() {
        assert!(
            (e[i] + di[i] + ind[i] - c[i]).abs().max_element() <= 1e-4 * (1.0 + c[i].max_element())
        );
    }

    let out = render(
        dir,
        &[
            "denoise",
            "f.exr",
            "--denoiser",
            "box:radius=2",
            "-o",
            "d.exr",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let want = "box:radius=2"
        .parse::<DenoiserSpec>()
        .unwrap()
        .build()
        .unwrap();
    let want = want.denoise(&frame).unwrap();
    let got = rt_film::read_rgb(&dir.join("d.exr")).unwrap();
    assert_eq!(got, want);

    let err = one_error_line(&render(
        dir,
        &[
            "denoise",
            "f.exr",
            "--denoiser",
            "box:size=2",
            "-o",
            "x.exr",
        ],
    ));
    assert!(err.contains("box: unknown option `size`"), "{err}");
    let err = one_error_line(&render(
        dir,
        &["denoise", "f.exr", "--denoiser", "nope", "-o", "x.exr"],
    ));
    assert!(err.contains("unknown denoiser 'nope'"), "{err}");
    let err = one_error_line(&render(
        dir,
        &["denoise", "gone.exr", "--denoiser", "box", "-o", "x.exr"],
    ));
    assert!(err.contains("gone.exr"), "{err}");
    assert!(!dir.join("x.exr").exists());

    // A frame without a channel the denoiser reads: the file and the channel are named.
    let out = render(
        dir,
        &["s.toml", "--spp", "2", "--aov", "albedo", "-o", "a.exr"],
    );
    assert!(out.status.success(), "{out:?}");
    let err = one_error_line(&render(
        dir,
        &["denoise", "a.exr", "--denoiser", "atrous", "-o", "x.exr"],
    ));
    assert!(
        err.contains("a.exr") && err.contains("needs the normal channel"),
        "{err}"
    );
    assert!(!dir.join("x.exr").exists());
    // SBMF filters samples, which no file holds: it runs while rendering, not on a saved frame.
    let err = one_error_line(&render(
        dir,
        &["denoise", "f.exr", "--denoiser", "sbmf", "-o", "x.exr"],
    ));
    assert!(
        err.contains("samples") && err.contains("--denoiser"),
        "{err}"
    );
    let out = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "2",
            "--denoiser",
            "sbmf:manifolds=3",
            "-o",
            "s.exr",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let sbmf = rt_film::read_rgb(&dir.join("s.exr")).unwrap();
    assert!(sbmf.pixels().iter().all(|p| p.is_finite()) && sbmf.pixels().iter().any(|p| p.x > 0.0));
    // A render-time denoiser is the library's on the same film: same seed, same frame.
    let out = render(
        dir,
        &[
            "s.toml",
            "--spp",
            "4",
            "--denoiser",
            "box:radius=2",
            "-o",
            "b.exr",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let got = rt_film::read_rgb(&dir.join("b.exr")).unwrap();
    let want = "box:radius=2"
        .parse::<DenoiserSpec>()
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(
        got,
        want.denoise(&NoisyFrame::new(
            rt_film::read_rgb(&dir.join("f.exr")).unwrap()
        ))
        .unwrap()
    );
    let err = one_error_line(&render(
        dir,
        &[
            "s.toml",
            "--denoiser",
            "atrous:split=direct-indirect",
            "--integrator",
            "ao",
            "-o",
            "y.exr",
        ],
    ));
    assert!(err.contains("lighting split"), "{err}");
    // With every channel it runs.
    let out = render(
        dir,
        &[
            "denoise",
            "f.exr",
            "--denoiser",
            "atrous:split=direct-indirect",
            "-o",
            "x.png",
        ],
    );
    assert!(out.status.success(), "{out:?}");
}

/// `[render] denoiser`: the scene's default is read and applied like `--denoiser`, a given
/// `--denoiser` wins (`none` turns it off), and a bad value is one error line naming the file.
#[test]
fn the_render_tables_denoiser_is_read_and_a_bad_one_is_one_line() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    scene(dir);
    let base = std::fs::read_to_string(dir.join("s.toml")).unwrap();
    let with = |name: &str, table: &str| {
        std::fs::write(
            dir.join(name),
            format!("{base}\n[render]\nspp = 4\n{table}\n"),
        )
        .unwrap();
    };
    with("t.toml", "denoiser = \"box:radius=2\"");
    let out = render(dir, &["t.toml", "-o", "t.exr"]);
    assert!(out.status.success(), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("denoised by box"), "{stdout}");
    let out = render(dir, &["t.toml", "--denoiser", "none", "-o", "n.exr"]);
    assert!(out.status.success(), "{out:?}");
    let noisy = rt_film::read_rgb(&dir.join("n.exr")).unwrap();
    let want = |spec: &str| {
        let d = spec.parse::<DenoiserSpec>().unwrap().build().unwrap();
        d.denoise(&NoisyFrame::new(noisy.clone())).unwrap()
    };
    assert_eq!(
        rt_film::read_rgb(&dir.join("t.exr")).unwrap(),
        want("box:radius=2")
    );
    assert_ne!(noisy, want("box:radius=2"));
    // The command line wins over the table.
    let out = render(
        dir,
        &["t.toml", "--denoiser", "box:radius=1", "-o", "g.exr"],
    );
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        rt_film::read_rgb(&dir.join("g.exr")).unwrap(),
        want("box:radius=1")
    );
    // AOVs with the table's denoiser: one line saying how to keep them.
    let err = one_error_line(&render(
        dir,
        &["t.toml", "--aov", "variance", "-o", "a.exr"],
    ));
    assert!(
        err.contains("t.toml: [render] denoiser = \"box:radius=2\"")
            && err.contains("--denoiser none"),
        "{err}"
    );
    let out = render(
        dir,
        &[
            "t.toml",
            "--denoiser",
            "none",
            "--aov",
            "variance",
            "-o",
            "a.exr",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    // Bad values: one line naming the file and the key (and the position when the type or
    // the emptiness is wrong).
    for (table, want) in [
        (
            "denoiser = \"optix\"",
            "b.toml: [render] denoiser = \"optix\": unknown denoiser 'optix'",
        ),
        (
            "denoiser = \"nlm:size=3\"",
            "b.toml: [render] denoiser = \"nlm:size=3\"",
        ),
        ("denoiser = \"\"", "denoiser must name a denoiser"),
        ("denoiser = 3", "b.toml:"),
    ] {
        with("b.toml", table);
        let err = one_error_line(&render(dir, &["b.toml", "-o", "b.exr"]));
        assert!(
            err.starts_with("error: ") && err.contains(want),
            "{table}: {err}"
        );
        assert!(!dir.join("b.exr").exists());
    }
}
