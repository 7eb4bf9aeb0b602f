//! White furnace: objects of albedo 1 under a constant environment of radiance L must render as
//! L everywhere for the energy-conserving presets (diffuse, mirror, glass), and never brighter
//! than L for any material (scene: `rt_testkit::furnace`). The lossy materials are also bounded
//! from below, by a one-bounce furnace: a plane seen through a narrow camera, rendered with one
//! bounce, is `L · A(wo)` where `A(wo) = ∫ f(wo, wi) |cos θi| dωi` is the directional albedo,
//! integrated here by quadrature from `Bsdf::eval` (not from the sampler the renderer uses). A
//! black or half-energy renderer fails it.

use rt_core::glam::Vec3;
use rt_core::material::Bsdf;
use rt_core::Rgb;
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::{PathIntegrator, Wavefront, DEFAULT_LANES};
use rt_testkit::furnace::{one_bounce_plane_toml, scene_toml as furnace, L};
use rt_testkit::stats::{image_mean, variance_of_mean};
use rt_testkit::{render, scene_from_toml, Renderer};

/// Checks the image mean against L with a tolerance of 4 standard errors (estimated from the
/// per-pixel variances), and every pixel against L with 6 of its own standard errors.
fn check(material: &str, equal: bool, integrator: &PathIntegrator, spp: u32) {
    let scene = scene_from_toml(&furnace(material));
    check_film(material, equal, &render(&scene, integrator, spp, 1));
}

/// [`check`] for the wavefront tracer with `integrator`'s settings.
fn check_wavefront(material: &str, equal: bool, integrator: &PathIntegrator, spp: u32) {
    let scene = scene_from_toml(&furnace(material));
    let wavefront = Wavefront::new(integrator.clone(), DEFAULT_LANES);
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_variance();
    let (film, _) = Renderer::new(&scene)
        .threads(2)
        .render_technique(&wavefront, buffers, spp, 1);
    check_film(material, equal, &film);
}

fn check_film(material: &str, equal: bool, film: &rt_film::Film) {
    let (mean, se) = image_mean(film);
    let tol = 4.0 * se + 1e-4;
    if equal {
        assert!(
            (mean - L as f64).abs() <= tol,
            "{material}: image mean {mean} vs {L} (tol {tol})"
        );
    } else {
        assert!(
            mean <= L as f64 + tol,
            "{material}: image mean {mean} brighter than {L} (tol {tol})"
        );
    }
    for (i, p) in film.pixels().enumerate() {
        let (m, v) = (p.mean(), variance_of_mean(&p));
        for c in 0..3 {
            let tol = 6.0 * v[c].sqrt() + 1e-4;
            let d = m[c] - L;
            if equal {
                assert!(
                    d.abs() <= tol,
                    "{material}: pixel {i} = {} vs {L} (tol {tol})",
                    m[c]
                );
            } else {
                assert!(
                    d <= tol,
                    "{material}: pixel {i} = {} brighter than {L} (tol {tol})",
                    m[c]
                );
            }
        }
    }
}

const ENERGY_CONSERVING: [&str; 3] = [
    r#"type = "diffuse"
color = [1.0, 1.0, 1.0]"#,
    r#"type = "mirror"
color = [1.0, 1.0, 1.0]"#,
    r#"type = "glass"
color = [1.0, 1.0, 1.0]"#,
];

const LOSSY: [&str; 6] = [
    r#"type = "glossy"
color = [1.0, 1.0, 1.0]
hardness = 0.5"#,
    r#"type = "metal"
color = [1.0, 1.0, 1.0]
hardness = 0.8"#,
    r#"type = "plastic"
color = [1.0, 1.0, 1.0]"#,
    r#"type = "glass"
color = [1.0, 1.0, 1.0]
hardness = 0.6"#,
    r#"type = "glass"
color = [1.0, 1.0, 1.0]
hardness = 0.05"#,
    r#"layers = [ { weight = 0.5, color = [1.0, 1.0, 1.0] }, { weight = 0.5, color = [1.0, 1.0, 1.0], hardness = 0.7 } ]"#,
];

#[test]
fn energy_conserving_presets_render_as_the_environment() {
    for m in ENERGY_CONSERVING {
        check(m, true, &PathIntegrator::new(1000), 64);
        check(m, true, &PathIntegrator::bsdf_only(1000), 64);
        check_wavefront(m, true, &PathIntegrator::new(1000), 64);
    }
}

/// `A(wo)` (the largest channel) by the midpoint rule on the (θ, φ) grid of
/// `rt_testkit::chi2` with `sub²` points per bin.
fn directional_albedo(bsdf: &Bsdf, sub: usize) -> f64 {
    let f = |d: Vec3| bsdf.eval(d).max_element() as f64 * d.z.abs() as f64;
    rt_testkit::chi2::expected(f, sub).iter().sum()
}

/// One-bounce furnace: the image mean must be `L · A(wo)` within four standard errors, plus the
/// change of `A` over the camera's ±0.5° and the quadrature's own error (the difference of two
/// grid resolutions).
#[test]
fn one_bounce_lossy_materials_reflect_their_directional_albedo() {
    for m in LOSSY {
        for theta_deg in [25.0f32, 65.0] {
            let scene = scene_from_toml(&one_bounce_plane_toml(m, theta_deg.to_radians()));
            let material = &scene.materials[0];
            assert!(
                material.layers.iter().all(|l| !l.is_delta()),
                "{m}: a delta lobe escapes the quadrature"
            );
            let albedo_at = |deg: f32, sub: usize| {
                let t = deg.to_radians();
                let wo = Vec3::new(t.sin(), 0.0, t.cos());
                directional_albedo(&Bsdf::new(material, Rgb::ONE, Vec3::Z, Vec3::Z, wo), sub)
            };
            let a = albedo_at(theta_deg, 8);
            let quadrature = (albedo_at(theta_deg, 16) - a).abs();
            let spread = [theta_deg - 0.5, theta_deg + 0.5]
                .map(|d| (albedo_at(d, 8) - a).abs())
                .into_iter()
                .fold(0.0, f64::max);
            let film = render(&scene, &PathIntegrator::new(1), 2048, 3);
            let (mean, se) = image_mean(&film);
            let expected = L as f64 * a;
            let tol = 4.0 * se + L as f64 * (spread + quadrature);
            assert!(
                (mean - expected).abs() <= tol,
                "{m} at {theta_deg}°: image mean {mean} vs L·A = {expected} (A {a:.4}, tol {tol:.2e})"
            );
            // The test must be able to tell a half-energy renderer from the right one.
            assert!(tol < 0.25 * expected, "{m}: tolerance {tol} too loose");
        }
    }
}

#[test]
fn no_material_is_brighter_than_the_environment() {
    for m in LOSSY {
        check(m, false, &PathIntegrator::new(1000), 32);
        check_wavefront(m, false, &PathIntegrator::new(1000), 32);
    }
}
