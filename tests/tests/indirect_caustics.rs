//! Indirect caustics of the partitioned renderer (`indirect_caustics`, the thesis' artist-set
//! depth): a diffuse ceiling over a mirror floor sees itself in the mirror, so most of its
//! light arrives along `EDS+D+L` (ceiling, mirror, ceiling, lamp). Without photons from the
//! VPLs those paths are missing and the image is far too dark; with them (depth 3 covers every
//! path of 5 bounces) it agrees with the path tracer by the block z-test (block z 2.0 against
//! a critical 4.6; 15–21 without). The missing paths are the control.

use rt_integrators::{PartitionOptions, Partitioned};
use rt_testkit::agreement::{path_reference, reference_blocks, technique_blocks};
use rt_testkit::scene_from_toml;
use rt_testkit::stats::{compare_estimates, Comparison, ALPHA};

const SIZE: u32 = 24;
const DEPTH: u32 = 5;

fn scene() -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"
[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "c"
position = [0.0, 0.5, 1.0]
look_at = [0.0, 1.5, -1.0]
fov = 30.0
resolution = [{SIZE}, {SIZE}]

[[material]]
name = "mirror"
type = "mirror"
color = [0.9, 0.9, 0.9]

[[material]]
name = "ceiling"
color = [0.7, 0.6, 0.5]

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [6.0, 6.0, 6.0]
two_sided = true

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-20, 0, 20], [20, 0, 20], [20, 0, -20], [-20, 0, -20]]
material = "mirror"

[[geometry]]
name = "ceiling"
shape = "quad"
vertices = [[-20, 1, -20], [20, 1, -20], [20, 1, 20], [-20, 1, 20]]
material = "ceiling"

[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-0.2, 0.3, -1.2], [0.2, 0.3, -1.2], [0.2, 0.3, -0.8], [-0.2, 0.3, -0.8]]
material = "lamp"
"#
    ))
}

/// The partitioned renderer against the path tracer at block scale.
fn compare(indirect_caustics: u32) -> Comparison {
    let s = scene();
    let reference = reference_blocks(&path_reference(&s, DEPTH, 4096), SIZE, 4);
    let t = Partitioned::new(
        DEPTH,
        PartitionOptions {
            clamp: 0.0,
            photons: 10_000,
            indirect_caustics,
            ..PartitionOptions::default()
        },
    );
    let est = technique_blocks(&s, &t, 16, 32, 0.0, 4);
    let c = compare_estimates(&est, &reference, SIZE / 4, 1, ALPHA);
    eprintln!("indirect caustics {indirect_caustics}: {c:?}");
    c
}

#[test]
fn photons_from_vpls_add_the_missing_paths() {
    let with = compare(3);
    assert!(with.same_within_noise(), "with indirect caustics: {with:?}");
    let without = compare(0);
    assert!(
        !without.same_within_noise(),
        "without them the test passes: {without:?}"
    );
}
