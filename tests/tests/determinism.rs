//! The same scene, seed and settings give a bit-identical image whatever the thread count.

use rt_e2e::{render, scene_from_toml};
use rt_integrators::PathIntegrator;

#[test]
fn images_do_not_depend_on_thread_count() {
    let toml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/cornell-box.toml"
    ))
    .unwrap();
    let mut scene = scene_from_toml(&toml);
    scene.cameras[0] = rt_core::Camera::look_at(
        "small",
        scene.cameras[0].position,
        scene.cameras[0].position + scene.cameras[0].forward,
        scene.cameras[0].up,
        scene.cameras[0].fov_y_deg,
        24,
        24,
        0.0,
        1.0,
    );
    let integrator = PathIntegrator::new(8);
    let one = render(&scene, &integrator, 16, 5, 1);
    let three = render(&scene, &integrator, 16, 5, 3);
    assert_eq!(one.mean_image(), three.mean_image());
    assert!(one.variance_image().is_some());
    assert_eq!(one.variance_image(), three.variance_image());
    let other_seed = render(&scene, &integrator, 16, 6, 3);
    assert_ne!(one.mean_image(), other_seed.mean_image());
}
