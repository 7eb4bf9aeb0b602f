//! Times the point kd-tree (`rt_accel::points`): build, k-NN unbounded and bounded-first
//! (Dammertz claim 25), fixed-radius search, and the caustic histogram's covering search with
//! per-subtree and global radius bounds. Single thread; every figure is the median of
//! `--reps` runs.
//!
//! ```sh
//! cargo run --release -p rt-accel --example points_bench -- [--n 1000000] [--queries 1000000]
//!     [--k 50] [--reps 3] [--set cube|surfaces] [--seed 1]
//! ```
//!
//! `cube`: points uniform in the unit cube. `surfaces`: points on the six faces of the unit
//! cube and a sphere inside it, as photons lie on surfaces. Queries are drawn from the same
//! distribution. The bounded-first radii are multiples of `r_k`, the median distance of the
//! k-th neighbour over the first 1000 queries. The first 200 queries of each search are checked
//! against brute force.

use rt_accel::points::{BruteForcePoints, CoverBound, PointItem, PointKdTree, PointQuery};
use rt_core::glam::Vec3;
use rt_core::rng::SplitMix64;
use std::hint::black_box;
use std::time::Instant;

struct Args {
    n: usize,
    queries: usize,
    k: usize,
    reps: usize,
    set: String,
    seed: u64,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        n: 1_000_000,
        queries: 1_000_000,
        k: 50,
        reps: 3,
        set: "cube".into(),
        seed: 1,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        let num = || {
            value
                .parse::<usize>()
                .map_err(|e| format!("{flag} {value}: {e}"))
        };
        match flag.as_str() {
            "--n" => a.n = num()?,
            "--queries" => a.queries = num()?,
            "--k" => a.k = num()?,
            "--reps" => a.reps = num()?.max(1),
            "--seed" => a.seed = num()? as u64,
            "--set" if value == "cube" || value == "surfaces" => a.set = value,
            _ => return Err(format!("unknown argument {flag} {value}")),
        }
    }
    Ok(a)
}

/// A point of the named distribution.
fn sample(set: &str, rng: &mut SplitMix64) -> Vec3 {
    let u = rng.vec_in(0.0, 1.0);
    if set == "cube" {
        return u;
    }
    // Six faces (area 6) and a sphere of radius 0.3 (area 1.13), by area.
    let pick = rng.range(0.0, 6.0 + 4.0 * std::f32::consts::PI * 0.09);
    if pick < 6.0 {
        let face = pick as usize;
        let mut p = u;
        p[face % 3] = (face / 3) as f32;
        p
    } else {
        Vec3::splat(0.5) + 0.3 * rng.unit_vec()
    }
}

/// CPU time of this thread in seconds: on a shared machine it leaves out the time other
/// processes hold the core (not their effect on the caches). Wall-clock time elsewhere.
#[cfg(target_os = "linux")]
fn cpu_secs() -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec and the clock id is a constant the kernel
    // knows; the call writes nothing else.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

#[cfg(not(target_os = "linux"))]
fn cpu_secs() -> Option<f64> {
    None
}

/// Median wall-clock and thread CPU seconds of `reps` runs of `f`, and its last result.
fn time<T>(reps: usize, mut f: impl FnMut() -> T) -> (Secs, T) {
    let (mut wall, mut cpu) = (Vec::with_capacity(reps), Vec::with_capacity(reps));
    let mut last = None;
    for _ in 0..reps {
        let (t, c) = (Instant::now(), cpu_secs());
        last = Some(black_box(f()));
        let w = t.elapsed().as_secs_f64();
        wall.push(w);
        cpu.push(c.zip(cpu_secs()).map_or(w, |(a, b)| b - a));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[reps / 2]
    };
    let secs = Secs {
        wall: median(&mut wall),
        cpu: median(&mut cpu),
    };
    (secs, last.expect("reps is at least 1"))
}

/// Median timings of one measurement.
#[derive(Clone, Copy)]
struct Secs {
    wall: f64,
    cpu: f64,
}

struct Row {
    name: String,
    secs: Secs,
    per: usize,
    nodes: f64,
    note: String,
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let mut rng = SplitMix64::new(args.seed);
    let items: Vec<PointItem> = (0..args.n)
        .map(|i| PointItem::new(sample(&args.set, &mut rng), i as u32))
        .collect();
    let queries: Vec<Vec3> = (0..args.queries)
        .map(|_| sample(&args.set, &mut rng))
        .collect();
    let mut rows = Vec::new();

    let (secs, tree) = time(args.reps, || {
        PointKdTree::build(&items).expect("finite points")
    });
    tree.validate().expect("valid tree");
    rows.push(Row {
        name: "build".into(),
        secs,
        per: args.n,
        nodes: 0.0,
        note: format!("{} MB", tree.memory_bytes() as f64 / 1e6),
    });

    let k = args.k;
    let mut q = PointQuery::new(k);
    let mut kth: Vec<f32> = queries
        .iter()
        .take(1000)
        .filter_map(|&p| {
            tree.nearest_k(p, k, None, &mut q)
                .last()
                .map(|n| n.dist2.sqrt())
        })
        .collect();
    kth.sort_by(f32::total_cmp);
    let r_k = kth.get(kth.len() / 2).copied().unwrap_or(0.0);

