//! `render bench-anim`: seconds per frame of an animated scene, split into the structure's
//! update and the trace of a fixed per-frame workload (Dammertz's Figs. 4.16/4.17: clustering
//! against per-object BVHs under a top level and against a flat BVH rebuilt every frame).
//!
//! This file parses the arguments, builds the contenders, calls
//! [`rt_accel::bench::anim::run`] (which checks, times and interleaves) and prints the table
//! and the CSV; the measurement itself lives in the library.

use anyhow::{bail, Context, Result};
use rt_accel::bench::anim::{self, AnimOptions, AnimReport, Contender};
use rt_accel::AccelSpec;
use std::path::PathBuf;
use std::time::Instant;

/// The default sweep: a flat BVH8 rebuilt per frame, per-object instancing rebuilt and
/// refitted, and clustering over the thesis' range of `t` and beyond.
const DEFAULT_ACCEL: &str = "bvh8,two-level,two-level:top=refit,clusters:t=1,clusters:t=2,\
clusters:t=4,clusters:t=8,clusters:t=16,clusters:t=32,clusters:t=64,clusters:t=128,\
clusters:t=256,clusters:t=512";
use crate::bench_accel::input::{MAX_PIXELS, MAX_SIDE};
use rt_core::limits::MAX_THREADS;

/// Arguments of `render bench-anim`.
#[derive(clap::Args, Debug)]
pub struct BenchAnimArgs {
    /// The animated scene: a .toml scene or gen:NAME (car, furniture).
    #[arg(value_name = "SCENE.toml|gen:NAME")]
    pub input: String,

    /// Frames A..B (half-open), frame f at time f / fps.
    #[arg(long, value_name = "A..B", value_parser = crate::args::parse_frames, default_value = "0..8")]
    pub frames: std::ops::Range<u32>,

    /// Frames per second.
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,

    /// Structures, comma separated, each KIND[:OPTION...] as for `render --accel`. Two-level
    /// kinds follow the animation by updating their top level; the others are rebuilt every
    /// frame. [default: bvh8, two-level, two-level:top=refit, clusters:t=1,2,4,...,512]
    #[arg(long, value_delimiter = ',')]
    pub accel: Option<Vec<String>>,

    /// Primary ray grid WxH (one jittered primary ray per pixel).
    #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "480x300")]
    pub size: (u32, u32),

    /// Rays per frame: full (each primary ray, a diffuse bounce and a shadow segment from each
    /// primary hit) or primary (primary rays only, as the thesis timed its figures).
    #[arg(long, value_enum, default_value = "full")]
    pub rays: Rays,

    /// Camera of the scene by name. [default: the first]
    #[arg(long)]
    pub camera: Option<String>,

    /// Seed of the jitter, bounce and light samples.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Rays of every set checked against a flat bvh8 per frame before timing; more than 0.1 %
    /// disagreeing stops the benchmark. 0 skips the check.
    #[arg(long, default_value_t = 2000)]
    pub check: usize,

    /// Timed rounds per frame (the contenders interleaved); the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,

    /// Threads of the untimed work (building, generating and checking rays). Timings always
    /// run on one thread.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,

    /// Also count traversal work (boxes, leaves and triangles tested per ray) in an untimed
    /// pass per frame.
    #[arg(long)]
    pub count: bool,

    /// Write one row per structure and frame as CSV.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--rays`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Rays {
    /// Primary rays, a diffuse bounce and a shadow segment per primary hit.
    Full,
    /// Primary rays only.
    Primary,
}

/// `WxH`, each side in [1, 16384], at most 2^26 pixels (as `bench-accel`).
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || {
        format!(
            "size must be WxH with sides 1 to {MAX_SIDE} and at most {MAX_PIXELS} pixels, e.g. 480x300, got `{s}`"
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|n| (1..=MAX_SIDE).contains(n))
    };
    let (w, h) = (side(w).ok_or_else(bad)?, side(h).ok_or_else(bad)?);
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(bad());
    }
    Ok((w, h))
}

fn parse_specs(list: &[String]) -> Result<Vec<AccelSpec>> {
    let mut specs: Vec<AccelSpec> = Vec::new();
    for s in list {
        let spec: AccelSpec = s.parse().map_err(|e| anyhow::anyhow!("--accel {s}: {e}"))?;
        if spec.kind.permutes() {
            bail!("--accel {s}: a structure that reorders the scene's triangles cannot be compared frame by frame");
        }
        if specs.contains(&spec) {
            bail!("--accel: {spec} is listed twice");
        }
        specs.push(spec);
    }
    if specs.is_empty() {
        bail!("--accel: no acceleration structure given");
    }
    Ok(specs)
}

