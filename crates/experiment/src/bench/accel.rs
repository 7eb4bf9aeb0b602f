//! One scene, several structures: build, check against the binary BVH, time every ray set on
//! 1 and N threads, count traversal work.
//!
//! The steps: the scene ([`super::input`]); the ray sets of `rt_accel::bench`, generated once
//! with the binary BVH (primary, incoherent diffuse bounces, shadow segments, uniform random
//! rays) or read from a ray file, optionally dumped to files; per structure the build, the
//! check on the first `check` rays of every set, the timed runs and one counted pass; the
//! [`Row`]s, shown by [`table`] and [`csv`].

use super::input::{self, View};
use super::table::aligned;
use super::BenchError;
use crate::csv::field;
use rt_accel::bench::{self as rays, measure, RaySet};
use rt_accel::AccelSpec;
use rt_core::TraversalCounters;
use std::path::PathBuf;
use std::time::Instant;

/// A structure fails the check when more than this fraction of the checked rays disagree with
/// the binary BVH (a handful may differ legitimately: a ray grazing a shared edge in the
/// crack-free test modes, or a nearly degenerate triangle whose `t` is noisy).
pub const MAX_MISMATCH_FRACTION: f64 = 1e-3;

/// Which generated ray sets to trace.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RaySets {
    /// One jittered camera ray per pixel.
    pub primary: bool,
    /// A cosine-distributed diffuse bounce from each primary hit.
    pub incoherent: bool,
    /// A segment from each primary hit to a point on a light.
    pub shadow: bool,
    /// Origins uniform in the bounds, directions uniform on the sphere.
    pub uniform: bool,
}

impl RaySets {
    /// All four.
    pub const ALL: Self = Self {
        primary: true,
        incoherent: true,
        shadow: true,
        uniform: true,
    };

    /// True if any set is wanted.
    pub fn any(&self) -> bool {
        self.primary || self.incoherent || self.shadow || self.uniform
    }

    /// The sets `names` asks for (`file`, the ray file's set, is allowed when `file` is true
    /// and traced anyway); without names all four, or none when there is a ray file.
    pub fn from_names(names: Option<&[String]>, file: bool) -> Result<Self, RaySetError> {
        let Some(names) = names else {
            return Ok(if file { Self::default() } else { Self::ALL });
        };
        let mut w = Self::default();
        for n in names {
            match n.trim() {
                "primary" => w.primary = true,
                "incoherent" => w.incoherent = true,
                "shadow" => w.shadow = true,
                "uniform" => w.uniform = true,
                "file" if file => {}
                "file" => return Err(RaySetError::NoRayFile),
                other => return Err(RaySetError::Unknown(other.to_string())),
            }
        }
        if !w.any() && !file {
            return Err(RaySetError::None);
        }
        Ok(w)
    }
}

/// Ray set names that do not make a benchmark.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RaySetError {
    /// A name of no set.
    #[error("unknown ray set \"{0}\" (expected primary, incoherent, shadow, uniform or file)")]
    Unknown(String),
    /// The set `file` without a ray file.
    #[error("the set file needs a ray file")]
    NoRayFile,
    /// No set at all.
    #[error("no ray set given")]
    None,
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct AccelBench {
    /// A `.toml` scene, a mesh file or `gen:NAME`.
    pub input: String,
    /// The structures, the first the baseline of the speedups.
    pub specs: Vec<AccelSpec>,
    /// The generated ray sets.
    pub sets: RaySets,
    /// A ray set read from a file (`rt_accel::bench::read_set`), traced after the generated.
    pub file_rays: Option<RaySet>,
    /// Threads of the parallel runs (every set is also timed on one thread).
    pub threads: usize,
    /// Primary ray grid; missing sides follow the camera's aspect ratio.
    pub width: Option<u32>,
    /// See `width`.
    pub height: Option<u32>,
    /// A scene's camera by name (the first by default).
    pub camera: Option<String>,
    /// The automatic camera of a mesh file (outside by default).
    pub view: Option<View>,
    /// Seed of the jitter, bounce and light samples.
    pub seed: u64,
    /// Where to write the generated rays.
    pub dump_rays: Option<PathBuf>,
    /// Rays of every set checked against the binary BVH; 0 skips the check.
    pub check: usize,
    /// Timed repetitions; the fastest counts.
    pub repeat: u32,
    /// Time one-thread runs by the thread's CPU time (Linux).
    pub cpu_time: bool,
}

