//! Claim 13 of the seed-004 digest: the caustic histogram's bias is bounded. With bins of
//! half a pixel's footprint, the partitioned renderer's caustic under a glass sphere matches
//! the path tracer's image by the block z-test (4 × 4-pixel blocks, the partitioned renderer's
//! block variances from the spread of 16 runs' block means, as its pixels are correlated), although the histogram
//! blurs each photon over its bin. The VPL clamp is off, so the blur is the only bias. A 2 %
//! dropped-connection control is caught at the same sample counts.

use rt_integrators::{PartitionOptions, Partitioned};
use rt_testkit::agreement::{path_reference, reference_blocks, technique_blocks};
use rt_testkit::scene_from_toml;
use rt_testkit::stats::{compare_estimates, ALPHA};

const SIZE: u32 = 24;
const DEPTH: u32 = 6;

const SCENE: &str = r#"
[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "top"
position = [0.0, 2.4, 1.9]
look_at = [0.0, 0.0, 0.45]
fov = 30.0
resolution = [24, 24]

[[material]]
name = "floor"
color = [0.7, 0.7, 0.7]

[[material]]
name = "glass"
type = "glass"
ior = 1.5

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [30.0, 30.0, 30.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]
material = "floor"

[[geometry]]
name = "ball"
shape = "sphere"
center = [0.0, 0.55, 0.0]
radius = 0.45
subdivisions = 4
material = "glass"

[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-0.2, 2.5, -1.4], [0.2, 2.5, -1.4], [0.2, 2.5, -1.0], [-0.2, 2.5, -1.0]]
material = "lamp"
"#;

#[test]
fn caustic_histogram_matches_path_tracing_within_noise() {
    let scene = scene_from_toml(SCENE);
    let reference = reference_blocks(&path_reference(&scene, DEPTH, 8192), SIZE, 4);
    let t = Partitioned::new(
        DEPTH,
        PartitionOptions {
            clamp: 0.0,
            photons: 20_000,
            ..PartitionOptions::default()
        },
    );
    let run = |dropped| {
        let c = compare_estimates(
            &technique_blocks(&scene, &t, 16, 16, dropped, 4),
            &reference,
            SIZE / 4,
            1,
            ALPHA,
        );
        eprintln!("dropped {dropped}: {c:?}");
        c
    };
    let honest = run(0.0);
    assert!(honest.same_within_noise(), "{honest:?}");
    let biased = run(0.02);
    assert!(!biased.same_within_noise(), "control passes: {biased:?}");
}