/// Runs the benchmark.
pub fn run(args: &BenchAnimArgs) -> Result<()> {
    let list: Vec<String> = match &args.accel {
        Some(l) => l.clone(),
        None => DEFAULT_ACCEL.split(',').map(str::to_owned).collect(),
    };
    let specs = parse_specs(&list)?;
    if args.threads == 0 || args.threads > MAX_THREADS {
        bail!(
            "--threads: thread count must be between 1 and {MAX_THREADS}, got {}",
            args.threads
        );
    }
    rt_session::job::check_fps(args.fps)?;
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    let info = |msg: &str| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    let t = Instant::now();
    let loaded = rt_session::load_scene(std::path::Path::new(&args.input), None, &[])?.loaded;
    for w in &loaded.warnings {
        info(&format!("warning: {w}"));
    }
    let mut scene = loaded.scene;
    if scene.triangles.is_empty() {
        bail!("{}: the scene has no triangles", args.input);
    }
    let camera = match &args.camera {
        Some(name) => scene
            .cameras
            .iter()
            .position(|c| &c.name == name)
            .with_context(|| format!("{}: no camera named \"{name}\"", args.input))?,
        None if scene.cameras.is_empty() => bail!("{}: the scene has no camera", args.input),
        None => 0,
    };
    if scene.instances.is_empty() {
        info(&format!(
            "warning: {} has no instances: nothing moves rigidly, two-level kinds hold one static object",
            args.input
        ));
    }
    info(&format!(
        "{}: {} triangles, {} instances, loaded in {:.2} s",
        args.input,
        scene.triangle_count(),
        scene.instances.len(),
        t.elapsed().as_secs_f64()
    ));
    let pool = rt_session::job::thread_pool(Some(args.threads))?;
    scene.set_time((f64::from(args.frames.start) / args.fps) as f32);
    let mut contenders = Vec::with_capacity(specs.len());
    for spec in &specs {
        let c = pool
            .install(|| Contender::build(spec, &scene))
            .map_err(|e| anyhow::anyhow!("{}: --accel {spec}: {e}", args.input))?;
        info(&format!(
            "{}: built in {:.3} s{}",
            c.name,
            c.build_seconds,
            c.entries
                .map_or(String::new(), |n| format!(", {n} top-level entries"))
        ));
        contenders.push(c);
    }
    let options = AnimOptions {
        frames: args.frames.clone(),
        fps: args.fps,
        camera,
        width: args.size.0,
        height: args.size.1,
        seed: args.seed,
        check: args.check,
        repeat: args.repeat,
        count: args.count,
        workload: match args.rays {
            Rays::Full => anim::Workload::Full,
            Rays::Primary => anim::Workload::Primary,
        },
    };
    let mut progress = |line: &str| info(line);
    let report = anim::run(&mut scene, &mut contenders, &options, &pool, &mut progress)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.input))?;
    print_table(&args.input, &options, &report);
    if let Some(path) = &args.csv {
        write_csv(path, &args.input, &report)?;
        info(&format!("wrote {}", path.display()));
    }
    Ok(())
}

/// The contender to compare with: the first with this name prefix.
fn find<'a>(report: &'a AnimReport, name: &str) -> Option<&'a anim::ContenderResult> {
    report.contenders.iter().find(|c| c.name == name)
}

/// The aligned table: per structure the entries, the mean seconds per frame (update, trace,
/// total) and the ratios the thesis' goals are stated in.
fn print_table(input: &str, options: &AnimOptions, report: &AnimReport) {
    let rays: usize = report.rays.iter().map(|r| r.total()).sum::<usize>() / report.rays.len();
    println!(
        "{input}: {} triangles; frames {}..{} at {} fps; {}x{} primary rays{}, {rays} rays per \
         frame on average; seconds per frame: mean over frames of the best of {} rounds, 1 thread",
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
    let widths: Vec<usize> = (0..header.len())
        .map(|i| cells.iter().map(|r| r[i].len()).max().unwrap_or(0))
        .collect();
    for row in &cells {
        let line: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(i, c)| {
                if i == 0 {
                    format!("{c:<w$}", w = widths[i])
                } else {
                    format!("{c:>w$}", w = widths[i])
                }
            })
            .collect();
        println!("{}", line.join("  ").trim_end());
    }
    println!(
        "update: top level (two-level, clusters) or full rebuild (flat); x two-level: two-level's \
         total over this total; trace / bvh8: trace time over the flat bvh8's"
    );
}

/// The CSV header.
pub const CSV_HEADER: &str =
    "scene,accel,frame,entries,update_s,trace_s,total_s,rays,hits,build_s,bytes,boxes,leaves,tris";

/// One row per structure and frame.
fn write_csv(path: &std::path::Path, input: &str, report: &AnimReport) -> Result<()> {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    let quote = |s: &str| {
        if s.contains([',', '"', '\n']) {
            format!("\"{}\"", s.replace('"', "\"\""))
        } else {
            s.to_string()
        }
    };
    for c in &report.contenders {
        for (f, r) in c.frames.iter().zip(&report.rays) {
            out.push_str(&format!(
                "{},{},{},{},{:.7},{:.7},{:.7},{},{},{:.5},{},{}\n",
                quote(input),
                quote(&c.name),
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
    rt_film::write_bytes_atomic(path, out.as_bytes()).map_err(|e| anyhow::anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_say_why() {
        assert_eq!(parse_size("480x300"), Ok((480, 300)));
        assert_eq!(parse_size("8X6"), Ok((8, 6)));
        for bad in ["480", "0x3", "x3", "4x", "99999x2", "-1x2"] {
            assert!(parse_size(bad).unwrap_err().contains("WxH"), "{bad}");
        }
    }

    #[test]
    fn the_default_sweep_parses() {
        let list: Vec<String> = DEFAULT_ACCEL.split(',').map(str::to_owned).collect();
        let specs = parse_specs(&list).unwrap();
        assert_eq!(specs.len(), 13);
        assert!(parse_specs(&["iosp0".into()]).is_err());
        assert!(parse_specs(&["bvh8".into(), "bvh8".into()]).is_err());
    }
}
