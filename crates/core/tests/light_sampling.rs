//! χ² goodness of fit of the light samplers against their own pdfs (`rt_testkit::chi2`):
//! emitter area sampling (`LightSampler::sample` against `LightSampler::pdf_triangle`, summed
//! over the emitters a direction meets) and environment-map importance sampling
//! (`Environment::sample` against `Environment::pdf`). Both pdfs are the ones next-event
//! estimation divides by and MIS weighs with, so a sampler that disagrees with its pdf biases
//! every lit image. The samples are independent (`rt_testkit::Rng`): the renderer's stratified
//! samples would make the statistic too small and the test too lenient.

use rt_core::environment::{EnvMap, Environment};
use rt_core::glam::Vec3;
use rt_core::triangle::{geometric_normal, intersect_triangle, RayPrecomp};
use rt_core::{Material, Ray, Rgb, Scene};
use rt_testkit::chi2;
use rt_testkit::Rng;

/// Family-wise false-alarm rate of this file's tests (Šidák-corrected over them).
const FAMILY_ALPHA: f64 = 0.01;
/// Tests in this file.
const TESTS: usize = 2;
/// Samples per test.
const N: usize = 400_000;

/// Draws `N` directions with `sample` and judges them against `pdf`, integrated over each bin
/// on a `sub × sub` grid, at the corrected level.
fn check(
    what: &str,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
    sub: usize,
) {
    let mut rng = Rng::new(0x11e5);
    let expected = chi2::expected(pdf, sub);
    let mut observed = vec![0.0; expected.len()];
    for _ in 0..N {
        if let Some(d) = sample(&mut rng) {
            observed[chi2::bin_of(d)] += 1.0;
        }
    }
    let total: f64 = expected.iter().sum();
    let r = chi2::test(&observed, &expected, N);
    let alpha = chi2::sidak(FAMILY_ALPHA, TESTS);
    eprintln!("{what}: {r:?}, integrated pdf {total:.4}, alpha {alpha:.2e}");
    assert!(
        r.passes(alpha),
        "{what}: sampled directions do not follow the pdf: {r:?} (α {alpha:.2e})"
    );
}

/// Three two-sided emitters of different sizes, powers, distances and orientations around the
/// origin, which is the shading point.
fn emitters() -> Scene {
    let mut scene = Scene::empty();
    for (i, e) in [1.0f32, 5.0, 2.0].into_iter().enumerate() {
        let mut m = Material::diffuse(&format!("light{i}"), Rgb::splat(0.5));
        m.emission = Rgb::splat(e);
        m.two_sided = true;
        scene.materials.push(m);
    }
    let tris = [
        (
            [
                Vec3::new(-1.0, -0.5, 2.0),
                Vec3::new(1.5, -0.5, 2.0),
                Vec3::new(0.0, 1.5, 2.5),
            ],
            0,
        ),
        (
            [
                Vec3::new(-1.5, 0.3, -1.0),
                Vec3::new(-1.2, 0.9, -1.2),
                Vec3::new(-1.8, 0.6, -0.6),
            ],
            1,
        ),
        (
            [
                Vec3::new(0.5, -3.0, 0.5),
                Vec3::new(2.5, -3.5, 0.0),
                Vec3::new(0.8, -3.2, -2.0),
            ],
            2,
        ),
    ];
    for (v, m) in tris {
        scene.push_triangle(v, m);
    }
    scene.build_lights();
    scene
}

#[test]
fn emitter_area_sampling_matches_its_pdf_chi_square() {
    let scene = emitters();
    let x = Vec3::ZERO;
    let lights = scene.lights();
    let pdf = |d: Vec3| {
        let pre = RayPrecomp::new(&Ray::new(x, d));
        (0..scene.triangles.len())
            .filter_map(|prim| {
                let v = &scene.triangles[prim];
                let hit = intersect_triangle(&pre, v, f32::INFINITY)?;
                let ng = geometric_normal(v).normalize();
                Some(lights.pdf_triangle(&scene, prim as u32, x, x + d * hit.t, ng) as f64)
            })
            .sum()
    };
    check(
        "emitters",
        |rng| Some(lights.sample(&scene, x, rng.f32(), rng.vec2())?.wi),
        pdf,
        // The pdf jumps at the triangles' edges: a fine grid, so that the bins cut by an edge
        // (and the corners that fall between grid points) are integrated well enough.
        32,
    );
}

/// The equirectangular map of `estimators_agree.rs`: a smooth sky with a broad bright patch,
/// plus a dark band, so the importance map is far from uniform.
fn sky() -> Environment {
    let (w, h) = (64u32, 32u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let patch = (-((x - 0.5).powi(2) + (y - 0.3).powi(2)) / 0.01).exp() * 8.0;
            let band = if (0.6..0.7).contains(&y) { 0.05 } else { 1.0 };
            Rgb::new(
                0.4 + patch,
                0.5 + 0.8 * patch,
                0.7 * (1.0 - y) + 0.5 * patch,
            ) * band
        })
        .collect();
    Environment::Map(EnvMap::new(w, h, texels))
}

#[test]
fn environment_map_sampling_matches_its_pdf_chi_square() {
    let env = sky();
    check(
        "environment map",
        |rng| Some(env.sample(rng.vec2())?.dir),
        |d| env.pdf(d) as f64,
        8,
    );
    // The pdf is a density over the sphere.
    let total: f64 = chi2::expected(|d| env.pdf(d) as f64, 4).iter().sum();
    assert!(
        (total - 1.0).abs() < 1e-2,
        "environment pdf integrates to {total}"
    );
}
