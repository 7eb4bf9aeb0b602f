//! Every material preset and layered stacks, through the renderer, each case with its control.
//!
//! A plain Lambertian material takes the BSDF's fast path (`Bsdf::new` keeps its value and pdf
//! and skips the layer loop), so the furnace and agreement tests on diffuse scenes never reach
//! the layer code that plastic's base and every custom stack go through. Here each preset
//! (diffuse, glossy, metal, plastic, rough glass) and two custom stacks are rendered by the
//! scalar path tracer and by the wavefront tracer (the default integrator), two ways:
//!
//! - **One-bounce furnace**: a plane under a constant sky `L`, seen through a 1° camera, has
//!   the image `L · A(wo)`. The reference `A` is built per layer, not from the material's own
//!   `Bsdf::eval`: `A = Σᵢ wᵢ(wo) Aᵢ(wo)`, with the layer weights `wᵢ` of the documented rule
//!   (a coat takes the Schlick share `F(θo)` of its weight and passes `1 − F`), a Lambertian
//!   layer's `Aᵢ` its colour exactly, and any other layer's `Aᵢ` the quadrature of that layer
//!   alone. A stack that mixes its layers wrongly, or evaluates one of them wrongly, misses it.
//!   Tolerance: 4 standard errors, plus the change of `A` over the camera's ±0.5° and the
//!   quadrature's own error (two grid resolutions).
//! - **Light sampling against BSDF sampling**: one bounce of next-event estimation with MIS
//!   against one bounce of BSDF sampling alone, on a plane lit by an area light, judged by the
//!   block z-test (`rt_testkit::stats::compare`, α = 10⁻³).
//!
//! Control of both, per case: the material with its Lambertian layers 3 % darker (a preset
//! without one: every layer 3 % darker) — what a Lambertian layer evaluated 3 % low inside a
//! stack does to the renderer — must fail the furnace against the honest reference, and its
//! light-sampled image must disagree with the honest BSDF-sampled one. Mirror and smooth glass
//! are delta lobes: light sampling cannot reach them and the quadrature cannot see them; the
//! energy-conserving furnace (`furnace.rs`) holds them to `L` exactly.

