//! A camera's near clip hides what lies between the lens and the near plane, for camera rays
//! and for light paths alike: the Cornell box seen through a wall 100 mm in front of the
//! camera, clipped at 200 mm, is the box without the wall. The path tracer and the wavefront
//! tracer (camera rays start on the near plane), the light tracer (connections are tested for
//! visibility only up to the near plane) and BDPT (both) are each compared with the path tracer's image of the box without the
//! wall by the block z-test of `estimators_agree.rs`.
//!
//! Control: the same light tracer without the clip sees the (black) wall and must be
//! caught; so must a path tracer whose clip is too short to pass the wall.

use rt_integrators::{
    Bdpt, CameraRays, LightTracer, PathIntegrator, Technique, Wavefront, DEFAULT_LANES,
};
use rt_testkit::agreement::{path_reference, technique_estimate};
use rt_testkit::stats::{compare_estimates, ALPHA};
use rt_testkit::{scene_from_toml, workspace_root, SceneExt};

const SIZE: u32 = 24;
const BLOCK: u32 = 4;
const DEPTH: u32 = 6;

/// The shipped Cornell box, optionally with a black wall across the whole view at z = -700
/// (100 mm in front of the camera) and a near clip of `near` mm. Black, so that it only
/// absorbs what would otherwise leave the open box for the black environment: the light in
/// the box is the same with and without it.
fn box_scene(wall: bool, near: f32) -> rt_core::Scene {
    let path = workspace_root().join("scenes/cornell-box.toml");
    let text = std::fs::read_to_string(&path).expect("the shipped Cornell box");
    let mut text = text.replacen(
        "resolution = [512, 512]",
        &format!("resolution = [512, 512]\nnear_clip = {near}"),
        1,
    );
    if wall {
        text.push_str(
            r#"
[[material]]
name = "black"
color = [0.0, 0.0, 0.0]

[[geometry]]
name = "wall-before-the-camera"
material = "black"
shape = "quad"
vertices = [[-2000, -2000, -700], [2000, -2000, -700], [2000, 2000, -700], [-2000, 2000, -700]]
"#,
        );
    }
    scene_from_toml(&text).with_resolution(SIZE, SIZE)
}

#[test]
fn a_near_clip_hides_a_wall_before_the_camera_from_camera_rays_and_light_paths() {
    let reference = path_reference(&box_scene(false, 0.0), DEPTH, 2048);
    let path = CameraRays(Box::new(PathIntegrator::new(DEPTH)));
    let wavefront = Wavefront::new(PathIntegrator::new(DEPTH), DEFAULT_LANES);
    let (light, bdpt) = (LightTracer::new(DEPTH), Bdpt::new(DEPTH));
    let compare = |scene: &rt_core::Scene, technique: &dyn Technique| {
        let e = technique_estimate(scene, technique, 8, 128, 0.0);
        let c = compare_estimates(&e, &reference, SIZE, BLOCK, ALPHA);
        eprintln!("{}: {c:?}", technique.name());
        c
    };
    let clipped = box_scene(true, 200.0);
    let techniques: [&dyn Technique; 4] = [&path, &wavefront, &light, &bdpt];
    for t in techniques {
        let c = compare(&clipped, t);
        assert!(c.same_within_noise(), "{}: {c:?}", t.name());
    }
    // Controls: a clip short of the wall, and no clip, see the wall.
    let short = compare(&box_scene(true, 50.0), &path);
    assert!(!short.same_within_noise(), "control, path: {short:?}");
    let open = compare(&box_scene(true, 0.0), &light);
    assert!(!open.same_within_noise(), "control, light: {open:?}");
}
