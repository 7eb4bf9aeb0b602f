//! Seconds per frame of an animated scene, split into the structure's update and the trace of
//! a fixed per-frame workload (Dammertz's Figs. 4.16/4.17: clustering against per-object BVHs
//! under a top level and against a flat BVH rebuilt every frame).
//!
//! [`run`] loads the scene, builds the contenders and calls [`rt_accel::bench::anim::run`]
//! (which checks, times and interleaves); [`table`] and [`csv`] show the report.

use super::table::aligned;
use super::BenchError;
use crate::csv::field;
use rt_accel::bench::anim::{self, AnimOptions, AnimReport, Contender, ContenderResult};
use rt_accel::AccelSpec;
use std::path::Path;
use std::time::Instant;

/// The default sweep: a flat BVH8 rebuilt per frame, per-object instancing rebuilt and
/// refitted, and clustering over the thesis' range of `t` and beyond.
pub const DEFAULT_SWEEP: &str = "bvh8,two-level,two-level:top=refit,clusters:t=1,clusters:t=2,\
clusters:t=4,clusters:t=8,clusters:t=16,clusters:t=32,clusters:t=64,clusters:t=128,\
clusters:t=256,clusters:t=512";

/// What to measure.
#[derive(Clone, Debug)]
pub struct AnimBench {
    /// A `.toml` scene or `gen:NAME`.
    pub input: String,
    /// The contenders.
    pub specs: Vec<AccelSpec>,
    /// The camera by name (the first by default); it replaces `options.camera`.
    pub camera: Option<String>,
    /// Threads of the untimed work (building, generating and checking rays).
    pub threads: usize,
    /// Frames, ray grid, rounds and workload.
    pub options: AnimOptions,
}

/// Runs the benchmark; `info` gets the progress lines.
pub fn run(bench: &AnimBench, info: &dyn Fn(&str)) -> Result<AnimReport, BenchError> {
    let input = bench.input.as_str();
    let t = Instant::now();
    let path = Path::new(input);
    let loaded = rt_session::load_scene(path, None, &[])?.loaded;
    for w in &loaded.warnings {
        info(&format!("warning: {w}"));
    }
    let mut scene = loaded.scene;
    if scene.triangles.is_empty() {
        return Err(BenchError::Input {
            input: input.to_string(),
            message: "the scene has no triangles".into(),
        });
    }
    let picked = rt_session::pick_camera(&scene, path, bench.camera.as_deref())?;
    let camera = scene
        .cameras
        .iter()
        .position(|c| std::ptr::eq(c, picked))
        .expect("picked from the scene's cameras");
    if scene.instances.is_empty() {
        info(&format!(
            "warning: {input} has no instances: nothing moves rigidly, two-level kinds hold one static object"
        ));
    }
    info(&format!(
        "{input}: {} triangles, {} instances, loaded in {:.2} s",
        scene.triangle_count(),
        scene.instances.len(),
        t.elapsed().as_secs_f64()
    ));
    let pool = rt_session::job::thread_pool(Some(bench.threads))?;
    let options = AnimOptions {
        camera,
        ..bench.options.clone()
    };
    scene.set_time((f64::from(options.frames.start) / options.fps) as f32);
    let mut contenders = Vec::with_capacity(bench.specs.len());
    for spec in &bench.specs {
        let c = pool
            .install(|| Contender::build(spec, &scene))
            .map_err(|e| BenchError::Build {
                input: input.to_string(),
                spec: spec.to_string(),
                message: e.to_string(),
            })?;
        info(&format!(
            "{}: built in {:.3} s{}",
            c.name,
            c.build_seconds,
            c.entries
                .map_or(String::new(), |n| format!(", {n} top-level entries"))
        ));
        contenders.push(c);
    }
    let mut progress = |line: &str| info(line);
    anim::run(&mut scene, &mut contenders, &options, &pool, &mut progress).map_err(|source| {
        BenchError::Anim {
            input: input.to_string(),
            source,
        }
    })
}

