//! Sequence experiments end to end: a few frames of a moving scene and of a still one, at
//! 16x12 with 16-spp references in a temporary cache; frames.csv and sequences.csv have the
//! right rows, and their numbers agree with the stills and the references written beside them.

use rt_experiment::{config, prepare_out, run, Cache, Silent};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The experiment file: the animated scene (its camera dollies, objects move) and the
/// interior (nothing moves), four frames each, the interior with an event at frame 2.
fn config_text() -> String {
    let scenes = root().join("scenes");
    format!(
        r#"
name = "seq"

[[scene]]
name = "anim"
path = "{0}/animated.toml"
resolution = [16, 12]
frames = [0, 4]
reference = {{ spp = 16 }}

[[scene]]
name = "still"
path = "{0}/interior.toml"
resolution = [16, 12]
frames = [10, 14]
fps = 30
event = 12
reference = {{ spp = 16, max_depth = 4 }}

[[method]]
name = "noisy"
spp = 1
max_depth = 4

[[method]]
name = "svgf"
spp = 1
max_depth = 4
denoiser = "svgf"

[[method]]
name = "atrous"
spp = [1]
max_depth = 4
denoiser = "atrous"
scenes = ["still"]
"#,
        scenes.display()
    )
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (head, rows)
}

fn col(head: &[String], name: &str) -> usize {
    head.iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {head:?}"))
}

