//! On-demand spectral dispersion end to end (Dammertz 2011, §6.6; digest §1.11, claim 24),
//! through the hidden `spectral` switch of the path and light tracers (off: dispersive glass
//! refracts with its `n_d`, as if the renderer had no spectral code):
//!
//! - Scenes without dispersive materials (glass included) render bit-identically with the
//!   switch on and off, for the path and the light tracer. Control: on the prism the switch
//!   changes the image.
//! - White light keeps its mean colour through dispersive glass: two parallel slabs of dense
//!   flint in a white furnace (a uniform environment of radiance L, lossless glass), seen by
//!   the camera, are L in every pixel and channel. Each path carries one wavelength and its
//!   RGB weight, so the spectral image is noisy colour; its mean is tested against L by the
//!   block z-test with the film's per-pixel variance.
//! - A dispersive scene (the prism, both cameras) renders bit-identically on 1 and 4 threads.

use rt_film::{AovSet, FilmBuffers};
use rt_integrators::{LightTracer, PathIntegrator};
use rt_testkit::stats::{compare_estimates, Estimate, ALPHA};
use rt_testkit::{scene_from_toml, shipped_scene, Renderer, SceneExt};

fn path(spectral: bool) -> PathIntegrator {
    let mut p = PathIntegrator::new(8);
    p.spectral = spectral;
    p
}

fn light(spectral: bool) -> LightTracer {
    let mut l = LightTracer::new(6);
    l.spectral = spectral;
    l
}

fn path_image(scene: &rt_core::Scene, spectral: bool, threads: usize) -> Vec<rt_core::Rgb> {
    Renderer::new(scene)
        .threads(threads)
        .render(&path(spectral), AovSet::default(), 8, 11)
        .0
        .mean_image()
}

fn light_image(scene: &rt_core::Scene, spectral: bool, threads: usize) -> Vec<rt_core::Rgb> {
    Renderer::new(scene)
        .threads(threads)
        .render_technique(&light(spectral), AovSet::default(), 8, 11)
        .0
        .mean_image()
}

fn lit(image: &[rt_core::Rgb]) -> bool {
    image.iter().any(|p| p.max_element() > 0.0)
}

/// Some pixel whose channels differ by more than 10 %: coloured light.
fn coloured(image: &[rt_core::Rgb]) -> bool {
    image
        .iter()
        .any(|p| p.max_element() > 0.0 && p.min_element() < 0.9 * p.max_element())
}

#[test]
fn scenes_without_dispersion_are_bit_identical_with_spectral_on_and_off() {
    // A glass sphere under an environment map with a sun; a Cornell box.
    for name in ["environment.toml", "cornell-box.toml"] {
        let scene = shipped_scene(name).with_resolution(24, 16);
        assert!(
            scene
                .materials
                .iter()
                .all(|m| m.layers.iter().all(|l| l.dispersion.is_none())),
            "{name} has a dispersive material"
        );
        let on = path_image(&scene, true, 2);
        assert!(lit(&on), "{name}: black");
        assert_eq!(on, path_image(&scene, false, 2), "{name}: path tracer");
        let on = light_image(&scene, true, 2);
        assert!(lit(&on), "{name}: black (light)");
        assert_eq!(on, light_image(&scene, false, 2), "{name}: light tracer");
    }
    // Control: where there is dispersion the switch changes the image.
    let prism = shipped_scene("prism.toml").with_resolution(64, 32);
    let on = light_image(&prism, true, 2);
    assert!(coloured(&on), "the prism casts no spectrum");
    assert_ne!(on, light_image(&prism, false, 2), "prism, light tracer");
}

const L: f32 = 0.5;
const SIZE: u32 = 16;

/// Two parallel slabs of dense flint (N-SF11) in a white furnace, filling the view.
fn slabs() -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"
[environment]
color = [{L}, {L}, {L}]

