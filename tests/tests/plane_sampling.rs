//! Plane sampling of environment light paths (Dammertz 2011, §6.4.2; digest claim 15): a
//! Lambertian square of albedo ρ under a constant environment of radiance L, seen from above
//! by a camera whose view the square fills, is ρ·L in every pixel for the light tracer, whose
//! particles all start from the environment by plane sampling. The tolerance is the z-test's,
//! with the light tracer's variance from the spread of independent runs.
//!
//! Claim 16 (hit fraction = projected area / rectangle area, tighter than the bounding disk)
//! is the second test; a rectangle sampled 10 % narrower than its reported area fails it.
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
        runs: None,
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

/// Claim 16: the fraction of plane-sampled particles that hit the scene is its projected area
/// over the rectangle's, and that rectangle (the projected box) is tighter than the bounding
/// sphere's disk that pbrt, Mitsuba and LuxCore draw from. For an axis-aligned box the
/// projected area along `d` is `Σᵢ |dᵢ| Aᵢ` (one face area per axis). Tolerance: 4.5 binomial
/// standard deviations per direction, over 24 directions.
#[test]
fn hit_fraction_is_projected_area_over_the_rectangle() {
    use rt_core::emission::{plane_area, plane_sample};
    use rt_core::glam::Vec3;
    let scene = scene_from_toml(
        r#"
[[camera]]
name = "c"
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[[material]]
name = "m"
color = [0.5, 0.5, 0.5]

[[geometry]]
name = "slab"
shape = "box"
min = [-2.0, -0.5, -1.0]
max = [2.0, 0.5, 1.0]
material = "m"
"#,
    );
    let accel = rt_accel::AccelSpec::new(rt_accel::AccelKind::Bvh8)
        .build(&scene.triangles)
        .expect("the default structure builds");
    let bounds = accel.bounds();
    let size = bounds.extent();
    let faces = Vec3::new(size.y * size.z, size.x * size.z, size.x * size.y);
    let mut rng = rt_core::rng::SplitMix64::new(16);
    let n = 20_000;
    let (mut ours, mut disk) = (0.0, 0.0);
    for _ in 0..24 {
        let d = rt_core::sampling::uniform_sphere(rng.vec2());
        let projected = f64::from(d.abs().dot(faces));
        let area = f64::from(plane_area(&bounds, d));
        let predicted = projected / area;
        let hits = (0..n)
            .filter(|_| {
                let (o, _) = plane_sample(&bounds, d, rng.vec2()).unwrap();
                accel
                    .intersect(&rt_core::ray::Ray::new(o, d), f32::INFINITY)
                    .is_some()
            })
            .count();
        let got = hits as f64 / n as f64;
        let sigma = (predicted * (1.0 - predicted) / n as f64).sqrt();
        assert!(
            (got - predicted).abs() < 4.5 * sigma + 1e-4,
            "along {d}: hit fraction {got}, predicted {predicted} (σ {sigma})"
        );
        ours += got;
        let r = f64::from(size.length()) / 2.0;
        disk += projected / (std::f64::consts::PI * r * r);
    }
    eprintln!(
        "mean hit fraction: projected box {:.3}, bounding disk {:.3}",
        ours / 24.0,
        disk / 24.0
    );
    assert!(
        ours > 1.3 * disk,
        "the rectangle is not tighter than the disk"
    );
}
