//! Every shipped scene (`scenes/*.toml`) loads and renders with every light-transport technique
//! (`path`, `light`, `bdpt`, `partitioned`), the way `render` and `render experiment` render it:
//! through `rt_session` with the scene's own `[render]` settings, at a tiny resolution and a
//! few samples. Each image must be finite everywhere and not all black. This catches a scene
//! that no longer loads, a light that went missing or faces the wrong way, and a technique that
//! cannot handle some scene (an environment map, the sky, a thin lens, dispersion).
//!
//! The camera that light reaches only through specular paths is exempt for the techniques that
//! cannot see it: the prism's default camera looks at a wall lit only through the prism (a
//! caustic), which the path tracer does not find in a few samples. It renders with the
//! prism's `spectroscope` camera instead, which the path tracer does see.
//!
//! Control: a scene whose only light is switched off renders black and must be caught, and a
//! broken scene file must fail to load.

use rt_core::SampleStream;
use rt_film::{Film, FilmBuffers};
use rt_integrators::{Ctx, IntegratorSpec};
use rt_session::{pick_camera, Budgets, ImageSize, Overrides, Session};
use rt_testkit::workspace_root;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Image size: enough pixels for a few to land on anything the camera sees.
const SIZE: (u32, u32) = (32, 24);
/// Samples per pixel (light paths per pixel for the splatting techniques).
const SPP: u32 = 8;

/// The techniques, with a bounce limit and (for `partitioned`) pass sizes made small: what is
/// tested is that each runs on each scene, not its speed or its noise.
const TECHNIQUES: [&str; 4] = [
    "path:max-depth=6",
    "light:max-depth=6",
    "bdpt:max-depth=6",
    "partitioned:max-depth=6:vpls=4:photons=2000",
];

/// Cameras other than the first, for the (scene, technique) pairs that cannot see anything
/// through the first at this sample count (see the module documentation).
fn camera_for(scene: &str, technique: &str) -> Option<&'static str> {
    (scene == "prism.toml" && technique.starts_with("path")).then_some("spectroscope")
}

/// The shipped scenes, sorted by name.
fn shipped_scenes() -> Vec<PathBuf> {
    let dir = workspace_root().join("scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    scenes
}

/// Renders the scene at `path` with `technique` through `camera` (the first if `None`), as
/// `render experiment` does; the error is one line naming the scene.
fn render(path: &Path, technique: &str, camera: Option<&str>) -> Result<Film, String> {
    let loaded = rt_scene::load(path).map_err(|e| e.to_string())?;
    let spec: IntegratorSpec = technique.parse().map_err(|e| format!("{technique}: {e}"))?;
    let overrides = Overrides {
        integrator: Some(spec),
        ..Overrides::default()
    };
    let settings = overrides
        .resolve(&loaded, path)
        .map_err(|e| e.to_string())?;
    let camera = ImageSize::Pixels(SIZE.0, SIZE.1)
        .apply(pick_camera(&loaded.scene, path, camera).map_err(|e| e.to_string())?);
    let accel = settings
        .accel
        .build(&loaded.scene)
        .expect("the structure builds over the scene");
    let integrator = settings.integrator.build();
    let session = Session {
        ctx: Ctx {
            scene: &loaded.scene,
            accel: accel.as_ref(),
            camera: &camera,
        },
        integrator: integrator.as_ref(),
        seed: settings.seed,
        stream: SampleStream::Render,
        buffers: FilmBuffers::default(),
    };
    session.render(&Budgets::Spp(vec![SPP]), &|_| {}, &mut |_, _| {
        Ok::<(), String>(())
    })
}

/// What is wrong with the image, if anything: a non-finite or negative pixel, or no light.
fn check(film: &Film) -> Result<(), String> {
    let pixels = film.mean_image();
    if let Some((i, p)) = pixels
        .iter()
        .enumerate()
        .find(|(_, p)| !p.is_finite() || p.min_element() < 0.0)
    {
        let w = film.width() as usize;
        return Err(format!("pixel ({}, {}) is {p}", i % w, i / w));
    }
    if !pixels.iter().any(|p| p.max_element() > 0.0) {
        return Err("the image is all black".to_string());
    }
    Ok(())
}

/// Renders and checks one pair; the error names the scene, the technique and the problem.
fn render_and_check(path: &Path, technique: &str) -> Result<(), String> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let camera = camera_for(&name, technique);
    let at = match camera {
        Some(c) => format!("{name} (camera {c}) with {technique}"),
        None => format!("{name} with {technique}"),
    };
    render(path, technique, camera)
        .and_then(|film| check(&film))
        .map_err(|e| format!("{at}: {e}"))
}

#[test]
fn every_shipped_scene_renders_with_every_technique() {
    let scenes = shipped_scenes();
    // The four scenes made for these techniques (issue 11) are among them,
    for name in [
        "penumbra.toml",
        "caustic.toml",
        "sun-caustic.toml",
        "interior.toml",
        // and issue 14's animated scenes.
        "hall-glossy.toml",
        "hall-mirror.toml",
        "light-toggle.toml",
        "dynamic-small.toml",
    ] {
        assert!(
            scenes.iter().any(|p| p.ends_with(name)),
            "scenes/{name} is missing"
        );
    }
    let mut failures = Vec::new();
    for path in &scenes {
        for technique in TECHNIQUES {
            let t = Instant::now();
            let result = render_and_check(path, technique);
            eprintln!(
                "{} {technique}: {:.2} s{}",
                path.file_name().unwrap_or_default().to_string_lossy(),
                t.elapsed().as_secs_f64(),
                result
                    .as_ref()
                    .err()
                    .map(|e| format!(": {e}"))
                    .unwrap_or_default()
            );
            if let Err(e) = result {
                failures.push(e);
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} renders failed:\n{}",
        failures.len(),
        scenes.len() * TECHNIQUES.len(),
        failures.join("\n")
    );
}

/// The checks catch what they are for: a scene without light gives a black image, and a scene
/// that does not load is an error naming the file.
#[test]
fn a_broken_scene_is_caught() {
    let dir = tempfile_dir();
    let penumbra = std::fs::read_to_string(workspace_root().join("scenes/penumbra.toml"))
        .expect("scenes/penumbra.toml");
    // The lamp switched off: the scene loads (with a warning) and renders black.
    let lamp = "emission = [6.0, 6.0, 6.0]";
    assert!(penumbra.contains(lamp), "the penumbra scene's lamp changed");
    let off = penumbra.replace(lamp, "emission = [0.0, 0.0, 0.0]");
    let dark = dir.join("dark.toml");
    std::fs::write(&dark, off).unwrap();
    for technique in TECHNIQUES {
        let e = render_and_check(&dark, technique)
            .err()
            .unwrap_or_else(|| panic!("{technique}: a black image passes"));
        assert!(e.contains("all black"), "{e}");
    }
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, penumbra.replace("radius = 0.5", "radius = -0.5")).unwrap();
    let e = render_and_check(&broken, TECHNIQUES[0]).expect_err("a broken scene loads");
    assert!(e.contains("broken.toml"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A fresh directory for this test's files (no tempfile dependency in this package).
fn tempfile_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rt-shipped-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
