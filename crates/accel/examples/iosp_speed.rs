//! Rays per second and traversal counts of the IOSP structures (`rt_accel::iosp`) next to the
//! binary SAH BVH and the default eight-wide BVH, on a mesh of `../shared/data` with the bench
//! module's `uniform` ray set (origins uniform in the bounding box, directions uniform on the
//! sphere), closest-hit queries, one thread, best of `reps` runs. The IOSP answers are first
//! checked against the binary BVH built over the same permuted triangles. Speeds are per
//! second of this thread's CPU time (Linux `/proc/thread-self/schedstat`, wall time elsewhere):
//! on a machine shared with other jobs, wall time mostly measures the other jobs.
//!
//! ```sh
//! cargo run --release -p rt-accel --example iosp_speed -- [models/stanford-bunny.obj]
//!     [--rays 200000] [--reps 3] [--seed 1]
//! ```

use rt_accel::bench::{measure, uniform, RaySet};
use rt_accel::{BuildParams, Bvh2, Bvh8, Iosp0, Iosp2, Iosp4};
use rt_core::glam::Vec3;
use rt_core::Accel;
use std::time::Instant;

fn main() {
    let mut mesh = "models/stanford-bunny.obj".to_string();
    let (mut n_rays, mut reps, mut seed) = (200_000usize, 3u32, 1u64);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().expect("a value after the flag");
        match a.as_str() {
            "--rays" => n_rays = value().parse().expect("--rays N"),
            "--reps" => reps = value().parse().expect("--reps N"),
            "--seed" => seed = value().parse().expect("--seed N"),
            _ => mesh = a,
        }
    }
    let Some(tris) = rt_testkit::obj::shared_mesh(&mesh) else {
        eprintln!("{mesh}: not found under ../shared/data");
        std::process::exit(1);
    };
    println!(
        "{mesh}: {} triangles, {n_rays} uniform rays, one thread, best of {reps}",
        tris.len()
    );
    let timed = |label: &str, f: &mut dyn FnMut() -> Box<dyn Accel>| {
        let t = Instant::now();
        let a = f();
        println!("  build {label}: {:.3} s", t.elapsed().as_secs_f64());
        a
    };
    type Entry = (Box<dyn Accel>, usize, Vec<[Vec3; 3]>);
    let mut entries: Vec<Entry> = Vec::new();
    let bvh8 = timed("bvh8", &mut || {
        Box::new(Bvh8::build(&tris, &BuildParams::default()))
    });
    let bvh8_bytes = bvh8.memory_bytes() - std::mem::size_of_val(tris.as_slice());
    entries.push((bvh8, bvh8_bytes, tris.clone()));
    let bvh = timed("bvh", &mut || {
        Box::new(Bvh2::build(&tris, &BuildParams::default()))
    });
    let bvh_bytes = bvh.memory_bytes() - std::mem::size_of_val(tris.as_slice());
    entries.push((bvh, bvh_bytes, tris.clone()));
    let mut bytes = 0;
    let mut perm_tris = Vec::new();
    let i0 = timed("iosp0", &mut || {
        let (s, _) = Iosp0::build(&tris).expect("iosp0");
        bytes = s.structure_bytes();
        perm_tris = s.triangles().to_vec();
        Box::new(s)
    });
    entries.push((i0, bytes, perm_tris.clone()));
    let i4 = timed("iosp4", &mut || {
        let (s, _) = Iosp4::build(&tris).expect("iosp4");
        bytes = s.structure_bytes();
        perm_tris = s.triangles().to_vec();
        Box::new(s)
    });
    entries.push((i4, bytes, perm_tris.clone()));
    let i2 = timed("iosp2", &mut || {
        let (s, _) = Iosp2::build(&tris).expect("iosp2");
        bytes = s.structure_bytes();
        perm_tris = s.triangles().to_vec();
        Box::new(s)
    });
    entries.push((i2, bytes, perm_tris.clone()));

    let set: RaySet = uniform(&entries[0].0.bounds(), n_rays, seed);
    // Check each structure against a binary BVH over its own triangle order.
    for (accel, _, order) in &entries[2..] {
        let reference = Bvh2::build(order, &BuildParams::default());
        let c = measure::check(
            accel.as_ref(),
            &reference,
            std::slice::from_ref(&set),
            20_000,
        );
        println!("  {}: {}", accel.name(), c.summary());
    }
    let mut base = None;
    println!(
        "  {:<6} {:>9} {:>8} {:>12} {:>11} {:>11} {:>12}",
        "accel", "Mrays/s", "vs bvh8", "nodes/ray", "tris/ray", "NT/NI", "bytes (acc.)"
    );
    for (accel, bytes, _) in &entries {
        let mut seconds = f64::INFINITY;
        for _ in 0..reps {
            let (cpu0, wall0) = (thread_cpu_seconds(), Instant::now());
            measure::time(accel.as_ref(), &set, None, 1);
            let wall = wall0.elapsed().as_secs_f64();
            seconds = seconds.min(thread_cpu_seconds().map_or(wall, |c| c - cpu0.unwrap_or(0.0)));
        }
        let c = measure::count(accel.as_ref(), &set).expect("counts");
        let mrays = n_rays as f64 / seconds / 1e6;
        let base = *base.get_or_insert(mrays);
        let per = |x: u64| x as f64 / n_rays as f64;
        println!(
            "  {:<6} {:>9.3} {:>7.1}% {:>12.1} {:>11.1} {:>11.3} {:>12}",
            accel.name(),
            mrays,
            100.0 * mrays / base,
            per(c.nodes_visited),
            per(c.prims_tested),
            c.prims_tested as f64 / c.nodes_visited.max(1) as f64,
            bytes
        );
    }
}

/// Seconds this thread has run on a CPU, where Linux reports it.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}
