//! Ray-origin offsets have no scene-scale epsilon, so a scene scaled by any factor (with its
//! camera) renders the same image: no acne, no light leaking through the corners of the box at
//! small scales, no self-shadowing at large ones. The Cornell box is rendered at 1e-4, 1 and 1e4
//! times its published (millimetre) size and compared pixel by pixel within noise.

use rt_core::{Camera, Scene};
use rt_e2e::{render, scene_from_toml, variance_of_mean};
use rt_integrators::PathIntegrator;

fn scaled(base: &Scene, s: f32) -> Scene {
    let mut scene = base.clone();
    for t in &mut scene.triangles {
        *t = t.map(|v| v * s);
    }
    let c = &base.cameras[0];
    scene.cameras = vec![Camera::look_at(
        "scaled",
        c.position * s,
        (c.position + c.forward) * s,
        c.up,
        c.fov_y_deg,
        24,
        24,
        0.0,
        1.0,
    )];
    scene.build_lights();
    scene
}

#[test]
fn cornell_box_renders_the_same_at_every_scale() {
    let toml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/cornell-box.toml"
    ))
    .unwrap();
    let base = scene_from_toml(&toml);
    let integrator = PathIntegrator::new(8);
    let reference = render(&scaled(&base, 1.0), &integrator, 128, 1, 2);
    for s in [1e-4f32, 1e4] {
        // A different seed: the comparison is statistical, not bitwise.
        let film = render(&scaled(&base, s), &integrator, 128, 2, 2);
        let mut over_4 = 0;
        let (mut diff, mut var) = (0.0f64, 0.0f64);
        for (a, b) in reference.pixels().zip(film.pixels()) {
            let d = a.mean() - b.mean();
            let v = variance_of_mean(&a) + variance_of_mean(&b);
            for c in 0..3 {
                diff += d[c] as f64;
                var += v[c] as f64;
                if d[c].abs() > 4.0 * v[c].sqrt() + 1e-6 {
                    over_4 += 1;
                }
            }
        }
        assert!(
            over_4 <= 4,
            "scale {s}: {over_4} pixel channels differ by more than 4σ"
        );
        let z = diff / var.sqrt();
        assert!(z.abs() < 4.0, "scale {s}: image means differ by {z}σ");
    }
}
