//! Bidirectional path tracing estimates the path tracer's image, all of it (camera rays that
//! hit lights cover what light tracing cannot see): the two agree within noise by the block
//! z-test of `estimators_agree.rs` on the Cornell box (pinhole and thin lens) and on a glass
//! sphere under an environment map, where every light path starts by plane sampling, and on
//! the box lit by a point, a spot and a directional light besides its lamp. BDPT
//! splats its light-tracing strategy, so its variance comes from independent runs.
//!
//! Control: BDPT with 2 % of its connections reported occluded (`DroppedShadowRays`) must be
//! caught. Also: bit-identical images for any thread count and for a render split in passes.

use rt_integrators::Bdpt;
use rt_testkit::agreement::{path_reference, render_in_passes, technique_estimate};
use rt_testkit::stats::{compare_estimates, Comparison, ALPHA};
use rt_testkit::{cornell_box_delta_lights, shipped_scene, SceneExt};

const SIZE: u32 = 24;
const BLOCK: u32 = 4;
const DEPTH: u32 = 6;

/// BDPT (8 runs of `spp`) against the path tracer (2048 spp): honestly and, if asked, with 2 %
/// of the connections dropped.
fn compare(scene: &rt_core::Scene, spp: u32, control: bool) -> (Comparison, Option<Comparison>) {
    let reference = path_reference(scene, DEPTH, 2048);
    let test = |dropped| {
        let b = technique_estimate(scene, &Bdpt::new(DEPTH), 8, spp, dropped);
        compare_estimates(&b, &reference, SIZE, BLOCK, ALPHA)
    };
    let honest = test(0.0);
    let biased = control.then(|| test(0.02));
    eprintln!("honest {honest:?}\nbiased {biased:?}");
    (honest, biased)
}

/// BDPT agrees with path tracing on `scene`, and the control (2 % of connections dropped)
/// is caught.
fn agrees_and_sees_the_control(scene: &rt_core::Scene) {
    let (honest, biased) = compare(scene, 64, true);
    assert!(honest.same_within_noise(), "bdpt disagrees: {honest:?}");
    let biased = biased.expect("asked for");
    assert!(
        !biased.same_within_noise(),
        "control: 2 % of connections dropped passes: {biased:?}"
    );
}

#[test]
fn bdpt_agrees_with_path_tracing_on_the_cornell_box() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    agrees_and_sees_the_control(&scene);
}

#[test]
fn bdpt_agrees_with_path_tracing_through_a_thin_lens() {
    let scene = shipped_scene("cornell-box.toml")
        .with_resolution(SIZE, SIZE)
        .with_lens(150.0, 1100.0);
    let (honest, _) = compare(&scene, 64, false);
    assert!(honest.same_within_noise(), "bdpt disagrees: {honest:?}");
}

/// An environment map with a sun and a glass sphere: light subpaths start by plane sampling,
/// and the sphere's caustic and refraction need the delta-aware weights.
#[test]
fn bdpt_agrees_with_path_tracing_under_an_environment_map() {
    let scene = shipped_scene("environment.toml").with_resolution(SIZE, SIZE);
    let (honest, _) = compare(&scene, 64, false);
    assert!(honest.same_within_noise(), "bdpt disagrees: {honest:?}");
}

/// Delta lights start light subpaths and are sampled by next-event estimation; the strategy
/// that would hit them (`s = 0`) cannot, and must drop out of their paths' weights.
#[test]
fn bdpt_agrees_with_path_tracing_under_delta_lights() {
    let mut scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    scene.delta_lights = cornell_box_delta_lights();
    scene.build_lights();
    agrees_and_sees_the_control(&scene);
}

#[test]
fn bdpt_is_deterministic_across_threads_and_passes() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(20, 12);
    let bdpt = Bdpt::new(DEPTH);
    let render = |threads, cuts: &[u32]| render_in_passes(&scene, &bdpt, threads, cuts);
    let one = render(1, &[0, 6]);
    let three = render(3, &[0, 6]);
    let split = render(2, &[0, 2, 6]);
    assert_eq!(one.mean_image(), three.mean_image());
    assert_eq!(one.mean_image(), split.mean_image());
    assert_eq!(one.half_image(0), split.half_image(0));
    assert_eq!(one.light_paths(), 20 * 12 * 6);
    assert!(one.mean_image().iter().any(|p| p.max_element() > 0.0));
}
