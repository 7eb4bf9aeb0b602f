//! Next-event estimation with MIS and pure BSDF sampling estimate the same integral, so their
//! images must agree within noise. The judge is the stress suite's block z-test
//! (`rt_testkit::stats::compare`): on 4 × 4 pixel blocks and on the whole image, the summed
//! difference over the square root of the summed variances of the mean (both films), against
//! the normal quantile at a family-wise false-alarm rate of 10⁻³ split over all blocks and
//! channels; pixels whose samples were all equal (directly seen sky) keep a rounding-size
//! variance, so they count, and differ only by rounding.
//!
//! Control: the same comparison with next-event estimation weakened by 2 % (an acceleration
//! structure that reports 2 % of the shadow rays occluded, `rt_testkit::mutants`) must fail,
//! so the test can see a bias of that size.

use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{Integrator, PathIntegrator, Technique, Wavefront, DEFAULT_LANES};
use rt_testkit::mutants::DroppedShadowRays;
use rt_testkit::stats::{compare, Comparison, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

/// Side of the pixel blocks of the z-test.
const BLOCK: u32 = 4;
/// Fraction of shadow rays the control drops: NEE × 0.98.
const DROPPED: f64 = 0.02;

/// A closed room with a large ceiling light (so BSDF sampling alone converges in a test's time)
/// and one object of each kind of lobe; plus an environment through an opening.
const ROOM: &str = r#"
[environment]
color = [0.3, 0.4, 0.6]

[[camera]]
name = "c"
position = [0.0, 1.0, 3.4]
look_at = [0.0, 0.9, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0
resolution = [20, 20]

[[material]]
name = "white"
type = "diffuse"
color = [0.75, 0.75, 0.75]

[[material]]
name = "red"
type = "diffuse"
color = [0.7, 0.15, 0.1]

[[material]]
name = "glossy"
type = "glossy"
color = [0.8, 0.8, 0.6]
hardness = 0.4

[[material]]
name = "plastic"
type = "plastic"
color = [0.2, 0.5, 0.8]
hardness = 0.6

[[material]]
name = "frosted"
type = "glass"
color = [1.0, 1.0, 1.0]
hardness = 0.7

[[material]]
name = "light"
type = "diffuse"
color = [0.5, 0.5, 0.5]
emission = [4.0, 3.6, 3.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-1.5, 0.0, 1.5], [1.5, 0.0, 1.5], [1.5, 0.0, -1.5], [-1.5, 0.0, -1.5]]
material = "white"

[[geometry]]
name = "back"
shape = "quad"
vertices = [[-1.5, 0.0, -1.5], [1.5, 0.0, -1.5], [1.5, 2.0, -1.5], [-1.5, 2.0, -1.5]]
material = "white"

[[geometry]]
name = "left"
shape = "quad"
vertices = [[-1.5, 0.0, 1.5], [-1.5, 0.0, -1.5], [-1.5, 2.0, -1.5], [-1.5, 2.0, 1.5]]
material = "red"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.9, 1.99, -0.9], [0.9, 1.99, -0.9], [0.9, 1.99, 0.9], [-0.9, 1.99, 0.9]]
material = "light"

[[geometry]]
name = "ball"
shape = "sphere"
center = [-0.55, 0.4, -0.3]
radius = 0.4
subdivisions = 2
material = "glossy"

[[geometry]]
name = "block"
shape = "box"
min = [0.2, 0.0, -0.8]
max = [0.9, 0.9, -0.1]
material = "plastic"

[[geometry]]
name = "glass"
shape = "sphere"
center = [0.2, 0.3, 0.6]
radius = 0.3
subdivisions = 2
material = "frosted"
"#;

/// Renders `(integrator, spp, seed)` on two threads with a fraction `dropped` of the shadow
/// rays reported occluded (0 for the real renderer).
fn film(scene: &rt_core::Scene, (integrator, spp, seed): Render, dropped: f64) -> Film {
    weakened(scene, dropped, &|r, buffers| {
        r.render(integrator, buffers, spp, seed).0
    })
}

type Render<'a> = (&'a dyn Integrator, u32, u32);

/// [`film`] for any technique (the wavefront tracer).
fn technique_film(
    scene: &rt_core::Scene,
    (technique, spp, seed): (&dyn Technique, u32, u32),
    dropped: f64,
) -> Film {
    weakened(scene, dropped, &|r, buffers| {
        r.render_technique(technique, buffers, spp, seed).0
    })
}

