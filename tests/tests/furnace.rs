//! White furnace: objects of albedo 1 under a constant environment of radiance L must render as
//! L everywhere for the energy-conserving presets (diffuse, mirror, glass), and never brighter
//! than L for any material. The objects are placed so that light inter-reflects between them
//! (a single convex object would be too easy). The sphere is faceted: interpolated shading
//! normals make any renderer lose (or gain) energy, which is a different question.

use rt_e2e::{image_mean, render, scene_from_toml, variance_of_mean};
use rt_integrators::PathIntegrator;

const L: f32 = 0.5;

fn furnace(material: &str) -> String {
    format!(
        r#"
[environment]
color = [{L}, {L}, {L}]

[[camera]]
name = "c"
position = [0.0, 1.2, 4.0]
look_at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0
resolution = [24, 24]

[[material]]
name = "m"
{material}

[[geometry]]
name = "slab"
shape = "box"
min = [-1.5, -0.2, -1.5]
max = [1.5, 0.0, 1.5]
material = "m"

[[geometry]]
name = "ball"
shape = "sphere"
center = [-0.45, 0.45, 0.0]
radius = 0.45
subdivisions = 2
smooth = false
material = "m"

[[geometry]]
name = "block"
shape = "box"
min = [0.05, 0.0, -0.5]
max = [0.85, 1.2, 0.3]
material = "m"
"#
    )
}

/// Checks the image mean against L with a tolerance of 4 standard errors (estimated from the
/// per-pixel variances), and every pixel against L with 6 of its own standard errors.
fn check(material: &str, equal: bool, integrator: &PathIntegrator, spp: u32) {
    let scene = scene_from_toml(&furnace(material));
    let film = render(&scene, integrator, spp, 1, 2);
    let (mean, se) = image_mean(&film);
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
    }
}

#[test]
fn no_material_is_brighter_than_the_environment() {
    for m in LOSSY {
        check(m, false, &PathIntegrator::new(1000), 32);
    }
}
