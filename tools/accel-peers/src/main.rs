//! Side-by-side benchmark of our acceleration structures (rt-accel, through `AccelSpec` and the
//! `Accel` trait) and other Rust BVH crates (obvhs, bvh) on the same ray files. See README.md.

mod bvh_peer;
mod embree_peer;
mod mesh;
mod obvhs_peer;
mod ours;
mod peer;

use anyhow::{Context, Result};
use clap::Parser;
use peer::{Peer, Work};
use rayon::prelude::*;
use rt_accel::bench::{read_rays, Query, SET_NAMES};
use rt_core::Ray;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A structure fails the check when more than this fraction of its checked rays disagree with
/// our `bvh` (as in `render bench-accel`).
const MAX_MISMATCH_FRACTION: f64 = 1e-3;

/// Benchmark rt-accel's structures against obvhs, the bvh crate and Embree on identical rays.
#[derive(Parser, Debug)]
#[command(name = "accel-peers")]
struct Args {
    /// Wavefront OBJ mesh (triangles in the order our loader reads them).
    mesh: PathBuf,
    /// Directory of primary.bin, incoherent.bin, shadow.bin, uniform.bin, as written by
    /// `render bench-accel MESH --dump-rays DIR` (missing sets are skipped).
    #[arg(long)]
    rays: PathBuf,
    /// Our structures: AccelSpec strings (`bvh8`, `qbvh`, `bvh`, `qbvh:order=distance`, ...).
    #[arg(long, value_delimiter = ',', default_value = "bvh8,qbvh,bvh")]
    accel: Vec<String>,
    /// Peer structures: obvhs-bvh2, obvhs-cwbvh (optionally `:fastest|fast|medium|slow`
    /// build preset, default medium), bvh-crate, bvh-crate-flat, embree, embree:high (needs
    /// --embree-lib). `none` for none.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "obvhs-bvh2,obvhs-cwbvh,bvh-crate,bvh-crate-flat"
    )]
    peers: Vec<String>,
    /// Embree 4's shared library for the `embree` peers (default: $EMBREE_LIB). The embreex
    /// wheel carries one: `pip install embreex`, then site-packages/embreex.libs/libembree4*.
    #[arg(long, value_name = "PATH")]
    embree_lib: Option<PathBuf>,
    /// Threads of the multi-threaded runs (default: all cores). Builds and traces run once
    /// with 1 thread and, if N > 1, once with N.
    #[arg(long)]
    threads: Option<usize>,
    /// Write the results as CSV here.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Check every structure's answers against ours (`bvh`) on this many rays of each set
    /// before timing; more than 0.1 % disagreeing stops the benchmark.
    #[arg(long, default_value_t = 10_000)]
    check: usize,
    /// Timed rounds: each round traces every set once with every structure, in turn, so that
    /// load drift hits all of them alike. The median round is reported (and the best).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Write our `bvh`'s answers for every ray to this directory: NAME.t.f32 (closest t,
    /// +inf on a miss), NAME.prim.u32 (u32::MAX on a miss) and shadow.occluded.u8.
    #[arg(long)]
    dump_hits: Option<PathBuf>,
}

/// One ray set read from the ray directory.
struct RaySet {
    name: &'static str,
    shadow: bool,
    rays: Vec<Ray>,
}

/// One output row.
struct Row {
    accel: String,
    rays: &'static str,
    threads: usize,
    build_ms: f64,
    /// CPU time of the build (1-thread rows).
    build_cpu_ms: Option<f64>,
    bytes: Option<usize>,
    /// Median round.
    mrays_per_s: f64,
    /// Fastest round.
    mrays_best: f64,
    /// Rays per CPU-second of the tracing thread, median round (1-thread rows).
    mrays_per_cpu_s: Option<f64>,
    hits: usize,
    work: [Option<f64>; 3],
}

/// What a query answered, for the correctness check.
#[derive(Clone, Copy, PartialEq)]
enum Answer {
    Closest(Option<(f32, u32)>),
    Occluded(bool),
}

