//! Plane sampling of environment light paths (Dammertz 2011, §6.4.2; digest claim 15): a
//! Lambertian square of albedo ρ under a constant environment of radiance L, seen from above
//! by a camera whose view the square fills, is ρ·L in every pixel for the light tracer, whose
//! particles all start from the environment by plane sampling. The tolerance is the z-test's,
//! with the light tracer's variance from the spread of independent runs.
//!
//! Control: the same with the scene box the particles' rectangle must cover reported at half
//! its size (`ShrunkBounds`), which leaves a margin of the view uncovered: caught.

use rt_film::AovSet;
use rt_integrators::LightTracer;
use rt_testkit::mutants::ShrunkBounds;
use rt_testkit::stats::{compare_estimates, Estimate, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

const ALBEDO: f32 = 0.5;
const L: f32 = 0.5;
const SIZE: u32 = 16;

fn scene() -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"
[environment]
color = [{L}, {L}, {L}]

[[camera]]
name = "top"
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 20.0
resolution = [{SIZE}, {SIZE}]

[[material]]
name = "m"
type = "diffuse"
color = [{ALBEDO}, {ALBEDO}, {ALBEDO}]

[[geometry]]
name = "square"
shape = "quad"
vertices = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]
material = "m"
"#
    ))
}

fn light_estimate(scene: &rt_core::Scene, scale: f32) -> Estimate {
    let renderer = Renderer::new(scene).threads(2);
    let shrunk = ShrunkBounds {
        inner: renderer.accel(),
        scale,
    };
    let renderer = Renderer::new(scene).with_accel(&shrunk).threads(2);
    let runs: Vec<_> = (0..8)
        .map(|seed| {
            let lt = LightTracer::new(4);
            renderer
                .render_technique(&lt, AovSet::default(), 512, seed)
                .0
                .mean_image()
        })
        .collect();
    Estimate::from_runs(&runs)
}

#[test]
fn plane_sampled_light_paths_give_albedo_times_radiance() {
    let scene = scene();
    let n = (SIZE * SIZE) as usize;
    let exact = Estimate {
        mean: vec![rt_core::Rgb::splat(ALBEDO * L); n],
        variance: vec![rt_core::Rgb::ZERO; n],
    };
    let honest = compare_estimates(&light_estimate(&scene, 1.0), &exact, SIZE, 4, ALPHA);
    let shrunk = compare_estimates(&light_estimate(&scene, 0.5), &exact, SIZE, 4, ALPHA);
    eprintln!("honest {honest:?}\nshrunk {shrunk:?}");
    assert!(honest.same_within_noise(), "not ρL: {honest:?}");
    assert!(
        !shrunk.same_within_noise(),
        "control: an uncovering rectangle passes: {shrunk:?}"
    );
}