use rt_core::glam::Vec3;
use rt_core::material::{Bsdf, Layer, Material};
use rt_core::{Rgb, Scene};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{CameraRays, PathIntegrator, Technique, Wavefront, DEFAULT_LANES};
use rt_testkit::furnace::{one_bounce_plane_toml, L};
use rt_testkit::stats::{compare, image_mean, Comparison, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

/// How much darker the control makes the Lambertian layers (or every layer).
const DARKER: f32 = 0.97;

/// The cases: a name and the body of a `[[material]]` table (without its name).
const CASES: [(&str, &str); 7] = [
    ("diffuse", "type = \"diffuse\"\ncolor = [0.9, 0.6, 0.3]"),
    (
        "glossy",
        "type = \"glossy\"\ncolor = [0.9, 0.8, 0.7]\nhardness = 0.3",
    ),
    (
        "metal",
        "type = \"metal\"\ncolor = [0.9, 0.6, 0.3]\nhardness = 0.3",
    ),
    (
        "plastic",
        "type = \"plastic\"\ncolor = [0.2, 0.5, 0.8]\nhardness = 0.3",
    ),
    (
        "rough glass",
        "type = \"glass\"\ncolor = [1.0, 1.0, 1.0]\nhardness = 0.3",
    ),
    (
        "lambert and glossy",
        "layers = [ { weight = 0.6, color = [0.8, 0.7, 0.5] }, \
         { weight = 0.4, color = [0.9, 0.9, 0.9], hardness = 0.25 } ]",
    ),
    (
        "coat over glossy and lambert",
        "layers = [ { weight = 1.0, color = [1.0, 1.0, 1.0], hardness = 0.35, coat = true, ior = 1.6 }, \
         { weight = 0.3, color = [0.7, 0.8, 0.9], hardness = 0.2 }, \
         { weight = 0.6, color = [0.9, 0.5, 0.4] } ]",
    ),
];

/// A layer that is Lambertian with one colour at all angles.
fn is_lambert(l: &Layer) -> bool {
    l.hardness == 0.0 && !l.transmission && !l.coat && l.color == l.color90
}

/// The control's material: Lambertian layers `DARKER` times their colour, or, without one,
/// every layer.
fn darkened(m: &Material) -> Material {
    let any_lambert = m.layers.iter().any(is_lambert);
    let mut m = m.clone();
    for l in m
        .layers
        .iter_mut()
        .filter(|l| !any_lambert || is_lambert(l))
    {
        l.color *= DARKER;
        l.color90 *= DARKER;
    }
    m
}

/// The weights of `m`'s layers for outgoing cosine `cos_o`, by the rule of the material
/// model's documentation: a coat takes `weight · F(θo)` (Schlick, for its ior) of what reaches
/// it and passes `1 − F(θo)` on; any other layer takes its weight of what reaches it.
fn layer_weights(m: &Material, cos_o: f64) -> Vec<f64> {
    let mut passed = 1.0;
    m.layers
        .iter()
        .map(|l| {
            let w = f64::from(l.weight) * passed;
            if !l.coat {
                return w;
            }
            let f0 = ((f64::from(l.ior) - 1.0) / (f64::from(l.ior) + 1.0)).powi(2);
            let f = f0 + (1.0 - f0) * (1.0 - cos_o).powi(5);
            passed *= 1.0 - f;
            w * f
        })
        .collect()
}

/// Directional albedo of layer `l` alone (weight 1, no coat share) at `wo`, per channel: its
/// colour for a Lambertian layer, else `∫ f |cos θi| dωi` by the midpoint rule on the (θ, φ)
/// grid of `rt_testkit::chi2` with `sub²` points per bin.
fn layer_albedo(l: &Layer, wo: Vec3, sub: usize) -> [f64; 3] {
    if is_lambert(l) {
        return l.color.to_array().map(f64::from);
    }
    let mut alone = Material::diffuse("alone", Rgb::ONE);
    alone.layers = vec![Layer {
        weight: 1.0,
        coat: false,
        ..l.clone()
    }];
    let bsdf = Bsdf::new(&alone, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
    std::array::from_fn(|c| {
        let f = |d: Vec3| f64::from(bsdf.eval(d)[c]) * f64::from(d.z.abs());
        rt_testkit::chi2::expected(f, sub).iter().sum()
    })
}

/// `A(wo)` of `m` at polar angle `deg`, averaged over the channels (as `image_mean` is).
fn albedo(m: &Material, deg: f32, sub: usize) -> f64 {
    let t = deg.to_radians();
    let wo = Vec3::new(t.sin(), 0.0, t.cos());
    let weights = layer_weights(m, f64::from(t.cos()));
    let per_layer = m.layers.iter().zip(weights).map(|(l, w)| {
        let a = layer_albedo(l, wo, sub);
        w * (a[0] + a[1] + a[2]) / 3.0
    });
    per_layer.sum()
}

/// Renders the first camera of `scene` at `spp` with seed `seed`, into a film that keeps the
/// variance.
fn film(scene: &Scene, technique: &dyn Technique, spp: u32, seed: u32) -> Film {
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_variance();
    Renderer::new(scene)
        .threads(2)
        .render_technique(technique, buffers, spp, seed)
        .0
}

/// The scalar path tracer as a technique.
fn scalar(settings: PathIntegrator) -> CameraRays {
    CameraRays(Box::new(settings))
}

/// The scalar path tracer `settings` and the wavefront tracer with the same settings.
fn both(settings: PathIntegrator) -> [Box<dyn Technique>; 2] {
    [
        Box::new(scalar(settings.clone())),
        Box::new(Wavefront::new(settings, DEFAULT_LANES)),
    ]
}

#[test]
fn one_bounce_furnace_of_every_preset_and_stack_with_a_darker_lambertian_control() {
    for (name, body) in CASES {
        for theta in [25.0f32, 65.0] {
            let mut scene = scene_from_toml(&one_bounce_plane_toml(body, theta.to_radians()));
            let honest = scene.materials[0].clone();
            let a = albedo(&honest, theta, 8);
            let quadrature = (albedo(&honest, theta, 16) - a).abs();
            let spread = [theta - 0.5, theta + 0.5]
                .map(|d| (albedo(&honest, d, 8) - a).abs())
                .into_iter()
                .fold(0.0, f64::max);
            let expected = f64::from(L) * a;
            let within = |film: &Film| {
                let (mean, se) = image_mean(film);
                let tol = 4.0 * se + f64::from(L) * (spread + quadrature);
                ((mean - expected).abs() <= tol, mean, tol)
            };
            for technique in both(PathIntegrator::new(1)) {
                let (ok, mean, tol) = within(&film(&scene, technique.as_ref(), 1024, 3));
                assert!(
                    ok,
                    "{name} at {theta}°, {}: image mean {mean:.5} vs L·A = {expected:.5} \
                     (A {a:.4}, tol {tol:.1e})",
                    technique.name()
                );
            }
            scene.materials[0] = darkened(&honest);
            let (ok, mean, tol) = within(&film(&scene, &scalar(PathIntegrator::new(1)), 1024, 3));
            eprintln!(
                "{name} at {theta}°: L·A {expected:.5}, tol {tol:.1e}; darker control {mean:.5}"
            );
            assert!(
                !ok,
                "control: {name} at {theta}° with its Lambertian layers {DARKER} times as \
                 bright passes: {mean:.5} vs {expected:.5} (tol {tol:.1e})"
            );
        }
    }
}

/// A plane of material `m` between two area lights, one above facing down and one below facing
/// up (what rough glass transmits), no sky, seen at angles from about 30° to 70°. The lights
/// cover the mirror and refracted directions of every pixel with a margin: a
/// glossy lobe that missed it entirely would leave BSDF sampling at zero with zero variance
/// where light sampling finds a tail of 10⁻⁸, a "difference" of no meaning.
fn lit_plane(body: &str) -> String {
    format!(
        r#"
[[camera]]
name = "c"
position = [0.0, 1.2, 2.2]
look_at = [0.0, 0.0, -0.2]
up = [0.0, 1.0, 0.0]
fov = 50.0
resolution = [16, 16]

[[material]]
name = "m"
{body}

[[material]]
name = "light"
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [3.0, 3.0, 3.0]

[[geometry]]
name = "plane"
shape = "quad"
vertices = [[-20.0, 0.0, 20.0], [20.0, 0.0, 20.0], [20.0, 0.0, -20.0], [-20.0, 0.0, -20.0]]
material = "m"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-4.0, 1.5, -9.0], [4.0, 1.5, -9.0], [4.0, 1.5, 0.0], [-4.0, 1.5, 0.0]]
material = "light"

[[geometry]]
name = "light below"
shape = "quad"
vertices = [[-4.0, -1.5, 2.0], [4.0, -1.5, 2.0], [4.0, -1.5, -9.0], [-4.0, -1.5, -9.0]]
material = "light"
"#
    )
}