/// One measurement: a structure, a ray set, a thread count.
#[derive(Clone, Debug)]
pub struct Row {
    /// Canonical spec of the structure.
    pub accel: String,
    /// Name of the ray set.
    pub rays: String,
    /// Threads of the run.
    pub threads: usize,
    /// Build time of the structure (one build, on the parallel pool).
    pub build_ms: f64,
    /// `Accel::memory_bytes` after the runs.
    pub bytes: usize,
    /// `Accel::structure_bytes` after the runs: the part of `bytes` beyond one copy of the
    /// triangles' vertices.
    pub structure_bytes: Option<usize>,
    /// Rays in the set.
    pub ray_count: usize,
    /// Best time over the repetitions.
    pub seconds: f64,
    /// Rays that hit (closest-hit sets) or were occluded (occlusion sets).
    pub hits: u64,
    /// Traversal work of one counted pass, if the structure counts.
    pub counters: Option<TraversalCounters>,
    /// Triangles of the scene.
    pub triangles: usize,
    /// The input's name.
    pub scene: String,
    /// Check against the binary BVH (per structure): rays that disagree.
    pub mismatches: usize,
    /// Check: rays whose distances tie.
    pub ties: usize,
}

/// Runs the benchmark; `info` gets the progress lines.
pub fn run(bench: AccelBench, info: &dyn Fn(&str)) -> Result<Vec<Row>, BenchError> {
    let t = Instant::now();
    let input = input::load(&bench.input, bench.camera.as_deref())?;
    for w in &input.warnings {
        info(&format!("warning: {w}"));
    }
    if bench.view.is_some() && !input.is_mesh {
        return Err(BenchError::ViewOfScene { input: input.name });
    }
    let scene = &input.scene;
    info(&format!(
        "{}: {} triangles, loaded in {:.2} s",
        input.name,
        scene.triangle_count(),
        t.elapsed().as_secs_f64()
    ));
    let pool = rt_session::job::thread_pool(Some(bench.threads))?;

    // The reference every structure is checked against, which also generates the rays.
    let reference_spec: AccelSpec = "bvh".parse().expect("static spec");
    let t = Instant::now();
    let reference = pool
        .install(|| reference_spec.build(&scene.triangles))
        .map_err(|e| BenchError::Build {
            input: bench.input.clone(),
            spec: reference_spec.to_string(),
            message: e.to_string(),
        })?;
    let reference_ms = t.elapsed().as_secs_f64() * 1e3;

    let (camera, fallback_light) = match bench.view {
        Some(View::Inside) if input.is_mesh => {
            rt_scene::views::inside_view(&input.bounds, reference.as_ref())
        }
        _ => (input.camera.clone(), input.fallback_light),
    };

    let mut sets: Vec<RaySet> = Vec::new();
    if bench.sets.any() || bench.dump_rays.is_some() {
        let (width, height) = input::resolution(&camera, bench.width, bench.height)?;
        let camera = camera.resized(width, height);
        let lights = rays::Lights::of(scene, fallback_light);
        info(&format!("shadow rays aim at {}", lights.describe()));
        let t = Instant::now();
        let generated = pool
            .install(|| rays::generate(scene, &camera, reference.as_ref(), &lights, bench.seed));
        info(&format!(
            "rays: {} primary ({width}x{height}), {} incoherent, {} shadow, {} uniform, generated \
             in {:.2} s",
            generated.primary.rays.len(),
            generated.incoherent.rays.len(),
            generated.shadow.rays.len(),
            generated.uniform.rays.len(),
            t.elapsed().as_secs_f64()
        ));
        if let Some(dir) = &bench.dump_rays {
            rays::dump(dir, &generated)?;
            info(&format!("rays written to {}", dir.display()));
        }
        let w = bench.sets;
        let on = [w.primary, w.incoherent, w.shadow, w.uniform];
        for (set, on) in generated.into_sets().into_iter().zip(on) {
            if on {
                sets.push(set);
            }
        }
    }
    if let Some(set) = bench.file_rays {
        sets.push(set);
    }
    if let Some(empty) = sets.iter().find(|s| s.rays.is_empty()) {
        return Err(BenchError::Input {
            input: input.name.clone(),
            message: format!("no {} rays (does the camera see any geometry?)", empty.name),
        });
    }

    let mut rows = Vec::new();
    for spec in &bench.specs {
        let name = spec.to_string();
        let reuse = *spec == reference_spec;
        let (fresh, build_ms) = if reuse {
            (None, reference_ms)
        } else {
            let t = Instant::now();
            // From the scene, so two-level kinds place its instances (over bare triangles they
            // would be one static object); every kind keeps the triangle order the rays use.
            let a = pool
                .install(|| spec.build(scene))
                .map_err(|e| BenchError::Build {
                    input: bench.input.clone(),
                    spec: name.clone(),
                    message: e.to_string(),
                })?;
            (Some(a), t.elapsed().as_secs_f64() * 1e3)
        };
        let accel = fresh.as_deref().unwrap_or(reference.as_ref());
        info(&format!("{name}: built in {build_ms:.1} ms"));
        let check = if reuse {
            measure::CheckResult::default()
        } else {
            let c = pool.install(|| measure::check(accel, reference.as_ref(), &sets, bench.check));
            info(&format!("{name}: {}", c.summary()));
            for line in c.examples.iter().take(3) {
                info(&format!("  {line}"));
            }
            if c.mismatches as f64 > MAX_MISMATCH_FRACTION * c.checked.max(1) as f64 {
                return Err(BenchError::Check {
                    spec: name,
                    mismatches: c.mismatches,
                    checked: c.checked,
                    percent: MAX_MISMATCH_FRACTION * 100.0,
                });
            }
            c
        };
        for set in &sets {
            let threads = bench.threads;
            let thread_counts: &[usize] = if threads == 1 { &[1] } else { &[1, threads] };
            let first_row = rows.len();
            for &n in thread_counts {
                let timing = if n == 1 && bench.cpu_time {
                    measure::time_cpu(accel, set, bench.repeat)
                } else {
                    measure::time(accel, set, (n > 1).then_some(&pool), bench.repeat)
                };
                info(&format!(
                    "{name}: {} rays, {n} thread{}: {:.2} Mrays/s",
                    set.name,
                    if n == 1 { "" } else { "s" },
                    set.rays.len() as f64 / timing.seconds / 1e6
                ));
                rows.push(Row {
                    accel: name.clone(),
                    rays: set.name.to_string(),
                    threads: n,
                    build_ms,
                    bytes: 0, // filled in below, after the runs (the lazy QBVH grows)
                    structure_bytes: None,
                    ray_count: set.rays.len(),
                    seconds: timing.seconds,
                    hits: timing.hits,
                    counters: None, // filled in below, after the timed runs
                    triangles: scene.triangle_count(),
                    scene: input.name.clone(),
                    mismatches: check.mismatches,
                    ties: check.ties,
                });
            }
            // Counted after the timed runs, so that with `check = 0, repeat = 1` the first
            // timed run is the structure's first pass (the on-demand QBVH builds its groups in
            // it rather than in the counting pass).
            let counted = pool.install(|| measure::count(accel, set));
            for r in &mut rows[first_row..] {
                r.counters = counted;
            }
        }
        let (bytes, structure_bytes) = (accel.memory_bytes(), accel.structure_bytes());
        for r in rows.iter_mut().filter(|r| r.accel == name) {
            r.bytes = bytes;
            r.structure_bytes = structure_bytes;
        }
    }
    Ok(rows)
}

