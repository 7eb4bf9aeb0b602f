//! The path-space-partitioned renderer estimates the path tracer's image: with the VPL clamp
//! off, on the Cornell box (no specular surface, so parts A and D only) the two agree within
//! noise by the block z-test, and a 2 % dropped-connection control is caught. On a scene with
//! glass (parts B and C) the histogram's half-pixel blur is its only bias. The box lit by a
//! point, a spot and a directional light besides its lamp agrees too (the lights become VPLs of
//! their own, unclamped). Also: bit-identical images for any thread count.

use rt_film::AovSet;
use rt_integrators::{PartitionOptions, Partitioned};
use rt_testkit::agreement::{path_reference, reference_blocks, technique_blocks};
use rt_testkit::stats::{compare_estimates, Comparison, Estimate, ALPHA};
use rt_testkit::{cornell_box_delta_lights, shipped_scene, Renderer, SceneExt};

const SIZE: u32 = 24;
const BLOCK: u32 = 4;
const DEPTH: u32 = 6;

fn unclamped() -> PartitionOptions {
    PartitionOptions {
        clamp: 0.0,
        ..PartitionOptions::default()
    }
}

/// The block z-test at block scale: the partitioned renderer's pixels are correlated (one VPL
/// lights many), so its block variances come from the spread of block means over 16 runs.
fn compare(scene: &rt_core::Scene, spp: u32, dropped: f64, o: PartitionOptions) -> Comparison {
    compare_with(&reference(scene), scene, spp, dropped, o)
}

/// The path tracer's block means and variances (2048 spp).
fn reference(scene: &rt_core::Scene) -> Estimate {
    reference_blocks(&path_reference(scene, DEPTH, 2048), SIZE, BLOCK)
}

/// [`compare`] against a reference already rendered.
fn compare_with(
    reference: &Estimate,
    scene: &rt_core::Scene,
    spp: u32,
    dropped: f64,
    o: PartitionOptions,
) -> Comparison {
    let t = Partitioned::new(DEPTH, o);
    let c = compare_estimates(
        &technique_blocks(scene, &t, 16, spp, dropped, BLOCK),
        reference,
        SIZE / BLOCK,
        1,
        ALPHA,
    );
    eprintln!("dropped {dropped}: {c:?}");
    c
}

/// The unclamped partitioned renderer agrees with path tracing on `scene`, and the control
/// (2 % of its radiance dropped) is caught.
fn agrees_and_sees_the_control(scene: &rt_core::Scene) {
    let honest = compare(scene, 32, 0.0, unclamped());
    assert!(
        honest.same_within_noise(),
        "partitioned disagrees: {honest:?}"
    );
    let biased = compare(scene, 32, 0.02, unclamped());
    assert!(!biased.same_within_noise(), "control passes: {biased:?}");
}

#[test]
fn partitioned_agrees_with_path_tracing_on_the_cornell_box() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    agrees_and_sees_the_control(&scene);
}

#[test]
fn partitioned_agrees_with_path_tracing_under_delta_lights() {
    let mut scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    scene.delta_lights = cornell_box_delta_lights();
    scene.build_lights();
    agrees_and_sees_the_control(&scene);
}

#[test]
fn partitioned_is_deterministic_across_threads() {
    let indirect = PartitionOptions {
        indirect_caustics: 2,
        photons: 20_000,
        ..PartitionOptions::default()
    };
    for (name, o) in [
        ("environment.toml", PartitionOptions::default()),
        ("caustic.toml", indirect),
    ] {
        let scene = shipped_scene(name).with_resolution(20, 12);
        let t = Partitioned::new(DEPTH, o);
        let one = Renderer::new(&scene)
            .threads(1)
            .render_technique(&t, AovSet::default(), 3, 5)
            .0;
        let three = Renderer::new(&scene)
            .threads(3)
            .render_technique(&t, AovSet::default(), 3, 5)
            .0;
        assert_eq!(one.mean_image(), three.mean_image(), "{name}");
        assert!(one.mean_image().iter().any(|p| p.max_element() > 0.0));
    }
}

/// The shipped default clamps the VPLs' geometric term at `1 / (10⁻³ · diagonal)²`. It loses
/// only light from VPLs closer than 10⁻³ of the diagonal to the point they light, which on the
/// Cornell box (diagonal about 3.5) is within 3.5·10⁻³ of a corner, a few per cent of the area
/// of the pixels along the box's edges at this size; the claim it documents is that this bias is
/// below what a render resolves. So the default must agree with path tracing within noise, by
/// the same test as the unclamped renderer; and the test must see a clamp that does matter: at
/// 0.15 of the diagonal (VPLs within half a metre clamped), the control, it fails. Both
/// renders also measure the clamp's loss directly: the same seeds unclamped are brighter by
/// exactly the clamped connections (the clamp only lowers terms), reported for the record.
#[test]
fn the_default_clamp_agrees_with_path_tracing() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    let default = PartitionOptions::default();
    let reference = reference(&scene);
    let shipped = compare_with(&reference, &scene, 32, 0.0, default);
    let coarse = PartitionOptions {
        clamp: 0.15,
        ..PartitionOptions::default()
    };
    let control = compare_with(&reference, &scene, 32, 0.0, coarse);
    let total = |o: PartitionOptions| -> f64 {
        let t = Partitioned::new(DEPTH, o);
        let (film, _) =
            Renderer::new(&scene)
                .threads(2)
                .render_technique(&t, AovSet::default(), 8, 7);
        film.mean_image()
            .iter()
            .map(|c| c.element_sum() as f64)
            .sum()
    };
    let open = total(unclamped());
    eprintln!(
        "clamp loss with the same seeds: default {:.2e}, control {:.2e} of the image",
        1.0 - total(default) / open,
        1.0 - total(coarse) / open
    );
    assert!(
        shipped.same_within_noise(),
        "the default clamp is biased beyond noise: {shipped:?}"
    );
    assert!(
        !control.same_within_noise(),
        "a clamp at 0.15 of the diagonal passes: {control:?}"
    );
}
