//! A material animation switches a lamp: a frame while it is on is the static scene with the
//! lamp lit, a frame while it is off the static scene without it (path traced with independent
//! seeds, compared by the block z-test), and the two differ. A frame in which nothing emits
//! renders black with every technique, without a panic: switching the only lamp off must leave
//! the light sampler valid (an empty table, rebuilt by `Scene::set_time`). Control: the on
//! frame against the off reference must fail the z-test.

use rt_film::FilmBuffers;
use rt_integrators::{IntegratorSpec, PathIntegrator};
use rt_testkit::stats::{compare, image_mean, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

use rt_testkit::scenes::LIT_FLOOR as COMMON;

/// A dim second lamp beside the main one, so the scene is lit while the main lamp is off.
const DIM_LAMP: &str = r#"
[[material]]
name = "dim"
emission = [1.5, 1.5, 1.5]

[[geometry]]
name = "dim-light"
shape = "quad"
vertices = [[1.0, 2.0, -1.5], [2.0, 2.0, -1.5], [2.0, 2.0, -0.5], [1.0, 2.0, -0.5]]
material = "dim"
"#;

/// The main lamp (LIT_FLOOR's `lamp`, emission 6) off from t = 1 to t = 2.
const TOGGLE: &str = r#"
[[animation]]
target = "lamp"
interpolate = "step"
keys = [ { time = 0.0, emission = [6, 6, 6] }, { time = 1.0, emission = [0, 0, 0] },
         { time = 2.0, emission = [6, 6, 6] } ]
"#;

/// A box on the floor so that the image has shadows and indirect light.
const BOX: &str = r#"
[[geometry]]
name = "box"
shape = "box"
min = [-0.4, 0, -0.4]
max = [0.4, 0.7, 0.4]
material = "red"
"#;

fn render(scene: &rt_core::Scene, seed: u32) -> rt_film::Film {
    Renderer::new(scene)
        .threads(2)
        .render(
            &PathIntegrator::new(4),
            FilmBuffers::from(rt_film::AovSet::default()).with_variance(),
            64,
            seed,
        )
        .0
}

#[test]
fn a_toggled_lamp_renders_as_the_static_scene_with_it_on_or_off() {
    let mut anim = scene_from_toml(&format!("{COMMON}{DIM_LAMP}{BOX}{TOGGLE}"));
    let lit = scene_from_toml(&format!("{COMMON}{DIM_LAMP}{BOX}"));
    let dark = scene_from_toml(&format!(
        "{}{DIM_LAMP}{BOX}",
        COMMON.replace("emission = [6, 6, 6]", "emission = [0, 0, 0]")
    ));
    let (lit_ref, dark_ref) = (render(&lit, 1), render(&dark, 2));

    // Before the switch, after it, and after switching back on (the light table is rebuilt
    // each time: the frames follow one another on one scene, as a sequence renders them).
    for (t, reference, seed) in [
        (0.5, &lit_ref, 3),
        (1.0, &dark_ref, 4),
        (1.5, &dark_ref, 5),
        (2.5, &lit_ref, 6),
    ] {
        anim.set_time(t);
        let c = compare(&render(&anim, seed), reference, 4, ALPHA);
        assert!(c.same_within_noise(), "t = {t}: {c:?}");
    }
    let control = compare(&lit_ref, &dark_ref, 4, ALPHA);
    assert!(!control.same_within_noise(), "control passes: {control:?}");
    // On is brighter than off, and off is not black (the dim lamp): by many standard errors.
    let ((on, on_se), (off, off_se)) = (image_mean(&lit_ref), image_mean(&dark_ref));
    let se = on_se.hypot(off_se);
    assert!(
        on - off > 10.0 * se && off > 10.0 * off_se,
        "on {on} ± {on_se}, off {off} ± {off_se}"
    );
}

#[test]
fn a_frame_without_a_lit_emitter_renders_black_with_every_technique() {
    let mut anim = scene_from_toml(&format!("{COMMON}{BOX}{TOGGLE}"));
    anim.set_time(0.0);
    assert!(!anim.lights().is_empty(), "the lamp is on at t = 0");
    anim.set_time(1.5);
    assert!(anim.lights().is_empty(), "the lamp is off at t = 1.5");
    for technique in [
        "path",
        "path-bsdf",
        "direct",
        "light",
        "bdpt",
        "partitioned:vpls=4:photons=200",
    ] {
        let spec: IntegratorSpec = technique.parse().unwrap();
        let integrator = spec.build();
        let film = Renderer::new(&anim)
            .threads(2)
            .render_technique(
                integrator.as_ref(),
                FilmBuffers::from(rt_film::AovSet::default()),
                4,
                7,
            )
            .0;
        let pixels = film.mean_image();
        assert!(
            pixels.iter().all(|p| *p == rt_core::Rgb::ZERO),
            "{technique}: a pixel is lit or not finite without any light"
        );
    }
}

#[test]
fn motion_blur_is_refused_while_a_keyed_emission_changes() {
    use rt_core::scene::MotionBlurError;
    let mut s = scene_from_toml(&format!("{COMMON}{TOGGLE}"));
    s.shutter = 0.1;
    // The shutter [0.95, 1.05] holds the switch at t = 1.
    s.set_time(0.95);
    assert_eq!(
        s.motion_blur_error(),
        Some(MotionBlurError::AnimatedEmission("lamp".into()))
    );
    let message = s.motion_blur_error().unwrap().to_string();
    assert!(
        message.contains("lamp") && !message.contains('\n'),
        "{message}"
    );
    // Opening at the switch or after it, the lamp stays as it is while the shutter is open.
    for t in [1.0, 1.2] {
        s.set_time(t);
        assert_eq!(s.motion_blur_error(), None, "t = {t}");
    }
    // A linear fade changes all the time between its keys.
    let mut fade = scene_from_toml(&format!(
        "{COMMON}{}",
        TOGGLE.replace("interpolate = \"step\"", "interpolate = \"linear\"")
    ));
    fade.shutter = 0.1;
    fade.set_time(1.2);
    assert!(fade.motion_blur_error().is_some());
    // Halfway between the keys at 1 (off) and 2 (6): 3, where the step holds 0.
    fade.set_time(1.5);
    s.set_time(1.5);
    let lamp = |s: &rt_core::Scene| {
        s.materials
            .iter()
            .find(|m| m.name == "lamp")
            .unwrap()
            .emission
    };
    assert_eq!(lamp(&fade), rt_core::Rgb::splat(3.0));
    assert_eq!(lamp(&s), rt_core::Rgb::ZERO);
}