impl Row {
    fn mrays(&self) -> f64 {
        self.ray_count as f64 / self.seconds / 1e6
    }

    fn per_ray(&self, f: impl Fn(&TraversalCounters) -> u64) -> Option<f64> {
        self.counters
            .as_ref()
            .map(|c| f(c) as f64 / self.ray_count.max(1) as f64)
    }

    fn bytes_per_tri(&self) -> f64 {
        self.bytes as f64 / self.triangles.max(1) as f64
    }

    fn structure_per_tri(&self) -> Option<f64> {
        self.structure_bytes
            .map(|b| b as f64 / self.triangles.max(1) as f64)
    }

    /// Mrays/s relative to the first structure's on the same set and thread count.
    fn speedup(&self, rows: &[Row]) -> Option<f64> {
        let first = &rows.first()?.accel;
        let base = rows
            .iter()
            .find(|r| &r.accel == first && r.rays == self.rays && r.threads == self.threads)?;
        Some(self.mrays() / base.mrays())
    }
}

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.decimals$}"))
}

/// The table: build time and memory on each structure's first row, then per set and thread
/// count the speed, the hits and the traversal work per ray. Empty without rows.
pub fn table(rows: &[Row], threads: usize) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = format!(
        "{}: {} triangles; Mrays/s best of the repetitions, on 1 and {threads} threads\n",
        first.scene, first.triangles
    );
    let header = [
        "accel",
        "build ms",
        "MiB",
        "B/tri",
        "struct B/tri",
        "rays",
        "count",
        "threads",
        "Mrays/s",
        "speedup",
        "hits %",
        "boxes/ray",
        "leaves/ray",
        "tris/ray",
    ];
    let mut cells: Vec<Vec<String>> = vec![header.iter().map(|s| s.to_string()).collect()];
    let mut last_accel = "";
    for r in rows {
        let new_accel = r.accel != last_accel;
        last_accel = &r.accel;
        let once = |s: String| if new_accel { s } else { String::new() };
        cells.push(vec![
            once(r.accel.clone()),
            once(format!("{:.1}", r.build_ms)),
            once(format!("{:.1}", r.bytes as f64 / (1u64 << 20) as f64)),
            once(format!("{:.1}", r.bytes_per_tri())),
            once(opt(r.structure_per_tri(), 2)),
            r.rays.clone(),
            r.ray_count.to_string(),
            r.threads.to_string(),
            format!("{:.2}", r.mrays()),
            opt(r.speedup(rows), 2),
            format!("{:.1}", 100.0 * r.hits as f64 / r.ray_count.max(1) as f64),
            opt(r.per_ray(|c| c.nodes_visited), 1),
            opt(r.per_ray(|c| c.leaves_visited), 2),
            opt(r.per_ray(|c| c.prims_tested), 2),
        ]);
    }
    out += &aligned(&cells, &[0, 5]);
    out += &format!(
        "speedup: Mrays/s over {}'s on the same rays and threads; MiB and B/tri: all the \
         structure's memory; struct B/tri: beyond one copy of the triangles (36 B each)\n",
        first.accel
    );
    out
}

