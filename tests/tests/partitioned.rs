//! The path-space-partitioned renderer estimates the path tracer's image: with the VPL clamp
//! off, on the Cornell box (no specular surface, so parts A and D only) the two agree within
//! noise by the block z-test, and a 2 % dropped-connection control is caught. On a scene with
//! glass (parts B and C) the histogram's half-pixel blur is its only bias. Also: bit-identical
//! images for any thread count.

use rt_film::AovSet;
use rt_integrators::{PartitionOptions, Partitioned};
use rt_testkit::agreement::{path_reference, reference_blocks, technique_blocks};
use rt_testkit::stats::{compare_estimates, Comparison, ALPHA};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

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
    let reference = reference_blocks(&path_reference(scene, DEPTH, 2048), SIZE, BLOCK);
    let t = Partitioned::new(DEPTH, o);
    let c = compare_estimates(
        &technique_blocks(scene, &t, 16, spp, dropped, BLOCK),
        &reference,
        SIZE / BLOCK,
        1,
        ALPHA,
    );
    eprintln!("dropped {dropped}: {c:?}");
    c
}

#[test]
fn partitioned_agrees_with_path_tracing_on_the_cornell_box() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    let honest = compare(&scene, 32, 0.0, unclamped());
    assert!(
        honest.same_within_noise(),
        "partitioned disagrees: {honest:?}"
    );
    let biased = compare(&scene, 32, 0.02, unclamped());
    assert!(!biased.same_within_noise(), "control passes: {biased:?}");
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
