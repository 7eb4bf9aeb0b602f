//! Rough single-thread timing of Bvh2 against Qbvh, closest hit, primary-like rays at an
//! icosphere(6). Run with `cargo test -p rt-accel --release --test qbvh_timing -- --ignored
//! --nocapture`.

mod common;

use glam::Vec3;
use rt_accel::{BuildParams, Bvh2, Qbvh};
use rt_core::{Accel, Ray, TraversalCounters};
use std::time::Instant;

#[test]
#[ignore = "timing, not a check"]
fn bvh2_vs_qbvh_closest_hit() {
    let tris = common::icosphere(6).triangles();
    let bvh = Bvh2::build(&tris, &BuildParams::default());
    let q = Qbvh::from_bvh2(&bvh);
    // A 512 x 512 pinhole camera at z = 3 looking down -z with a 45 degree field of view.
    let n = 512;
    let rays: Vec<Ray> = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            let s = (22.5f32).to_radians().tan();
            let d = Vec3::new(
                (2.0 * (x + 0.5) / n as f32 - 1.0) * s,
                (1.0 - 2.0 * (y + 0.5) / n as f32) * s,
                -1.0,
            );
            Ray::new(Vec3::new(0.1, 0.2, 3.0), d)
        })
        .collect();
    let run = |a: &dyn Accel| {
        let mut best = f64::INFINITY;
        let mut hits = 0;
        for _ in 0..5 {
            let start = Instant::now();
            hits = rays
                .iter()
                .filter(|r| a.intersect(r, f32::INFINITY).is_some())
                .count();
            best = best.min(start.elapsed().as_secs_f64());
        }
        let mut c = TraversalCounters::default();
        for r in &rays {
            a.intersect_counted(r, f32::INFINITY, &mut c);
        }
        println!(
            "{:>5}: {:7.2} Mrays/s, {hits} hits, {:.1} boxes/ray, {:.1} tris/ray, {:.1} MB",
            a.name(),
            rays.len() as f64 / best / 1e6,
            c.nodes_visited as f64 / rays.len() as f64,
            c.prims_tested as f64 / rays.len() as f64,
            a.memory_bytes() as f64 / 1e6
        );
    };
    println!("icosphere(6): {} triangles", tris.len());
    run(&bvh);
    run(&q);
}