fn show(c: &Comparison) -> String {
    format!(
        "max block |z| {:.2} (crit {:.2}), image z {:.2} (crit {:.2})",
        c.max_block_z, c.block_crit, c.image_z, c.image_crit
    )
}

#[test]
fn light_and_bsdf_sampling_agree_on_every_preset_and_stack_with_a_darker_lambertian_control() {
    for (name, body) in CASES {
        let mut scene = scene_from_toml(&lit_plane(body));
        let honest = scene.materials[0].clone();
        let bsdf_sampled = film(&scene, &scalar(PathIntegrator::bsdf_only(1)), 4096, 12);
        for technique in both(PathIntegrator::direct()) {
            let c = compare(
                &film(&scene, technique.as_ref(), 1024, 11),
                &bsdf_sampled,
                4,
                ALPHA,
            );
            assert!(
                c.same_within_noise(),
                "{name}, {}: light sampling and BSDF sampling disagree: {}",
                technique.name(),
                show(&c)
            );
        }
        scene.materials[0] = darkened(&honest);
        let dark = film(&scene, &scalar(PathIntegrator::direct()), 1024, 11);
        let c = compare(&dark, &bsdf_sampled, 4, ALPHA);
        eprintln!("{name}: darker control {}", show(&c));
        assert!(
            !c.same_within_noise(),
            "control: {name} light-sampled with its Lambertian layers {DARKER} times as bright \
             agrees with the honest BSDF-sampled image: {}",
            show(&c)
        );
    }
}
