//! Light tracing estimates the path tracer's image where it can (no delta bounce seen by the
//! camera, no environment seen directly): on the Cornell box the two agree within noise by the
//! block z-test of `estimators_agree.rs`. The light tracer's film knows no per-pixel variance
//! (its splats land anywhere), so its variance comes from the spread of independent runs.
//!
//! Control: the light tracer with 2 % of its camera connections reported occluded (the
//! `DroppedShadowRays` mutant) must be caught. Also: bit-identical images for any thread count
//! and for a render split into passes.

use rt_integrators::LightTracer;
use rt_testkit::agreement::{path_reference, render_in_passes, technique_estimate};
use rt_testkit::stats::{compare_estimates, Comparison, ALPHA};
use rt_testkit::{cornell_box_delta_lights, shipped_scene, SceneExt};

const SIZE: u32 = 24;
const BLOCK: u32 = 4;
const DEPTH: u32 = 6;

/// The light tracer (8 runs of 256 light paths per pixel) against the path tracer (2048 spp):
/// honestly and with 2 % of the connections dropped.
fn honest_and_biased(scene: &rt_core::Scene) -> (Comparison, Comparison) {
    let reference = path_reference(scene, DEPTH, 2048);
    let test = |dropped| {
        let lt = technique_estimate(scene, &LightTracer::new(DEPTH), 8, 256, dropped);
        compare_estimates(&lt, &reference, SIZE, BLOCK, ALPHA)
    };
    let (honest, biased) = (test(0.0), test(0.02));
    eprintln!("honest {honest:?}\nbiased {biased:?}");
    (honest, biased)
}

#[test]
fn light_tracing_agrees_with_path_tracing_on_the_cornell_box() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    let (honest, biased) = honest_and_biased(&scene);
    assert!(
        honest.same_within_noise(),
        "light tracing disagrees: {honest:?}"
    );
    assert!(
        !biased.same_within_noise(),
        "control: 2 % of camera connections dropped passes: {biased:?}"
    );
}

/// Particles from a point, a spot and a directional light (beside the box's lamp) carry the
/// same light as the path tracer's connections to them.
#[test]
fn light_tracing_agrees_with_path_tracing_under_delta_lights() {
    let mut scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    scene.delta_lights = cornell_box_delta_lights();
    scene.build_lights();
    let (honest, biased) = honest_and_biased(&scene);
    assert!(
        honest.same_within_noise(),
        "light tracing disagrees: {honest:?}"
    );
    assert!(
        !biased.same_within_noise(),
        "control: 2 % of camera connections dropped passes: {biased:?}"
    );
}

/// Through a thin lens (blur circles of about 2.5 pixels on the front block and the back
/// wall), the connection samples the lens.
#[test]
fn light_tracing_agrees_with_path_tracing_through_a_thin_lens() {
    let scene = shipped_scene("cornell-box.toml")
        .with_resolution(SIZE, SIZE)
        .with_lens(150.0, 1100.0);
    let (honest, _) = honest_and_biased(&scene);
    assert!(
        honest.same_within_noise(),
        "light tracing disagrees: {honest:?}"
    );
}

#[test]
fn light_tracing_is_deterministic_across_threads_and_passes() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(20, 12);
    let lt = LightTracer::new(DEPTH);
    let render = |threads, cuts: &[u32]| render_in_passes(&scene, &lt, threads, cuts);
    let one = render(1, &[0, 8]);
    let three = render(3, &[0, 8]);
    let split = render(2, &[0, 3, 8]);
    assert_eq!(one.mean_image(), three.mean_image());
    assert_eq!(one.mean_image(), split.mean_image());
    assert_eq!(one.half_image(0), split.half_image(0));
    assert_eq!(one.light_paths(), 20 * 12 * 8);
    assert!(one.mean_image().iter().any(|p| p.max_element() > 0.0));
    assert_ne!(one.half_image(0), one.half_image(1));
}
