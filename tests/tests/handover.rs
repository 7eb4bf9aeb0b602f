//! Claim 10 of the seed-004 digest: the partitioned renderer's handover at hardness κ = 0.2
//! is seamless. A glossy floor of κ = 0.199 is a diffuse-class layer (eye paths stop on it and
//! the VPLs light it); at κ = 0.2 it is specular-class (eye paths go on through it, specular
//! gathering, and photons reach it). Both lobes are almost the same (Blinn–Phong exponents
//! 204.8 and 205.8), and on both sides the renderer agrees with the path tracer at block scale
//! (block variances from the spread of 16 runs' block means) up to the caustic histogram's
//! derived edge bias, so no step appears at the threshold. That bias applies to caustic light
//! only: at κ = 0.199 the scene has no specular-class surface and no photon lands, so the
//! allowance there is zero; at κ = 0.2 it is 2.7 % of each block's caustic part (the light
//! that reached the block by way of the specular floor: the path tracer's image less its image
//! with a black floor). Control: 2 % of the connections dropped on the VPL side, with its
//! allowance of zero.
//!
//! The back wall stands 0.5 above the floor. Meeting it, the corner made the unclamped VPLs
//! (`clamp = 0`, to keep the VPL side unbiased) heavy-tailed (`G ~ 1/d²` next to the corner
//! has no finite variance): 16 runs underestimated the spread and the block z grew with the
//! samples (3.1 at 16 spp, 6.3 at 128) while 64 runs gave 3.0–3.5 at any spp.

use rt_core::Rgb;
use rt_integrators::{PartitionOptions, Partitioned};
use rt_testkit::agreement::{excess_z, path_reference, reference_blocks, technique_blocks};
use rt_testkit::scene_from_toml;
use rt_testkit::stats::{compare_estimates, ALPHA};

const SIZE: u32 = 24;
const DEPTH: u32 = 5;
const RUNS: u32 = 16;
const SPP: u32 = 128;

fn scene(hardness: f32, floor: f32) -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"
[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "c"
position = [0.0, 1.0, 2.2]
look_at = [0.0, 0.3, 0.0]
fov = 45.0
resolution = [{SIZE}, {SIZE}]

[[material]]
name = "floor"
type = "glossy"
color = [{floor}, {floor}, {floor}]
hardness = {hardness}

[[material]]
name = "wall"
color = [0.6, 0.5, 0.4]

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [8.0, 8.0, 8.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-1.5, 0, 1.5], [1.5, 0, 1.5], [1.5, 0, -1.5], [-1.5, 0, -1.5]]
material = "floor"

[[geometry]]
name = "back"
shape = "quad"
vertices = [[-1.5, 0.5, -1.5], [1.5, 0.5, -1.5], [1.5, 2.5, -1.5], [-1.5, 2.5, -1.5]]
material = "wall"

[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-0.5, 1.5, -1.0], [0.5, 1.5, -1.0], [0.5, 1.5, 0.0], [-0.5, 1.5, 0.0]]
material = "lamp"
"#
    ))
}

/// The caustic histogram's bias bound at block scale: a bin within its radius (half a pixel
/// footprint) of a surface's edge hangs over it and misses on average 2/(3π) ≈ 21 % of its
/// photons; in a block of 4 × 4 pixels that band is an eighth of the block at most, so the
/// block loses at most about 2.7 % of its caustic light. The wall's bottom edge here takes
/// most of the floor's glossy caustic, and at κ = 0.2 blocks along it came out 1–3.5 % dark
/// (block z to 4.1 at 64 runs × 64 spp): the histogram's documented blur, not a step.
const HISTOGRAM_EDGE_BIAS: f32 = 0.027;

/// The largest block excess over noise (beyond the histogram's bias bound on the caustic part)
/// of the partitioned renderer against the path tracer, and the critical value.
fn excess(hardness: f32, dropped: f64) -> (f64, f64) {
    let s = scene(hardness, 0.7);
    let reference = reference_blocks(&path_reference(&s, DEPTH, 8192), SIZE, 4);
    let allowed: Vec<Rgb> = if s.materials[0].layers[0].is_diffuse() {
        vec![Rgb::ZERO; reference.mean.len()]
    } else {
        let dark = reference_blocks(&path_reference(&scene(hardness, 0.0), DEPTH, 8192), SIZE, 4);
        let through_floor = reference.mean.iter().zip(&dark.mean);
        through_floor
            .map(|(all, without)| (*all - *without).max(Rgb::ZERO) * HISTOGRAM_EDGE_BIAS)
            .collect()
    };
    let t = Partitioned::new(
        DEPTH,
        PartitionOptions {
            clamp: 0.0,
            photons: 10_000,
            ..PartitionOptions::default()
        },
    );
    let est = technique_blocks(&s, &t, RUNS, SPP, dropped, 4);
    let crit = compare_estimates(&est, &reference, SIZE / 4, 1, ALPHA).block_crit;
    let z = excess_z(&est, &reference, &allowed);
    eprintln!("hardness {hardness}, dropped {dropped}: excess z {z:.2} (critical {crit:.2})");
    (z, crit)
}

#[test]
fn both_sides_of_the_hardness_threshold_agree_with_path_tracing() {
    for hardness in [0.199, 0.2] {
        let (z, crit) = excess(hardness, 0.0);
        assert!(
            z <= crit,
            "hardness {hardness}: excess z {z:.2} > {crit:.2}"
        );
    }
    // A 2 % loss on the VPL side (direct light included) is a step the test must see.
    let (z, crit) = excess(0.199, 0.02);
    assert!(z > crit, "control passes: excess z {z:.2} <= {crit:.2}");
}
