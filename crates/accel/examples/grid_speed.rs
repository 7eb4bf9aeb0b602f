//! Rays per second of the uniform and irregular grids against `bvh8` on one mesh, with uniform
//! random rays from the crate's bench code (`bench::uniform`, `bench::measure`).
//!
//! ```text
//! cargo run --release -p rt-accel --example grid_speed -- [MESH.obj] [RAYS] [REPEAT]
//! ```
//!
//! `MESH` defaults to `models/stanford-bunny.obj` under `../shared/data`; one thread, best of
//! `REPEAT` (3) runs of `RAYS` (200,000) closest-hit queries.

use rt_accel::bench::{self, measure};
use rt_accel::{AccelSpec, IrregularGrid, IrregularGridParams, UniformGrid, UniformGridParams};
use rt_core::Accel;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tris = match args.first() {
        Some(p) => rt_testkit::obj::read(std::path::Path::new(p)),
        None => rt_testkit::obj::shared_mesh("models/stanford-bunny.obj"),
    }
    .expect("mesh not found");
    // `GRID_SPEED_MORTON=1`: triangles sorted by the Morton code of their centroids first, to
    // see how much of the grids' time is fetching triangles scattered in memory.
    let tris = if std::env::var_os("GRID_SPEED_MORTON").is_some() {
        morton_sorted(tris)
    } else {
        tris
    };
    let n_rays: usize = args.get(1).map_or(200_000, |s| s.parse().expect("RAYS"));
    let repeat: u32 = args.get(2).map_or(3, |s| s.parse().expect("REPEAT"));

    let timed = |f: &dyn Fn() -> Box<dyn Accel>| {
        let t = Instant::now();
        let a = f();
        (a, t.elapsed().as_secs_f64() * 1e3)
    };
    let mut structures: Vec<(Box<dyn Accel>, f64, Option<usize>)> = vec![
        {
            let (a, ms) = timed(&|| {
                "bvh8"
                    .parse::<AccelSpec>()
                    .unwrap()
                    .build(&tris)
                    .expect("the structure builds")
            });
            (a, ms, None)
        },
        {
            let t = Instant::now();
            let g = UniformGrid::build(&tris, &UniformGridParams::default()).unwrap();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let s = g.structure_bytes();
            (Box::new(g) as Box<dyn Accel>, ms, Some(s))
        },
        {
            let t = Instant::now();
            let g = IrregularGrid::build(&tris, &IrregularGridParams::default()).unwrap();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            eprintln!(
                "irregular: virtual {:?}, {} cells, {} references",
                g.virtual_resolution(),
                g.cell_count(),
                g.references()
            );
            let s = g.structure_bytes();
            (Box::new(g) as Box<dyn Accel>, ms, Some(s))
        },
    ];
    // The irregular grid at shallower second levels: a smaller virtual grid, fewer cache misses.
    for max_depth in [1, 2] {
        let t = Instant::now();
        let p = IrregularGridParams {
            max_depth,
            ..Default::default()
        };
        let g = IrregularGrid::build(&tris, &p).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        eprintln!(
            "irregular max_depth={max_depth}: virtual {:?}, {} cells, {} references",
            g.virtual_resolution(),
            g.cell_count(),
            g.references()
        );
        let s = g.structure_bytes();
        structures.push((Box::new(g), ms, Some(s)));
    }
    let bounds = structures[0].0.bounds();
    let set = bench::uniform(&bounds, n_rays, 1);
    println!(
        "{} triangles, {n_rays} uniform rays in the scene box, 1 thread, best of {repeat}",
        tris.len()
    );
    println!(
        "{:<16} {:>10} {:>9} {:>9} {:>12} {:>12} {:>9} {:>9}",
        "structure", "build ms", "MRay/s", "hits", "struct B", "memory B", "cells/ray", "tris/ray"
    );
    for (a, build_ms, structure) in &structures {
        let t = measure::time(a.as_ref(), &set, None, repeat);
        let c = measure::count(a.as_ref(), &set).unwrap_or_default();
        let per = |x: u64| x as f64 / n_rays as f64;
        println!(
            "{:<16} {:>10.1} {:>9.2} {:>9} {:>12} {:>12} {:>9.1} {:>9.1}",
            a.name(),
            build_ms,
            n_rays as f64 / t.seconds / 1e6,
            t.hits,
            structure.map_or("-".to_string(), |s| s.to_string()),
            a.memory_bytes(),
            per(c.nodes_visited),
            per(c.prims_tested),
        );
    }
}

fn morton_sorted(mut tris: Vec<[rt_core::glam::Vec3; 3]>) -> Vec<[rt_core::glam::Vec3; 3]> {
    let b = tris.iter().fold(rt_core::Aabb::EMPTY, |b, t| {
        b.union(rt_core::Aabb::from_points(t))
    });
    let spread = |x: u64| {
        let mut x = x & 0x1f_ffff;
        x = (x | x << 32) & 0x1f00000000ffff;
        x = (x | x << 16) & 0x1f0000ff0000ff;
        x = (x | x << 8) & 0x100f00f00f00f00f;
        x = (x | x << 4) & 0x10c30c30c30c30c3;
        (x | x << 2) & 0x1249249249249249
    };
    let key = |t: &[rt_core::glam::Vec3; 3]| {
        let c = ((t[0] + t[1] + t[2]) / 3.0 - b.min)
            / (b.max - b.min).max(rt_core::glam::Vec3::splat(1e-30));
        let q = c.clamp(rt_core::glam::Vec3::ZERO, rt_core::glam::Vec3::ONE) * 2_097_151.0;
        spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2
    };
    tris.sort_by_cached_key(key);
    tris
}