/// The contender to compare with: the first with this name.
fn find<'a>(report: &'a AnimReport, name: &str) -> Option<&'a ContenderResult> {
    report.contenders.iter().find(|c| c.name == name)
}

/// The aligned table: per structure the entries, the mean seconds per frame (update, trace,
/// total) and the ratios the thesis' goals are stated in.
pub fn table(input: &str, options: &AnimOptions, report: &AnimReport) -> String {
    let rays: usize = report.rays.iter().map(|r| r.total()).sum::<usize>() / report.rays.len();
    let mut out = format!(
        "{input}: {} triangles; frames {}..{} at {} fps; {}x{} primary rays{}, {rays} rays per \
         frame on average; seconds per frame: mean over frames of the best of {} rounds, 1 thread\n",
        report.triangles,
        options.frames.start,
        options.frames.end,
        options.fps,
        options.width,
        options.height,
        match options.workload {
            anim::Workload::Full => " + bounce + shadow",
            anim::Workload::Primary => " only",
        },
        options.repeat
    );
    let instancing = find(report, "two-level");
    let flat = find(report, "bvh8");
    let header = [
        "accel",
        "entries",
        "build s",
        "update s",
        "trace s",
        "total s",
        "update %",
        "x two-level",
        "trace / bvh8",
        "Mrays/s",
        "boxes/ray",
        "leaves/ray",
        "tris/ray",
        "mismatches",
    ];
    let frames_rays: usize = report.rays.iter().map(|r| r.total()).sum();
    let mut cells: Vec<Vec<String>> = vec![header.iter().map(|s| s.to_string()).collect()];
    for c in &report.contenders {
        cells.push(vec![
            c.name.clone(),
            c.entries.map_or("-".into(), |n| n.to_string()),
            format!("{:.3}", c.build_seconds),
            format!("{:.5}", c.update()),
            format!("{:.4}", c.trace()),
            format!("{:.4}", c.total()),
            format!("{:.1}", 100.0 * c.update() / c.total()),
            instancing.map_or("-".into(), |b| format!("{:.2}", b.total() / c.total())),
            flat.map_or("-".into(), |b| format!("{:.3}", c.trace() / b.trace())),
            format!("{:.2}", rays as f64 / c.trace() / 1e6),
        ]);
        let row = cells.last_mut().expect("pushed above");
        let per_ray = |f: fn(&rt_core::TraversalCounters) -> u64| {
            c.counters().map_or("-".into(), |n| {
                format!("{:.1}", f(&n) as f64 / frames_rays.max(1) as f64)
            })
        };
        row.extend([
            per_ray(|n| n.nodes_visited),
            per_ray(|n| n.leaves_visited),
            per_ray(|n| n.prims_tested),
            format!("{}/{}", c.check.mismatches, c.check.checked),
        ]);
    }
    out += &aligned(&cells, &[0]);
    out +=
        "update: top level (two-level, clusters) or full rebuild (flat); x two-level: two-level's \
         total over this total; trace / bvh8: trace time over the flat bvh8's\n";
    out
}

/// The CSV header.
pub const CSV_HEADER: &str =
    "scene,accel,frame,entries,update_s,trace_s,total_s,rays,hits,build_s,bytes,boxes,leaves,tris";

/// [`CSV_HEADER`] and one row per structure and frame.
pub fn csv(input: &str, report: &AnimReport) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for c in &report.contenders {
        for (f, r) in c.frames.iter().zip(&report.rays) {
            out.push_str(&format!(
                "{},{},{},{},{:.7},{:.7},{:.7},{},{},{:.5},{},{}\n",
                field(input),
                field(&c.name),
                f.frame,
                c.entries.map_or(String::new(), |n| n.to_string()),
                f.update,
                f.trace,
                f.update + f.trace,
                r.total(),
                f.hits,
                c.build_seconds,
                c.bytes,
                f.counters.map_or(",,".into(), |n| format!(
                    "{},{},{}",
                    n.nodes_visited, n.leaves_visited, n.prims_tested
                ))
            ));
        }
    }
    out
}
