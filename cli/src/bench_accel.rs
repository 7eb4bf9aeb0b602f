//! `render bench-accel`: measures acceleration structures on one scene.
//! The arguments are here; the benchmark (`rt_experiment::bench::accel`: rays, checks, timings)
//! and its table and CSV are in the library. Progress goes to stderr (silenced by `-q`); the
//! table is the only thing on stdout.

use anyhow::{anyhow, bail, Result};
use rt_accel::bench::{read_set, Query};
use rt_accel::AccelSpec;
use rt_experiment::bench::accel::{self, AccelBench, RaySetError, RaySets};
use rt_experiment::bench::input::View;
use rt_experiment::bench::BenchError;
use std::path::PathBuf;

/// Arguments of `render bench-accel`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// The geometry: a scene (.toml; its first camera and its emissive triangles are used), a
    /// mesh (.obj, .gltf, .glb, .ra2; seen from a fixed diagonal with a point light above), or
    /// gen:NAME for a procedural scene (worst-case, rotated, mixed, million).
    #[arg(value_name = "SCENE.toml|MESH|gen:NAME")]
    pub input: String,

    /// Structures to measure, comma separated, each KIND[:OPTION...] as for `render --accel`.
    #[arg(long, value_delimiter = ',', default_value = "bvh,qbvh,bvh8")]
    pub accel: Vec<String>,

    /// Ray sets, comma separated: primary (one jittered camera ray per pixel), incoherent (a
    /// cosine-distributed diffuse bounce from each primary hit), shadow (a segment from each
    /// primary hit to a point on a light, occlusion query), uniform (as many rays as pixels,
    /// origins uniform in the scene's bounding box, directions uniform on the sphere).
    /// [default: all four, or none when --ray-file is given]
    #[arg(long, value_delimiter = ',')]
    pub rays: Option<Vec<String>>,

    /// Also trace these rays (set "file"): six little-endian f32 per ray (origin xyz,
    /// direction xyz), closest-hit queries over (0, infinity).
    #[arg(long, value_name = "RAYS.bin")]
    pub ray_file: Option<PathBuf>,

    /// Trace --ray-file as occlusion queries over (0, 1) instead, as in the shadow.bin written
    /// by --dump-rays.
    #[arg(long, requires = "ray_file")]
    pub ray_file_occlusion: bool,

    /// Threads of the parallel runs (every set is also timed on one thread). [default: all
    /// cores]
    #[arg(long)]
    pub threads: Option<usize>,

    /// Write the results as CSV, one row per structure, ray set and thread count.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,

    /// Width of the primary ray grid (one ray per pixel). [default: 512]
    #[arg(long)]
    pub width: Option<u32>,

    /// Height of the primary ray grid. [default: from the width and the camera's aspect ratio]
    #[arg(long)]
    pub height: Option<u32>,

    /// Camera of a TOML scene by name. [default: the first]
    #[arg(long)]
    pub camera: Option<String>,

    /// Automatic camera of a mesh file: outside (the whole mesh from the diagonal (1, 0.7,
    /// 1.3), point light above) or inside (a room: standing inside, looking down the long
    /// horizontal axis, point light under the ceiling). [default: outside]
    #[arg(long, value_enum)]
    pub view: Option<ViewArg>,

    /// Seed of the jitter, bounce and light samples.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Write the generated rays to DIR/primary.bin, DIR/incoherent.bin and DIR/uniform.bin
    /// (closest hit over (0, infinity)) and DIR/shadow.bin (occlusion over (0, 1): the
    /// direction reaches the light point), six little-endian f32 per ray.
    #[arg(long, value_name = "DIR")]
    pub dump_rays: Option<PathBuf>,

    /// Rays of every set checked against the binary BVH before timing; more than 0.1 %
    /// disagreeing stops the benchmark. 0 skips the check.
    #[arg(long, default_value_t = 10_000)]
    pub check: usize,

    /// Timed repetitions of every run; the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,

    /// Time the one-thread runs by the thread's CPU time instead of wall time (Linux; wall time
    /// elsewhere): on a machine shared with other jobs, wall time also counts waiting for a core.
    #[arg(long)]
    pub cpu_time: bool,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--view`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ViewArg {
    /// Outside the bounds, seeing every vertex (scanned objects: bunny, dragon).
    Outside,
    /// Inside, looking down the long horizontal axis (rooms: conference, Sibenik, kitchen).
    Inside,
}

/// The structures of `--accel` (`rt_accel::bench::contenders`).
pub(crate) fn parse_specs(list: &[String], fixed_order: bool) -> Result<Vec<AccelSpec>> {
    use rt_accel::bench::ListError;
    rt_accel::bench::contenders(list, fixed_order).map_err(|e| match e {
        ListError::Spec { .. } | ListError::Reorders(_) => anyhow!("--accel {e}"),
        _ => anyhow!("--accel: {e}"),
    })
}

/// A benchmark error with the flag it is about.
pub(crate) fn flagged(e: BenchError, camera: Option<&str>) -> anyhow::Error {
    match e {
        BenchError::Resolution { .. } => anyhow!("--width/--height: {e}"),
        BenchError::ViewOfScene { .. } => anyhow!("--view: {e}"),
        BenchError::MeshCamera => anyhow!("--camera {}: {e}", camera.unwrap_or_default()),
        other => other.into(),
    }
}

/// Runs the benchmark.
pub fn run(args: &BenchArgs) -> Result<()> {
    let specs = parse_specs(&args.accel, false)?;
    let sets =
        RaySets::from_names(args.rays.as_deref(), args.ray_file.is_some()).map_err(
            |e| match e {
                RaySetError::NoRayFile => anyhow!("--rays file needs --ray-file"),
                e => anyhow!("--rays: {e}"),
            },
        )?;
    // Checked by the thread pool.
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    // Cheap checks of the ray file before the (possibly slow) scene.
    let file_rays = match &args.ray_file {
        Some(path) => {
            let query = if args.ray_file_occlusion {
                Query::Occluded
            } else {
                Query::Closest
            };
            Some(read_set(path, "file", query)?)
        }
        None => None,
    };
    let bench = AccelBench {
        input: args.input.clone(),
        specs,
        sets,
        file_rays,
        threads,
        width: args.width,
        height: args.height,
        camera: args.camera.clone(),
        view: args.view.map(|v| match v {
            ViewArg::Outside => View::Outside,
            ViewArg::Inside => View::Inside,
        }),
        seed: args.seed,
        dump_rays: args.dump_rays.clone(),
        check: args.check,
        repeat: args.repeat,
        cpu_time: args.cpu_time,
    };
    let info = |msg: &str| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    let rows = accel::run(bench, &info).map_err(|e| flagged(e, args.camera.as_deref()))?;
    print!("{}", accel::table(&rows, threads));
    if let Some(path) = &args.csv {
        rt_film::write_bytes_atomic(path, accel::csv(&rows).as_bytes())
            .map_err(|e| anyhow!("{e}"))?;
        info(&format!("wrote {}", path.display()));
    }
    Ok(())
}