[[camera]]
name = "top"
position = [0.3, 0.2, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 20.0
resolution = [{SIZE}, {SIZE}]

[[material]]
name = "flint"
type = "glass"
color = [1.0, 1.0, 1.0]
dispersion = "sf11"

[[geometry]]
name = "upper"
shape = "box"
min = [-1.5, -1.5, 0.2]
max = [1.5, 1.5, 0.5]
material = "flint"

[[geometry]]
name = "lower"
shape = "box"
min = [-1.5, -1.5, -0.5]
max = [1.5, 1.5, -0.2]
material = "flint"
"#
    ))
}

#[test]
fn white_light_through_dispersive_slabs_keeps_its_mean_colour() {
    let scene = slabs();
    let n = (SIZE * SIZE) as usize;
    let render_scene = |scene: &rt_core::Scene, spectral: bool, spp| {
        let mut p = PathIntegrator::new(64);
        p.spectral = spectral;
        // No Russian roulette: inside glass the throughput is 1/n², which roulette would turn
        // into rare samples of weight n² (unbiased, but no longer L in every sample).
        p.rr_depth = u32::MAX;
        let film = Renderer::new(scene)
            .threads(2)
            .render(
                &p,
                FilmBuffers::from(AovSet::default()).with_variance(),
                spp,
                5,
            )
            .0;
        Estimate {
            mean: film.mean_image(),
            variance: film.variance_image().expect("kept"),
            runs: None,
        }
    };
    let render = |spectral: bool, spp| render_scene(&scene, spectral, spp);
    // Without the spectral code every path leaves lossless glass into the environment with
    // weight 1 (the 1/n² of entering cancels the n² of leaving): L up to rounding.
    let rgb = render(false, 8);
    for p in &rgb.mean {
        assert!(
            (*p - rt_core::Rgb::splat(L)).abs().max_element() < 1e-4,
            "{p}"
        );
    }
    let spectral = render(true, 512);
    // Every sample is L times one wavelength's weight: noisy colour, whose spread the
    // variance buffer shows (the RGB render has none).
    let spread = |e: &Estimate| {
        e.variance
            .iter()
            .map(|v| v.max_element())
            .fold(0.0, f32::max)
    };
    assert!(spread(&rgb) < 1e-10, "RGB render varies: {}", spread(&rgb));
    assert!(
        spread(&spectral) > 1e-5,
        "no dispersion: {}",
        spread(&spectral)
    );
    let exact = Estimate {
        mean: vec![rt_core::Rgb::splat(L); n],
        variance: vec![rt_core::Rgb::ZERO; n],
        runs: None,
    };
    let c = compare_estimates(&spectral, &exact, SIZE, 4, ALPHA);
    let mean = spectral.mean.iter().copied().sum::<rt_core::Rgb>() / n as f32;
    eprintln!("spectral mean {mean} (L = {L}): {c:?}");
    assert!(c.same_within_noise(), "white is not white: {c:?}");
    // Control: glass that keeps 1 % less blue at each interface (what a wavelength weight
    // 1 % low in blue does to the paths that cross it) must fail the same test.
    let mut tinted = slabs();
    for l in &mut tinted.materials[0].layers {
        l.color = rt_core::Rgb::new(1.0, 1.0, 0.99);
        l.color90 = l.color;
    }
    let c = compare_estimates(&render_scene(&tinted, true, 512), &exact, SIZE, 4, ALPHA);
    eprintln!("control, 1 % less blue per interface: {c:?}");
    assert!(!c.same_within_noise(), "control: a blue tint passes: {c:?}");
}

#[test]
fn dispersive_scene_is_deterministic_across_threads() {
    let prism = shipped_scene("prism.toml").with_resolution(64, 32);
    let one = light_image(&prism, true, 1);
    assert!(coloured(&one), "the prism casts no spectrum");
    assert_eq!(one, light_image(&prism, true, 4), "light tracer, wall");
    let mut scope = shipped_scene("prism.toml");
    scope.cameras.swap(0, 1);
    let scope = scope.with_resolution(64, 32);
    let one = path_image(&scope, true, 1);
    assert!(coloured(&one), "the spectroscope sees no spectrum");
    assert_eq!(
        one,
        path_image(&scope, true, 4),
        "path tracer, spectroscope"
    );
}