#[test]
fn a_tiny_sequence_experiment_writes_per_frame_and_temporal_metrics() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seq.toml");
    std::fs::write(&path, config_text()).unwrap();
    let plan = config::load(&path).unwrap();
    assert!(plan.is_sequence());
    let out = dir.path().join("out");
    prepare_out(&out).unwrap();
    let cache = Cache::new(&dir.path().join("cache"));
    let outcome = run(&plan, &out, &cache, &Silent).unwrap();
    let results = outcome.sequences.as_ref().unwrap();
    // Every frame of every scene is its own cache entry (time is in the scene's content).
    let entries = std::fs::read_dir(dir.path().join("cache"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().unwrap() == "exr")
        .count();
    assert_eq!(entries, 8);
    assert!(results.reference_origins[0].contains("4 rendered, 0 from the cache"));

    // frames.csv: scene, method, frame in order; 2 pairs x 4 frames + 3 pairs x 4 frames.
    let (head, rows) = csv(&out.join("frames.csv"));
    assert_eq!(
        head.join(","),
        "scene,method,frame,relmse,mse,ssim,render_s,guides_s,denoise_s"
    );
    let keys: Vec<(String, String, u32)> = rows
        .iter()
        .map(|r| (r[0].clone(), r[1].clone(), r[2].parse().unwrap()))
        .collect();
    let mut want = Vec::new();
    for (scene, methods, frames) in [
        ("anim", &["noisy", "svgf"][..], 0..4),
        ("still", &["noisy", "svgf", "atrous"][..], 10..14),
    ] {
        for m in methods {
            for f in frames.clone() {
                want.push((scene.to_string(), m.to_string(), f));
            }
        }
    }
    assert_eq!(keys, want);
    let value = |r: &Vec<String>, c: &str| r[col(&head, c)].parse::<f64>().unwrap();
    for r in &rows {
        assert!(value(r, "relmse") > 0.0 && value(r, "ssim") <= 1.0, "{r:?}");
        if r[1] != "noisy" {
            assert!(value(r, "denoise_s") > 0.0, "{r:?}");
        }
        if r[1] == "svgf" {
            assert!(value(r, "guides_s") > 0.0, "{r:?}");
        }
    }
    // A still's EXR measured against its reference frame from the cache gives the row's relMSE.
    for still in results.stills.iter().filter(|s| s.method != "reference") {
        let scene = &plan.scenes[still.scene].name;
        let image = rt_film::read_rgb(&out.join(&still.exr)).unwrap();
        let reference_still = results
            .stills
            .iter()
            .find(|s| s.scene == still.scene && s.method == "reference" && s.frame == still.frame)
            .unwrap();
        let reference = rt_film::read_rgb(&out.join(&reference_still.exr)).unwrap();
        let m = rt_metrics::compare(&image, &reference, &Default::default()).unwrap();
        let row = rows
            .iter()
            .find(|r| &r[0] == scene && r[1] == still.method && r[2] == still.frame.to_string())
            .unwrap();
        assert_eq!(value(row, "relmse"), m.relmse, "{}", still.exr);
        assert!(out.join(&still.file).exists());
    }
    // The stills are the frames one SequenceRenderer makes rendering the frames in order (so
    // SVGF's history carried from frame to frame), at the pair's settings and size.
    for (pi, pair) in plan.pairs.iter().enumerate() {
        let scene = &plan.scenes[pair.scene];
        let method = &plan.methods[pair.method];
        let seq = scene.sequence.as_ref().unwrap();
        let rt_experiment::config::Runs::Sequence { spp } = method.runs else {
            panic!("{pi}")
        };
        let mut renderer = rt_session::SequenceRenderer::new(
            pair.estimator.build(),
            pair.accel,
            method.temporal.as_ref().map(|t| t.build().unwrap()),
            None,
            spp,
            pair.seed,
            seq.fps,
        )
        .unwrap();
        let mut moving = scene.loaded.scene.clone();
        for f in seq.frames.clone() {
            moving.set_time((f64::from(f) / seq.fps) as f32);
            let camera =
                rt_session::ImageSize::Pixels(16, 12).apply(moving.cameras.first().unwrap());
            let frame = renderer.render_with(&mut moving, f, Some(&camera)).unwrap();
            if let Some(still) = results
                .stills
                .iter()
                .find(|s| s.scene == pair.scene && s.method == method.name && s.frame == f)
            {
                let written = rt_film::read_rgb(&out.join(&still.exr)).unwrap();
                assert!(written == frame.image, "{} differs", still.exr);
            }
        }
    }
    // First, middle and last frames of every method and of the reference.
    let frames_of = |scene: usize, method: &str| -> Vec<u32> {
        results
            .stills
            .iter()
            .filter(|s| s.scene == scene && s.method == method)
            .map(|s| s.frame)
            .collect()
    };
    assert_eq!(frames_of(0, "reference"), [0, 2, 3]);
    assert_eq!(frames_of(1, "atrous"), [10, 12, 13]);

    // sequences.csv: one row per pair, its means from the frames.
    let (shead, srows) = csv(&out.join("sequences.csv"));
    assert_eq!(
        shead.join(","),
        "scene,method,frames,temporal_error,reference_temporal_error,temporal_relmse,lag,\
         mean_relmse,last_relmse,ms_per_frame,temporal_error_specular"
    );
    assert_eq!(srows.len(), 5);
    let seq = |scene: &str, method: &str| {
        srows
            .iter()
            .find(|r| r[0] == scene && r[1] == method)
            .unwrap()
            .clone()
    };
    let sv = |r: &Vec<String>, c: &str| r[col(&shead, c)].parse::<f64>().unwrap();
    for r in &srows {
        assert_eq!(r[col(&shead, "frames")], "4");
        let relmse: Vec<f64> = rows
            .iter()
            .filter(|f| f[0] == r[0] && f[1] == r[1])
            .map(|f| value(f, "relmse"))
            .collect();
        let mean = relmse.iter().sum::<f64>() / 4.0;
        assert!((sv(r, "mean_relmse") - mean).abs() <= 1e-12 * mean, "{r:?}");
        assert_eq!(sv(r, "last_relmse"), relmse[3]);
        assert!(sv(r, "temporal_error") > 0.0 && sv(r, "temporal_relmse") > 0.0);
        assert!(sv(r, "ms_per_frame") > 0.0);
        // Both scenes are all diffuse: no pixel to measure the specular flicker over.
        assert_eq!(r[col(&shead, "temporal_error_specular")], "", "{r:?}");
        // The lag: only where there is an event, and as rt-metrics computes it from the
        // per-frame errors (steady state over the two frames before frame 12).
        let lag = &r[col(&shead, "lag")];
        if r[0] == "still" {
            let l = rt_metrics::temporal::lag(
                &relmse,
                2,
                &rt_metrics::temporal::LagOptions {
                    factor: 2.0,
                    window: 2,
                },
            )
            .unwrap();
            assert_eq!(*lag, l.frames.map(|f| f.to_string()).unwrap_or_default());
        } else {
            assert_eq!(lag, "");
        }
    }
    // The interior does not move and every frame's reference has the same seed: its
    // references are the same image, so they do not change at all; the animated scene's do.
    assert_eq!(sv(&seq("still", "noisy"), "reference_temporal_error"), 0.0);
    assert!(sv(&seq("anim", "noisy"), "reference_temporal_error") > 0.0);
    // At 1 spp a noisy sequence flickers; SVGF's accumulated history does much less.
    for scene in ["anim", "still"] {
        let (noisy, svgf) = (seq(scene, "noisy"), seq(scene, "svgf"));
        assert!(
            sv(&svgf, "temporal_error") < 0.5 * sv(&noisy, "temporal_error"),
            "{scene}: {svgf:?} {noisy:?}"
        );
    }

    // Reports: a table per scene, a plot per scene, the stills.
    let md = std::fs::read_to_string(&outcome.report).unwrap();
    for needle in [
        "## anim",
        "## still",
        "temporal relMSE",
        "plots/still-frames.png",
        "images/still/atrous-f0013.png",
        "event at frame 12",
    ] {
        assert!(md.contains(needle), "{needle} not in\n{md}");
    }
    assert!(out.join("plots/anim-frames.svg").exists());
    let html = std::fs::read_to_string(&outcome.html).unwrap();
    assert!(html.contains("images/anim/svgf-f0003.png"));

    // A second run takes every reference from the cache.
    let out2 = dir.path().join("out2");
    prepare_out(&out2).unwrap();
    let again = run(&plan, &out2, &cache, &Silent).unwrap();
    let origins = &again.sequences.as_ref().unwrap().reference_origins;
    assert!(
        origins[1].contains("0 rendered, 4 from the cache"),
        "{origins:?}"
    );
    // Same seeds: the same numbers.
    assert_eq!(
        std::fs::read_to_string(out.join("frames.csv"))
            .unwrap()
            .lines()
            .map(|l| l.split(',').take(6).collect::<Vec<_>>().join(","))
            .collect::<Vec<_>>(),
        std::fs::read_to_string(out2.join("frames.csv"))
            .unwrap()
            .lines()
            .map(|l| l.split(',').take(6).collect::<Vec<_>>().join(","))
            .collect::<Vec<_>>()
    );
}