fn t_max(shadow: bool) -> f32 {
    if shadow {
        Query::Occluded.t_max()
    } else {
        Query::Closest.t_max()
    }
}

fn answer(p: &dyn Peer, ray: &Ray, shadow: bool) -> Answer {
    let t_max = t_max(shadow);
    if shadow {
        Answer::Occluded(p.occluded(ray, t_max))
    } else {
        Answer::Closest(p.closest(ray, t_max))
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    embree_peer::set_library(args.embree_lib.clone());
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let t0 = Instant::now();
    let tris = mesh::load_obj(&args.mesh)?;
    eprintln!(
        "{}: {} triangles, loaded in {:.2} s",
        args.mesh.display(),
        tris.len(),
        t0.elapsed().as_secs_f64()
    );
    let sets = read_sets(&args.rays)?;
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build();
    let pools = if threads > 1 {
        vec![(1, pool(1)?), (threads, pool(threads)?)]
    } else {
        vec![(1, pool(1)?)]
    };
    let all = pools.last().map(|p| &p.1).context("no thread pool")?;

    // Reference answers from our binary BVH.
    let reference = all.install(|| peer::build("bvh", &tris))?;
    let expected: Vec<Vec<Answer>> = all.install(|| {
        sets.iter()
            .map(|s| {
                let n = args.check.min(s.rays.len());
                s.rays[..n]
                    .par_iter()
                    .map(|r| answer(&*reference, r, s.shadow))
                    .collect()
            })
            .collect()
    });
    if let Some(dir) = &args.dump_hits {
        all.install(|| dump_hits(dir, &*reference, &sets))?;
    }
    drop(reference);

    let names: Vec<&String> = args
        .accel
        .iter()
        .chain(args.peers.iter().filter(|p| *p != "none"))
        .collect();
    if names.iter().any(|n| n.starts_with("embree")) {
        // Opening the library (and starting TBB) is not part of any build time.
        embree_peer::preload()?;
    }
    let mut rows = Vec::new();
    let mut checks = String::new();
    let mut work: Vec<Vec<[Option<f64>; 3]>> = Vec::new();
    for (n, pool) in &pools {
        // Build everything on this pool.
        let mut built = Vec::new();
        for name in &names {
            let (start, cpu) = (Instant::now(), pool.install(thread_cpu_seconds));
            let p = pool.install(|| peer::build(name, &tris))?;
            let build_ms = start.elapsed().as_secs_f64() * 1e3;
            // On one thread the whole build ran on the pool's one worker (Embree: its own
            // single TBB thread, so the CPU time is not seen here).
            let build_cpu_ms = (*n == 1 && !name.starts_with("embree"))
                .then(|| (pool.install(thread_cpu_seconds) - cpu) * 1e3);
            eprintln!("{name}: built in {build_ms:.1} ms on {n} thread(s)");
            built.push((p, build_ms, build_cpu_ms));
        }
        // Checked and counted once, on the first (1-thread) builds, before any timing.
        if work.is_empty() {
            for (p, ..) in &built {
                for (s, exp) in sets.iter().zip(&expected) {
                    let (line, wrong) = check(&**p, s, exp);
                    eprintln!("{line}");
                    let _ = writeln!(checks, "{line}");
                    anyhow::ensure!(
                        wrong as f64 <= MAX_MISMATCH_FRACTION * exp.len().max(1) as f64,
                        "{}: {wrong} of {} {} rays disagree with our bvh",
                        p.name(),
                        exp.len(),
                        s.name
                    );
                }
                work.push(all.install(|| sets.iter().map(|s| mean_work(&**p, s)).collect()));
            }
        }
        // Interleaved rounds: every structure on every set, in turn.
        let mut timings: Vec<Vec<Vec<Timing>>> = vec![vec![Vec::new(); sets.len()]; built.len()];
        for round in 0..args.runs.max(1) {
            for (i, (p, ..)) in built.iter().enumerate() {
                for (k, s) in sets.iter().enumerate() {
                    timings[i][k].push(pool.install(|| trace(&**p, s, *n)));
                }
            }
            eprintln!(
                "{n} thread(s): round {} of {} done",
                round + 1,
                args.runs.max(1)
            );
        }
        for (i, (p, build_ms, build_cpu_ms)) in built.iter().enumerate() {
            for (k, s) in sets.iter().enumerate() {
                let runs = &timings[i][k];
                let mrays = |secs: f64| s.rays.len() as f64 / secs / 1e6;
                let wall = median(runs.iter().map(|r| r.wall).collect());
                let best = runs.iter().map(|r| r.wall).fold(f64::INFINITY, f64::min);
                let cpu: Vec<f64> = runs.iter().filter_map(|r| r.cpu).collect();
                rows.push(Row {
                    accel: names[i].clone(),
                    rays: s.name,
                    threads: *n,
                    build_ms: *build_ms,
                    build_cpu_ms: *build_cpu_ms,
                    bytes: p.bytes(),
                    mrays_per_s: mrays(wall),
                    mrays_best: mrays(best),
                    mrays_per_cpu_s: (!cpu.is_empty()).then(|| mrays(median(cpu))),
                    hits: runs[0].hits,
                    work: work[i][k],
                });
            }
        }
    }

    print!("{}", table(&args, &tris, &sets, &rows));
    if let Some(v) = names
        .iter()
        .any(|n| n.starts_with("embree"))
        .then(embree_peer::version)
        .flatten()
    {
        println!("embree: Embree {v}, single-ray API (rtcIntersect1 / rtcOccluded1); embree@8: rtcIntersect8 / rtcOccluded8 on consecutive rays, in chunks of {STREAM_CHUNK}");
    }
    println!(
        "\nCheck against ours (bvh), first {} rays of each set:",
        args.check
    );
    print!("{checks}");
    if let Some(path) = &args.csv {
        std::fs::write(path, csv(&rows))
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn read_sets(dir: &Path) -> Result<Vec<RaySet>> {
    let mut sets = Vec::new();
    for name in SET_NAMES {
        let path = dir.join(format!("{name}.bin"));
        if path.exists() {
            sets.push(RaySet {
                name,
                shadow: Query::of_set(name) == Query::Occluded,
                rays: read_rays(&path)?,
            });
        } else {
            eprintln!("note: {} is missing, skipping that set", path.display());
        }
    }
    anyhow::ensure!(!sets.is_empty(), "no ray files in {}", dir.display());
    Ok(sets)
}

/// CPU time of the calling thread in seconds: on a shared machine it excludes the time the
/// thread waited for a core, which wall time does not.
fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_THREAD_CPUTIME_ID is always supported
    // on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// One timed pass over a set.
#[derive(Clone)]
struct Timing {
    /// Wall-clock seconds.
    wall: f64,
    /// CPU seconds of the tracing thread (1-thread runs only).
    cpu: Option<f64>,
    /// Closest hits, or occluded rays.
    hits: usize,
}

/// Traces a whole set on the current pool.
fn trace(p: &dyn Peer, s: &RaySet, threads: usize) -> Timing {
    let t_max = t_max(s.shadow);
    let one = |r: &Ray| -> usize {
        if s.shadow {
            p.occluded(r, t_max) as usize
        } else {
            p.closest(r, t_max).is_some() as usize
        }
    };
    if p.is_stream() {
        return trace_stream(p, s, threads);
    }
    if threads == 1 {
        let (start, cpu) = (Instant::now(), thread_cpu_seconds());
        let hits = s.rays.iter().map(one).sum();
        Timing {
            wall: start.elapsed().as_secs_f64(),
            cpu: Some(thread_cpu_seconds() - cpu),
            hits,
        }
    } else {
        let start = Instant::now();
        let hits = s
            .rays
            .par_chunks(256)
            .map(|c| c.iter().map(one).sum::<usize>())
            .sum();
        Timing {
            wall: start.elapsed().as_secs_f64(),
            cpu: None,
            hits,
        }
    }
}

/// Rays per stream call of a streaming peer: a wavefront stage's worth.
const STREAM_CHUNK: usize = 4096;

/// Answers of a streaming peer for `rays`, in chunks of [`STREAM_CHUNK`].
fn stream_answers(p: &dyn Peer, rays: &[Ray], shadow: bool) -> Vec<Answer> {
    let t_max = t_max(shadow);
    if shadow {
        let mut out = vec![false; rays.len()];
        for (r, o) in rays.chunks(STREAM_CHUNK).zip(out.chunks_mut(STREAM_CHUNK)) {
            p.occluded_stream(r, t_max, o);
        }
        out.into_iter().map(Answer::Occluded).collect()
    } else {
        let mut out = vec![None; rays.len()];
        for (r, o) in rays.chunks(STREAM_CHUNK).zip(out.chunks_mut(STREAM_CHUNK)) {
            p.closest_stream(r, t_max, o);
        }
        out.into_iter().map(Answer::Closest).collect()
    }
}

/// [`trace`] for a streaming peer: chunks of [`STREAM_CHUNK`] rays per call, into buffers made
/// before the clock starts.
fn trace_stream(p: &dyn Peer, s: &RaySet, threads: usize) -> Timing {
    let t_max = t_max(s.shadow);
    let chunk = |rays: &[Ray], occ: &mut Vec<bool>, hit: &mut Vec<Option<(f32, u32)>>| {
        if s.shadow {
            p.occluded_stream(rays, t_max, &mut occ[..rays.len()]);
            occ[..rays.len()].iter().filter(|&&o| o).count()
        } else {
            p.closest_stream(rays, t_max, &mut hit[..rays.len()]);
            hit[..rays.len()].iter().filter(|h| h.is_some()).count()
        }
    };
    if threads == 1 {
        let (mut occ, mut hit) = (vec![false; STREAM_CHUNK], vec![None; STREAM_CHUNK]);
        let (start, cpu) = (Instant::now(), thread_cpu_seconds());
        let hits = s
            .rays
            .chunks(STREAM_CHUNK)
            .map(|r| chunk(r, &mut occ, &mut hit))
            .sum();
        Timing {
            wall: start.elapsed().as_secs_f64(),
            cpu: Some(thread_cpu_seconds() - cpu),
            hits,
        }
    } else {
        let start = Instant::now();
        let hits = s
            .rays
            .par_chunks(STREAM_CHUNK)
            .map(|r| chunk(r, &mut vec![false; r.len()], &mut vec![None; r.len()]))
            .sum();
        Timing {
            wall: start.elapsed().as_secs_f64(),
            cpu: None,
            hits,
        }
    }
}

/// Mean work per ray over the whole set (boxes, leaves, triangles), where the structure counts.
fn mean_work(p: &dyn Peer, s: &RaySet) -> [Option<f64>; 3] {
    let t_max = t_max(s.shadow);
    let add = |a: Option<u64>, b: Option<u64>| a.zip(b).map(|(a, b)| a + b);
    let total = s
        .rays
        .par_iter()
        .map(|r| p.work(r, t_max, s.shadow))
        .reduce(
            || Work {
                boxes: Some(0),
                leaves: Some(0),
                tris: Some(0),
            },
            |a, b| Work {
                boxes: add(a.boxes, b.boxes),
                leaves: add(a.leaves, b.leaves),
                tris: add(a.tris, b.tris),
            },
        );
    let n = s.rays.len().max(1) as f64;
    [total.boxes, total.leaves, total.tris].map(|c| c.map(|c| c as f64 / n))
}

/// Compares a structure's answers with the reference's; one report line.
fn check(p: &dyn Peer, s: &RaySet, expected: &[Answer]) -> (String, usize) {
    let (mut wrong, mut other_prim) = (0, 0);
    let answers: Vec<Answer> = if p.is_stream() {
        stream_answers(p, &s.rays[..expected.len()], s.shadow)
    } else {
        s.rays[..expected.len()]
            .iter()
            .map(|r| answer(p, r, s.shadow))
            .collect()
    };
    for (a, exp) in answers.into_iter().zip(expected) {
        match (a, *exp) {
            (Answer::Closest(Some((t, prim))), Answer::Closest(Some((te, prim_e)))) => {
                if (t - te).abs() > 1e-4 * te.abs() {
                    wrong += 1;
                } else if prim != prim_e {
                    other_prim += 1;
                }
            }
            (a, e) if a != e => wrong += 1,
            _ => {}
        }
    }
    let line = format!(
        "  {:<28} {:<10} {:>6} of {:>6} differ (hit/miss or t beyond 1e-4 relative){}",
        p.name(),
        s.name,
        wrong,
        expected.len(),
        if other_prim > 0 {
            format!("; {other_prim} same t, other triangle")
        } else {
            String::new()
        }
    );
    (line, wrong)
}

fn dump_hits(dir: &Path, reference: &dyn Peer, sets: &[RaySet]) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    for s in sets {
        let answers: Vec<Answer> = s
            .rays
            .par_iter()
            .map(|r| answer(reference, r, s.shadow))
            .collect();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for ans in answers {
            match ans {
                Answer::Closest(h) => {
                    a.extend_from_slice(&h.map_or(f32::INFINITY, |h| h.0).to_le_bytes());
                    b.extend_from_slice(&h.map_or(u32::MAX, |h| h.1).to_le_bytes());
                }
                Answer::Occluded(o) => a.push(o as u8),
            }
        }
        if s.shadow {
            std::fs::write(dir.join(format!("{}.occluded.u8", s.name)), a)?;
        } else {
            std::fs::write(dir.join(format!("{}.t.f32", s.name)), a)?;
            std::fs::write(dir.join(format!("{}.prim.u32", s.name)), b)?;
        }
    }
    eprintln!("wrote our bvh's answers to {}", dir.display());
    Ok(())
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or(String::new(), |x| format!("{x:.digits$}"))
}

fn table(args: &Args, tris: &[[rt_core::glam::Vec3; 3]], sets: &[RaySet], rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "\n{} ({} triangles)", args.mesh.display(), tris.len());
    for s in sets {
        let _ = writeln!(out, "  {}: {} rays", s.name, s.rays.len());
    }
    let _ = writeln!(
        out,
        "\n{:<28} {:<10} {:>3} {:>9} {:>9} {:>11} {:>7} {:>9} {:>9} {:>9} {:>8} {:>7} {:>7} {:>7}",
        "accel",
        "rays",
        "thr",
        "build ms",
        "(CPU)",
        "bytes",
        "B/tri",
        "Mrays/s",
        "(best)",
        "(CPU)",
        "hits",
        "boxes",
        "leaves",
        "tris"
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{:<28} {:<10} {:>3} {:>9.1} {:>9} {:>11} {:>7} {:>9.3} {:>9.3} {:>9} {:>8} {:>7} {:>7} {:>7}",
            r.accel,
            r.rays,
            r.threads,
            r.build_ms,
            opt(r.build_cpu_ms, 1),
            r.bytes.map_or(String::new(), |b| b.to_string()),
            opt(r.bytes.map(|b| b as f64 / tris.len() as f64), 1),
            r.mrays_per_s,
            r.mrays_best,
            opt(r.mrays_per_cpu_s, 3),
            r.hits,
            opt(r.work[0], 1),
            opt(r.work[1], 1),
            opt(r.work[2], 1),
        );
    }
    out
}

fn csv(rows: &[Row]) -> String {
    let mut out = String::from(
        "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,leaves_per_ray,tris_per_ray,mrays_per_cpu_s,build_cpu_ms,mrays_best\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{:.2},{},{:.4},{},{},{},{},{},{},{:.4}",
            r.accel,
            r.rays,
            r.threads,
            r.build_ms,
            r.bytes.map_or(String::new(), |b| b.to_string()),
            r.mrays_per_s,
            r.hits,
            opt(r.work[0], 2),
            opt(r.work[1], 2),
            opt(r.work[2], 2),
            opt(r.mrays_per_cpu_s, 4),
            opt(r.build_cpu_ms, 2),
            r.mrays_best,
        );
    }
    out
}
