//! Rough single-thread timing of the structures and QBVH options, closest hit, on primary-like
//! rays at an icosphere(6) and on incoherent rays from points on it (or on `RT_TIMING_OBJ`, an
//! OBJ file, when set). Run with `cargo test -p rt-accel --release --test qbvh_timing --
//! --ignored --nocapture`; `render bench-accel` is the real benchmark.

mod common;

use common::Rng;
use glam::Vec3;
use rt_accel::AccelSpec;
use rt_core::{Ray, TraversalCounters};
use std::time::Instant;

#[test]
#[ignore = "timing, not a check"]
fn structures_and_options() {
    let tris = match std::env::var("RT_TIMING_OBJ") {
        Ok(path) => {
            rt_testkit::obj::read(std::path::Path::new(&path)).expect("RT_TIMING_OBJ readable")
        }
        Err(_) => common::icosphere(6).triangles(),
    };
    let bounds = tris.iter().fold(rt_core::Aabb::EMPTY, |b, t| {
        b.union(rt_core::Aabb::from_points(t))
    });
    let (c, r) = (bounds.center(), (bounds.max - bounds.min).length() * 0.5);
    // A 512 x 512 pinhole camera looking at the centre from 2.5 radii away.
    let n = 512;
    let eye = c + Vec3::new(0.3, 0.4, 2.5) * r;
    let fwd = (c - eye).normalize();
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let primary: Vec<Ray> = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            let s = (22.5f32).to_radians().tan();
            let d = fwd
                + right * (2.0 * (x + 0.5) / n as f32 - 1.0) * s
                + up * (1.0 - 2.0 * (y + 0.5) / n as f32) * s;
            Ray::new(eye, d)
        })
        .collect();
    // Incoherent: from the primary hits, uniformly random directions.
    let reference = "bvh"
        .parse::<AccelSpec>()
        .unwrap()
        .build(&tris)
        .expect("the structure builds");
    let mut rng = Rng::new(3);
    let incoherent: Vec<Ray> = primary
        .iter()
        .filter_map(|ray| {
            let h = reference.intersect(ray, f32::INFINITY)?;
            let p = ray.origin + ray.dir * h.t;
            let d = rng.unit_vec();
            Some(Ray::new(p - ray.dir.normalize() * 1e-4 * r, d))
        })
        .collect();
    println!(
        "{} triangles, {} primary, {} incoherent rays",
        tris.len(),
        primary.len(),
        incoherent.len()
    );
    let specs = std::env::var("RT_TIMING_SPECS").unwrap_or_else(|_| {
        "bvh,qbvh,qbvh:order=distance,qbvh:order=unsorted,qbvh:tstack,qbvh:leaf=8".into()
    });
    for spec in specs.split(',') {
        let spec: AccelSpec = spec.parse().unwrap();
        let start = Instant::now();
        let a = spec.build(&tris).expect("the structure builds");
        let build = start.elapsed().as_secs_f64();
        for (name, rays) in [("primary", &primary), ("incoherent", &incoherent)] {
            let mut best = f64::INFINITY;
            let mut hits = 0;
            for _ in 0..10 {
                let start = Instant::now();
                hits = rays
                    .iter()
                    .filter(|r| a.intersect(r, f32::INFINITY).is_some())
                    .count();
                best = best.min(start.elapsed().as_secs_f64());
            }
            let mut c = TraversalCounters::default();
            for r in rays.iter() {
                a.closest_hit(r, f32::INFINITY, Some(&mut c));
            }
            let per = |x: u64| x as f64 / rays.len() as f64;
            println!(
                "{:<28} {:<10} {:7.2} Mrays/s  {hits:>7} hits  {:5.1} boxes {:4.1} leaves {:5.1} tris/ray  build {:6.0} ms  {:6.1} MB",
                spec.to_string(),
                name,
                rays.len() as f64 / best / 1e6,
                per(c.nodes_visited),
                per(c.leaves_visited),
                per(c.prims_tested),
                build * 1e3,
                a.memory_bytes() as f64 / 1e6
            );
        }
    }
}