    let brute = BruteForcePoints::new(&items).expect("finite points");
    let checked = queries.len().min(200);
    for &p in &queries[..checked] {
        let want = brute.nearest_k(p, k, None);
        assert_eq!(tree.nearest_k(p, k, None, &mut q), want, "k-NN at {p}");
        assert_eq!(tree.nearest_k_bounded_first(p, k, r_k, None, &mut q), want);
    }

    // Sum of payloads, the same for every k-NN variant.
    let mut knn_sum = None;
    let mut knn = |name: String, initial: Option<f32>, rows: &mut Vec<Row>| {
        let mut q = PointQuery::new(k);
        let (secs, sum) = time(args.reps, || {
            q.reset_stats();
            let mut sum = 0u64;
            for &p in &queries {
                let found = match initial {
                    None => tree.nearest_k(p, k, None, &mut q),
                    Some(r) => tree.nearest_k_bounded_first(p, k, r, None, &mut q),
                };
                sum += found.iter().map(|n| u64::from(n.payload)).sum::<u64>();
            }
            sum
        });
        assert_eq!(*knn_sum.get_or_insert(sum), sum, "{name} differs");
        let s = q.stats();
        rows.push(Row {
            name,
            secs,
            per: queries.len(),
            nodes: s.nodes_visited as f64 / s.queries as f64,
            note: format!(
                "restarts {:.1} %",
                100.0 * s.restarts as f64 / s.queries as f64
            ),
        });
    };
    knn(format!("{k}-NN unbounded"), None, &mut rows);
    for f in [0.5, 1.0, 1.25, 1.5, 2.0, 3.0] {
        knn(
            format!("{k}-NN bounded-first {f} r_k"),
            Some(f * r_k),
            &mut rows,
        );
    }

    let mut found = Vec::new();
    for &p in &queries[..checked] {
        tree.within(p, r_k, &mut q, &mut found);
        found.sort_unstable();
        assert_eq!(found, brute.within(p, r_k), "within at {p}");
    }
    q.reset_stats();
    let (secs, count) = time(args.reps, || {
        let mut count = 0usize;
        for &p in &queries {
            tree.for_each_within(p, r_k, &mut q, |_| count += 1);
        }
        count
    });
    let s = q.stats();
    rows.push(Row {
        name: "within r_k (callback)".into(),
        secs,
        per: queries.len(),
        nodes: s.nodes_visited as f64 / s.queries as f64,
        note: format!("{:.1} found per query", count as f64 / queries.len() as f64),
    });

    // Bins: radius about the spacing (r_1, the median nearest-neighbour distance), and the
    // same with one bin in 1000 twenty times larger, like bins on distant surfaces.
    let mut r1: Vec<f32> = queries
        .iter()
        .take(1000)
        .filter_map(|&p| {
            tree.nearest_k(p, 1, None, &mut q)
                .first()
                .map(|n| n.dist2.sqrt())
        })
        .collect();
    r1.sort_by(f32::total_cmp);
    let r_1 = r1.get(r1.len() / 2).copied().unwrap_or(0.0);
    for outliers in [false, true] {
        let mut rng = SplitMix64::new(args.seed + 1);
        let bins: Vec<PointItem> = items
            .iter()
            .map(|it| {
                let r = if outliers && it.payload % 1000 == 0 {
                    20.0
                } else {
                    rng.range(0.5, 1.5)
                };
                PointItem::with_radius(it.point, it.payload, r * r_1)
            })
            .collect();
        let bin_tree = PointKdTree::build(&bins).expect("finite bins");
        let bin_brute = BruteForcePoints::new(&bins).expect("finite bins");
        let label = if outliers { "bins + 0.1 % x20" } else { "bins" };
        let mut covering_sum = None;
        for bound in [CoverBound::Subtree, CoverBound::Global] {
            let mut q = PointQuery::new(0);
            for &p in &queries[..checked] {
                let got = bin_tree.nearest_covering_with(p, bound, &mut q);
                assert_eq!(got, bin_brute.nearest_covering(p), "covering at {p}");
            }
            q.reset_stats();
            let (secs, (sum, hits)) = time(args.reps, || {
                let (mut sum, mut hits) = (0u64, 0usize);
                for &p in &queries {
                    if let Some(n) = bin_tree.nearest_covering_with(p, bound, &mut q) {
                        sum += u64::from(n.payload);
                        hits += 1;
                    }
                }
                (sum, hits)
            });
            assert_eq!(*covering_sum.get_or_insert(sum), sum);
            let s = q.stats();
            rows.push(Row {
                name: format!("covering, {label}, {bound:?} bound"),
                secs,
                per: queries.len(),
                nodes: s.nodes_visited as f64 / s.queries as f64,
                note: format!(
                    "{:.1} % covered",
                    100.0 * hits as f64 / queries.len() as f64
                ),
            });
        }
    }

    println!(
        "set {}, {} points, {} queries, k = {k}, r_k = {r_k:.5}, r_1 = {r_1:.5}, median of {} runs, 1 thread",
        args.set, args.n, args.queries, args.reps
    );
    println!(
        "{:<42} {:>10} {:>10} {:>10} {:>12}  notes",
        "operation", "wall ms", "cpu ms", "cpu ns/op", "visits/query"
    );
    for r in rows {
        println!(
            "{:<42} {:>10.1} {:>10.1} {:>10.1} {:>12.1}  {}",
            r.name,
            r.secs.wall * 1e3,
            r.secs.cpu * 1e3,
            r.secs.cpu * 1e9 / r.per.max(1) as f64,
            r.nodes,
            r.note
        );
    }
}
