//! Point, spot and directional lights against their closed forms: a Lambertian plane of
//! albedo ρ under a light reflects `ρ/π · I cosθ / r²` (point), that times the spot's falloff,
//! and `ρ/π · E cosθ` (directional). With one delta light and nothing else the path tracer's
//! estimate of one camera ray is deterministic (the light is always chosen, its connection is
//! exact), so the tolerance is rounding; with several lights chosen by power it is a mean
//! whose tolerance comes from the estimator's variance (every sample is one light's
//! contribution over its probability).
//!
//! Controls: each check also computes what a renderer missing the cosine, the `1/r²` or the
//! falloff would give at the same points and asserts those differ from the measurement by
//! far more than the tolerance, so the points can see such a bias.

use rt_core::delta_light::DeltaLight;
use rt_core::glam::Vec3;
use rt_core::{Ray, Rgb, Sampler, Scene};
use rt_integrators::{Integrator, PathIntegrator, RayCounters, SampleAux};
use rt_testkit::scene_from_toml;
use rt_testkit::Renderer;
use std::f32::consts::PI;

const ALBEDO: f32 = 0.5;

/// A 40 × 40 white floor at y = 0 of albedo 0.5 and the lights in `lights` (TOML tables).
fn floor(lights: &str) -> Scene {
    scene_from_toml(&format!(
        r#"
[[camera]]
name = "cam"
position = [0, 5, 5]
look_at = [0, 0, 0]
resolution = [8, 8]

[[material]]
name = "white"
color = [{ALBEDO}, {ALBEDO}, {ALBEDO}]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-20, 0, 20], [20, 0, 20], [20, 0, -20], [-20, 0, -20]]
material = "white"
{lights}
"#
    ))
}

/// The path tracer's radiance along a ray straight down onto floor point `(x, 0, z)`, the
/// mean of `n` samples.
fn radiance_at(scene: &Scene, integrator: &dyn Integrator, x: f32, z: f32, n: u32) -> Rgb {
    let r = Renderer::new(scene);
    let ctx = r.ctx();
    let ray = Ray::new(Vec3::new(x, 1.0, z), -Vec3::Y);
    let mut sum = Rgb::ZERO;
    let mut sampler = Sampler::new(7);
    for i in 0..n {
        sampler.start(0, 0, i);
        sum += integrator.li(
            &ctx,
            ray,
            &mut sampler,
            &mut SampleAux::default(),
            &mut RayCounters::default(),
        );
    }
    sum / n as f32
}

/// Asserts `got ≈ want` within relative `tol` (every channel), and that each of the
/// `biased` predictions is off by more than ten times the tolerance.
fn assert_matches(what: &str, got: f32, want: f32, tol: f32, biased: &[(&str, f32)]) {
    assert!(
        (got - want).abs() <= tol * want.abs().max(1e-6),
        "{what}: rendered {got}, expected {want}"
    );
    for (name, b) in biased {
        assert!(
            (got - b).abs() > 10.0 * tol * want.abs().max(1e-6),
            "{what}: the control `{name}` ({b}) is as close to {got} as the truth ({want})"
        );
    }
}

#[test]
fn a_point_light_over_a_lambertian_floor_gives_rho_over_pi_i_cos_over_r2() {
    let (h, intensity) = (2.0f32, 30.0f32);
    let scene = floor(&format!(
        "[[light]]\ntype = \"point\"\nposition = [0, {h}, 0]\nintensity = [{intensity}, {intensity}, {intensity}]"
    ));
    for integrator in [PathIntegrator::direct(), PathIntegrator::new(8)] {
        for x in [0.0f32, 1.0, 3.0] {
            let got = radiance_at(&scene, &integrator, x, 0.5, 4).x;
            let r2 = x * x + 0.25 + h * h;
            let cos = h / r2.sqrt();
            let want = ALBEDO / PI * intensity * cos / r2;
            let biased = [
                ("no cosine", ALBEDO / PI * intensity / r2),
                ("no 1/r²", ALBEDO / PI * intensity * cos),
                ("no 1/π", ALBEDO * intensity * cos / r2),
            ];
            // Off-centre points only: at x = 0 the cosine is near 1 and cannot be seen.
            let biased = if x == 0.0 { &biased[1..] } else { &biased[..] };
            assert_matches(&format!("point, x = {x}"), got, want, 1e-4, biased);
        }
    }
}

#[test]
fn a_spot_light_falls_off_linearly_between_beam_width_and_cutoff() {
    let h = 2.0f32;
    let scene = floor(&format!(
        "[[light]]\ntype = \"spot\"\nposition = [0, {h}, 0]\ndirection = [0, -1, 0]\nintensity = [10, 10, 10]\ncutoff_angle = 40\nbeam_width = 20"
    ));
    let integrator = PathIntegrator::direct();
    // Angles from the axis: in the beam, a quarter and three quarters down the ramp, outside.
    for (deg, falloff) in [(10.0f32, 1.0f32), (25.0, 0.75), (35.0, 0.25), (45.0, 0.0)] {
        let x = h * deg.to_radians().tan();
        let got = radiance_at(&scene, &integrator, x, 0.0, 2).x;
        let r2 = x * x + h * h;
        let cos = h / r2.sqrt();
        let want = ALBEDO / PI * 10.0 * falloff * cos / r2;
        let smooth = ((deg.to_radians().cos() - 40f32.to_radians().cos())
            / (20f32.to_radians().cos() - 40f32.to_radians().cos()))
        .clamp(0.0, 1.0);
        let biased = [
            ("no falloff", ALBEDO / PI * 10.0 * cos / r2),
            (
                "falloff linear in cosθ",
                ALBEDO / PI * 10.0 * smooth * cos / r2,
            ),
        ];
        let ramp = falloff > 0.0 && falloff < 1.0;
        let biased: &[(&str, f32)] = if ramp { &biased } else { &[] };
        if falloff == 0.0 {
            assert_eq!(got, 0.0, "outside the cone at {deg}°");
        } else {
            assert_matches(&format!("spot at {deg}°"), got, want, 1e-4, biased);
        }
    }
}