/// The CSV header. The first ten columns are the interface of issue 3; the rest are extras.
pub const CSV_HEADER: &str = "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,\
leaves_per_ray,tris_per_ray,scene,triangles,bytes_per_tri,ray_count,seconds,check_mismatches,\
check_ties,structure_bytes,structure_bytes_per_tri";

/// [`CSV_HEADER`] and one line per row; empty traversal columns when a structure does not
/// count.
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    let num = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for r in rows {
        let line = [
            field(&r.accel),
            field(&r.rays),
            r.threads.to_string(),
            format!("{:.3}", r.build_ms),
            r.bytes.to_string(),
            format!("{:.4}", r.mrays()),
            r.hits.to_string(),
            num(r.per_ray(|c| c.nodes_visited)),
            num(r.per_ray(|c| c.leaves_visited)),
            num(r.per_ray(|c| c.prims_tested)),
            field(&r.scene),
            r.triangles.to_string(),
            format!("{:.2}", r.bytes_per_tri()),
            r.ray_count.to_string(),
            format!("{:.6}", r.seconds),
            r.mismatches.to_string(),
            r.ties.to_string(),
            r.structure_bytes.map_or(String::new(), |b| b.to_string()),
            num(r.structure_per_tri()),
        ];
        out.push_str(&line.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn csv_header_keeps_the_interface_columns() {
        assert!(super::CSV_HEADER.starts_with(
            "accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,leaves_per_ray,tris_per_ray"
        ));
    }
}
