//! Checking a structure against the reference, timing it and counting its traversal work.

use super::{Query, RaySet};
use rayon::prelude::*;
use rt_core::{Accel, Hit, TraversalCounters};
use std::time::Instant;

/// Rays per parallel work item when timing or counting on several threads.
pub const CHUNK: usize = 4096;

/// Relative tolerance of `t` between two structures' closest hits.
pub const T_TOLERANCE: f32 = 1e-5;

/// The outcome of [`check`].
#[derive(Clone, Debug, Default)]
pub struct CheckResult {
    /// Rays compared.
    pub checked: usize,
    /// Rays whose answers differ: hit versus miss, `t` beyond the tolerance, or a different
    /// occlusion answer.
    pub mismatches: usize,
    /// Closest hits on different triangles at the same `t` (coplanar or shared-edge ties):
    /// both answers are right.
    pub ties: usize,
    /// Descriptions of the first few mismatches.
    pub examples: Vec<String>,
}

impl CheckResult {
    /// One line for the progress output.
    pub fn summary(&self) -> String {
        format!(
            "checked {} rays against bvh: {} mismatches, {} ties (same t, other triangle)",
            self.checked, self.mismatches, self.ties
        )
    }
}

enum Verdict {
    Same,
    Tie,
    Differ(String),
}

fn compare_hits(a: Option<Hit>, reference: Option<Hit>) -> Verdict {
    match (a, reference) {
        (None, None) => Verdict::Same,
        (Some(a), Some(r)) => {
            let close = (a.t - r.t).abs() <= T_TOLERANCE * a.t.abs().max(r.t.abs());
            match (close, a.prim == r.prim) {
                (true, true) => Verdict::Same,
                (true, false) => Verdict::Tie,
                (false, _) => Verdict::Differ(format!(
                    "triangle {} at t = {} (bvh: triangle {} at t = {})",
                    a.prim, a.t, r.prim, r.t
                )),
            }
        }
        (a, r) => Verdict::Differ(format!("{a:?} (bvh: {r:?})")),
    }
}

/// Compares `accel` with `reference` on the first `limit` rays of every set, in parallel on
/// the current pool. Closest-hit sets compare `intersect` (same triangle and `t` within
/// [`T_TOLERANCE`], or a tie) and also `occluded(ray, ∞)` with the reference's hit or miss;
/// occlusion sets compare `occluded`.
pub fn check(
    accel: &dyn Accel,
    reference: &dyn Accel,
    sets: &[RaySet],
    limit: usize,
) -> CheckResult {
    let mut result = CheckResult::default();
    for set in sets {
        let rays = &set.rays[..limit.min(set.rays.len())];
        let t_max = set.t_max();
        let verdicts: Vec<(usize, Verdict)> = rays
            .par_iter()
            .enumerate()
            .map(|(i, ray)| {
                let v = match set.query {
                    Query::Closest => {
                        let r = reference.intersect(ray, t_max);
                        let v = compare_hits(accel.intersect(ray, t_max), r);
                        let occluded = accel.occluded(ray, t_max);
                        if matches!(v, Verdict::Differ(_)) || occluded == r.is_some() {
                            v
                        } else {
                            Verdict::Differ(format!(
                                "occluded = {occluded} but bvh's closest hit is {r:?}"
                            ))
                        }
                    }
                    Query::Occluded => {
                        let (a, r) = (accel.occluded(ray, t_max), reference.occluded(ray, t_max));
                        if a == r {
                            Verdict::Same
                        } else {
                            Verdict::Differ(format!("occluded = {a} (bvh: {r})"))
                        }
                    }
                };
                (i, v)
            })
            .collect();
        result.checked += rays.len();
        for (i, v) in verdicts {
            match v {
                Verdict::Same => {}
                Verdict::Tie => result.ties += 1,
                Verdict::Differ(why) => {
                    result.mismatches += 1;
                    if result.examples.len() < 10 {
                        let r = &rays[i];
                        result.examples.push(format!(
                            "{} ray {i} (origin {}, direction {}): {why}",
                            set.name, r.origin, r.dir
                        ));
                    }
                }
            }
        }
    }
    result
}

/// Traces every ray of `set` once; returns the number of hits (or occluded rays).
fn trace(accel: &dyn Accel, set: &RaySet, rays: &[rt_core::Ray]) -> u64 {
    let t_max = set.t_max();
    match set.query {
        Query::Closest => rays
            .iter()
            .filter(|r| accel.intersect(r, t_max).is_some())
            .count() as u64,
        // The segment's far end is the light point, which keys a shadow cache.
        Query::Occluded => rays
            .iter()
            .filter(|r| accel.occluded_toward(r, t_max, r.origin + r.dir * t_max))
            .count() as u64,
    }
}

/// Best of `repeat` runs.
pub struct Timing {
    /// Seconds of the fastest run.
    pub seconds: f64,
    /// Rays that hit something (closest hit) or were occluded.
    pub hits: u64,
}

/// Best of `repeat` runs of `set` on this thread, timed by the thread's CPU time where Linux
/// reports it (`/proc/thread-self/schedstat`) and by wall time elsewhere: on a machine shared
/// with other jobs, wall time also counts the time the thread waited for a core.
pub fn time_cpu(accel: &dyn Accel, set: &RaySet, repeat: u32) -> Timing {
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..repeat {
        let (cpu, wall) = (thread_cpu_seconds(), Instant::now());
        hits = trace(accel, set, &set.rays);
        let seconds = match (cpu, thread_cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => wall.elapsed().as_secs_f64(),
        };
        best = best.min(seconds);
    }
    Timing {
        seconds: best.max(1e-9),
        hits,
    }
}

/// Seconds this thread has run on a CPU, where Linux reports it.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Times `set`: a plain loop on this thread without a pool, `par_chunks` of [`CHUNK`] rays on
/// `pool` with one.
pub fn time(
    accel: &dyn Accel,
    set: &RaySet,
    pool: Option<&rayon::ThreadPool>,
    repeat: u32,
) -> Timing {
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..repeat {
        let t = Instant::now();
        hits = match pool {
            None => trace(accel, set, &set.rays),
            Some(pool) => pool.install(|| {
                set.rays
                    .par_chunks(CHUNK)
                    .map(|c| trace(accel, set, c))
                    .sum()
            }),
        };
        best = best.min(t.elapsed().as_secs_f64());
    }
    Timing {
        seconds: best.max(1e-9),
        hits,
    }
}

/// Traversal work of one pass over `set` (closest-hit or any-hit queries, as the set is
/// traced), or `None` if `accel` does not count.
pub fn count(accel: &dyn Accel, set: &RaySet) -> Option<TraversalCounters> {
    if !accel.counts_traversal() {
        return None;
    }
    let t_max = set.t_max();
    let total = set
        .rays
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut c = TraversalCounters::default();
            for r in chunk {
                match set.query {
                    Query::Closest => {
                        accel.closest_hit(r, t_max, Some(&mut c));
                    }
                    Query::Occluded => {
                        let target = r.origin + r.dir * t_max;
                        accel.any_hit(r, t_max, Some(target), Some(&mut c));
                    }
                }
            }
            c
        })
        .reduce(TraversalCounters::default, |mut a, b| {
            a += b;
            a
        });
    Some(total)
}