#[test]
fn a_directional_light_gives_rho_over_pi_e_cos() {
    let a = 50f32.to_radians();
    let scene = floor(&format!(
        "[[light]]\ntype = \"directional\"\ndirection = [{}, {}, 0]\nirradiance = [2, 3, 4]",
        a.sin(),
        -a.cos()
    ));
    let got = radiance_at(&scene, &PathIntegrator::new(4), 1.0, -2.0, 2);
    for (k, e) in [2.0f32, 3.0, 4.0].into_iter().enumerate() {
        let want = ALBEDO / PI * e * a.cos();
        let biased = [
            ("no cosine", ALBEDO / PI * e),
            ("no 1/π", ALBEDO * e * a.cos()),
        ];
        assert_matches(
            &format!("directional channel {k}"),
            got[k],
            want,
            1e-4,
            &biased,
        );
    }
}

/// Two point lights and a directional one, chosen by power: the mean of N samples is the
/// sum of the three closed forms within 4 standard deviations of the estimator, whose
/// variance is `Σ cᵢ²/pᵢ − (Σ cᵢ)²` for contributions `cᵢ` chosen with probability `pᵢ`.
#[test]
fn lights_chosen_by_power_sum_to_the_closed_forms() {
    let scene = floor(
        "[[light]]\ntype = \"point\"\nposition = [1, 2, 0]\nintensity = [40, 40, 40]\n\
         [[light]]\ntype = \"point\"\nposition = [-2, 1, 1]\nintensity = [5, 5, 5]\n\
         [[light]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [3, 3, 3]",
    );
    let p = Vec3::new(0.5, 0.0, 0.25);
    let point = |pos: Vec3, i: f32| {
        let d = pos - p;
        ALBEDO / PI * i * (d.y / d.length()) / d.length_squared()
    };
    let c = [
        point(Vec3::new(1.0, 2.0, 0.0), 40.0),
        point(Vec3::new(-2.0, 1.0, 1.0), 5.0),
        ALBEDO / PI * 3.0,
    ];
    // Selection probabilities as the sampler weighs power: 4I for a point light, E·R² for
    // a directional one (R the radius of the floor's bounding sphere).
    let bounds_r2 = (40.0f32 * 40.0 + 40.0 * 40.0) / 4.0;
    let w = [4.0 * 40.0, 4.0 * 5.0, 3.0 * bounds_r2];
    let total: f32 = w.iter().sum();
    let pr = w.map(|x| x / total);
    let mean: f64 = c.iter().map(|&x| x as f64).sum();
    let var: f64 = c
        .iter()
        .zip(&pr)
        .map(|(&c, &p)| (c as f64).powi(2) / p as f64)
        .sum::<f64>()
        - mean * mean;
    let n = 20_000;
    let got = radiance_at(&scene, &PathIntegrator::direct(), p.x, p.z, n).x as f64;
    let tol = 4.0 * (var / n as f64).sqrt();
    assert!(
        (got - mean).abs() < tol,
        "mean of {n} samples {got}, expected {mean} ± {tol}"
    );
    // Controls, at twice the tolerance: ignoring the choice's probability, or a sampler
    // that never chooses the directional light.
    let without_pmf: f64 = c.iter().zip(&pr).map(|(&c, &p)| (c * p) as f64).sum();
    let no_directional = mean - c[2] as f64;
    for (name, b) in [
        ("no 1/pmf", without_pmf),
        ("no directional", no_directional),
    ] {
        assert!(
            (b - mean).abs() > 2.0 * tol,
            "control {name}: {b} vs {mean} ± {tol}"
        );
    }
}

#[test]
fn delta_lights_reach_the_light_tracer_and_the_content_hash() {
    // The light tracer starts particles from point lights: its image of the lit floor is not
    // black (its agreement with the path tracer is tests/light_tracing.rs's business).
    let scene =
        floor("[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = [30, 30, 30]");
    let r = Renderer::new(&scene).threads(2);
    let t = rt_integrators::LightTracer::new(2);
    let buffers = rt_film::FilmBuffers::for_outputs(rt_film::AovSet::default());
    let mut film = r.film(buffers);
    let pass = rt_integrators::SamplePass {
        indices: 0..2,
        stream: rt_core::SampleStream::Render,
        pixels: None,
        centre_first: false,
    };
    r.technique_pass(&t, &mut film, 1, &pass);
    let sum: f32 = film.mean_image().iter().map(|c| c.x).sum();
    assert!(sum > 0.0 && sum.is_finite(), "{sum}");
    // A light is part of what the scene renders as.
    let digest = |s: &Scene| {
        let mut b = Vec::new();
        rt_core::ContentHash::content_hash(s, &mut |x: &[u8]| b.extend_from_slice(x));
        b
    };
    let mut moved = scene.clone();
    if let Some(DeltaLight::Point { position, .. }) = moved.delta_lights.first_mut() {
        position.y += 1e-3;
    }
    assert_ne!(digest(&scene), digest(&moved));
}
