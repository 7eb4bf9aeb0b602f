//! Next-event estimation with MIS and pure BSDF sampling estimate the same integral, so their
//! images must agree within noise: per pixel (z-test on the difference, using both variances)
//! and over the whole image.

use rt_e2e::{render, scene_from_toml, variance_of_mean};
use rt_film::Film;
use rt_integrators::PathIntegrator;

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

fn compare(a: &Film, b: &Film) {
    let mut worst = 0.0f32;
    let mut over_4 = 0;
    let (mut diff_sum, mut var_sum) = (0.0f64, 0.0f64);
    let n = a.pixels().len() * 3;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let d = pa.mean() - pb.mean();
        let v = variance_of_mean(&pa) + variance_of_mean(&pb);
        for c in 0..3 {
            diff_sum += d[c] as f64;
            var_sum += v[c] as f64;
            if v[c] > 0.0 {
                let z = d[c].abs() / v[c].sqrt();
                worst = worst.max(z);
                if z > 4.0 {
                    over_4 += 1;
                }
            }
        }
    }
    // With n ≈ 1200 values a normal z exceeds 4 about 0.08 times on average; heavy tails of
    // path-traced pixels make a few more plausible, many mean a bias.
    assert!(
        over_4 <= 3 + n / 400,
        "{over_4} of {n} pixel channels differ by more than 4σ (worst {worst})"
    );
    let z_all = diff_sum / var_sum.sqrt();
    assert!(z_all.abs() < 4.0, "image means differ by {z_all}σ");
}

#[test]
fn nee_with_mis_and_bsdf_sampling_agree() {
    let scene = scene_from_toml(ROOM);
    let nee = render(&scene, &PathIntegrator::new(6), 256, 11, 2);
    let bsdf = render(&scene, &PathIntegrator::bsdf_only(6), 1024, 12, 2);
    compare(&nee, &bsdf);
}

#[test]
fn direct_lighting_agrees_with_one_bounce_bsdf_sampling() {
    let scene = scene_from_toml(ROOM);
    let direct = render(&scene, &PathIntegrator::direct(), 128, 3, 2);
    let bsdf = render(&scene, &PathIntegrator::bsdf_only(1), 1024, 4, 2);
    compare(&direct, &bsdf);
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
    let nee = render(&scene, &PathIntegrator::new(4), 256, 21, 2);
    let bsdf = render(&scene, &PathIntegrator::bsdf_only(4), 1024, 22, 2);
    compare(&nee, &bsdf);
}