/// `render` through a two-thread renderer whose structure reports a fraction `dropped` of
/// the shadow rays occluded, into a film that keeps the variance.
fn weakened(
    scene: &rt_core::Scene,
    dropped: f64,
    render: &dyn Fn(&Renderer<'_>, FilmBuffers) -> Film,
) -> Film {
    let plain = Renderer::new(scene).threads(2);
    let mutant = DroppedShadowRays {
        inner: plain.accel(),
        fraction: dropped,
    };
    let renderer = Renderer::new(scene).with_accel(&mutant).threads(2);
    render(
        &renderer,
        FilmBuffers::from(AovSet::default()).with_variance(),
    )
}

/// Renders `nee` (with next-event estimation) and `bsdf` (BSDF sampling only), each given with
/// its samples per pixel and seed, and asserts that they agree within noise.
fn agree(scene: &rt_core::Scene, nee: Render, bsdf: Render) {
    let c = compare(
        &film(scene, nee, 0.0),
        &film(scene, bsdf, 0.0),
        BLOCK,
        ALPHA,
    );
    assert!(c.same_within_noise(), "estimators disagree: {}", show(&c));
}

fn show(c: &Comparison) -> String {
    format!(
        "max block |z| {:.2} (crit {:.2}), image z {:.2} (crit {:.2})",
        c.max_block_z, c.block_crit, c.image_z, c.image_crit
    )
}

/// [`agree`], and the control: `nee` with 2 % of its shadow rays dropped must disagree.
fn agree_and_control(scene: &rt_core::Scene, nee: Render, bsdf: Render) {
    control_case(
        nee.0.name(),
        &|dropped| film(scene, nee, dropped),
        film(scene, bsdf, 0.0),
    );
}

/// The honest film `nee(0)` agrees with `reference` and the film `nee(DROPPED)`, whose shadow
/// rays are 2 % weaker, does not.
fn control_case(name: &str, nee: &dyn Fn(f64) -> Film, reference: Film) {
    let honest = compare(&nee(0.0), &reference, BLOCK, ALPHA);
    let biased = compare(&nee(DROPPED), &reference, BLOCK, ALPHA);
    eprintln!(
        "{name}: {}; NEE x{}: {}",
        show(&honest),
        1.0 - DROPPED,
        show(&biased)
    );
    assert!(
        honest.same_within_noise(),
        "estimators disagree: {}",
        show(&honest)
    );
    assert!(
        !biased.same_within_noise(),
        "control: NEE x{} passes the same test: {}",
        1.0 - DROPPED,
        show(&biased)
    );
}

#[test]
fn nee_with_mis_and_bsdf_sampling_agree() {
    let scene = scene_from_toml(ROOM);
    agree_and_control(
        &scene,
        (&PathIntegrator::new(6), 1024, 11),
        (&PathIntegrator::bsdf_only(6), 8192, 12),
    );
}

/// The wavefront tracer (NEE and MIS in batches) against scalar BSDF sampling, with the same
/// control: its own shadow-ray stream 2 % weaker must disagree.
#[test]
fn wavefront_nee_with_mis_and_bsdf_sampling_agree() {
    let scene = scene_from_toml(ROOM);
    let wavefront = Wavefront::new(PathIntegrator::new(6), DEFAULT_LANES);
    control_case(
        "wavefront",
        &|dropped| technique_film(&scene, (&wavefront, 1024, 11), dropped),
        film(&scene, (&PathIntegrator::bsdf_only(6), 8192, 12), 0.0),
    );
}

#[test]
fn direct_lighting_agrees_with_one_bounce_bsdf_sampling() {
    let scene = scene_from_toml(ROOM);
    agree_and_control(
        &scene,
        (&PathIntegrator::direct(), 4096, 3),
        (&PathIntegrator::bsdf_only(1), 32768, 4),
    );
}

/// The same agreement under an environment map (a smooth sky with a broad bright patch), which
/// exercises the map's luminance importance sampling and its MIS weights.
#[test]
fn nee_and_bsdf_sampling_agree_under_an_environment_map() {
    use rt_core::environment::{EnvMap, Environment};
    use rt_core::Rgb;
    let open = ROOM
        .replace("[environment]\ncolor = [0.3, 0.4, 0.6]", "")
        .replace("name = \"back\"", "name = \"back-wall\"");
    // Remove the ceiling light and the back wall so the sky lights the scene.
    let open: String = open
        .split("[[geometry]]")
        .filter(|g| !g.contains("\"light\"\nshape") && !g.contains("back-wall"))
        .collect::<Vec<_>>()
        .join("[[geometry]]");
    let mut scene = scene_from_toml(&open);
    let (w, h) = (64u32, 32u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let patch = (-((x - 0.5).powi(2) + (y - 0.3).powi(2)) / 0.01).exp() * 8.0;
            Rgb::new(
                0.4 + patch,
                0.5 + 0.8 * patch,
                0.7 * (1.0 - y) + 0.5 * patch,
            )
        })
        .collect();
    scene.environment = Environment::Map(EnvMap::new(w, h, texels));
    scene.build_lights();
    // No control here: under a sky, BSDF sampling finds the light as well as NEE does, MIS
    // gives NEE about half the weight, and a 2 % NEE bias (1 % of the image) would need about
    // ten times the samples to see (measured: image z moved by 0.9).
    agree(
        &scene,
        (&PathIntegrator::new(4), 256, 21),
        (&PathIntegrator::bsdf_only(4), 1024, 22),
    );
}
