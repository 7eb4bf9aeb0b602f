//! `render bench-accel`: measures acceleration structures on one scene.
//!
//! The steps, each in its own file:
//! 1. `input`: the scene (TOML, a bare mesh with an automatic camera and light, or `gen:NAME`).
//! 2. the ray sets of `rt_accel::bench`, generated once with the binary BVH (primary,
//!    incoherent diffuse bounces, shadow segments, uniform random rays) or read from
//!    `--ray-file`; optionally dumped to files.
//! 3. `run`: per structure, build it, check its answers against the binary BVH on the first
//!    `--check` rays of every set, then time every set on 1 and N threads and count traversal
//!    work.
//! 4. `report`: the aligned table on stdout and the CSV.
//!
//! Progress goes to stderr (silenced by `-q`); the table is the only thing on stdout.

pub mod input;
mod report;

use anyhow::{bail, Result};
use rt_accel::bench::{self as rays, measure, Query, RaySet};
use rt_accel::AccelSpec;
use rt_core::limits::MAX_THREADS;
use std::path::PathBuf;
use std::time::Instant;

/// A structure fails the check when more than this fraction of the checked rays disagree with
/// the binary BVH (a handful may differ legitimately: a ray grazing a shared edge in the
/// crack-free test modes, or a nearly degenerate triangle whose `t` is noisy).
const MAX_MISMATCH_FRACTION: f64 = 1e-3;

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
    pub view: Option<input::View>,

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

/// Which generated ray sets to trace.
#[derive(Clone, Copy, Debug, Default)]
struct Wanted {
    primary: bool,
    incoherent: bool,
    shadow: bool,
    uniform: bool,
}

impl Wanted {
    fn any(&self) -> bool {
        self.primary || self.incoherent || self.shadow || self.uniform
    }
}

fn parse_sets(args: &BenchArgs) -> Result<Wanted> {
    let Some(names) = &args.rays else {
        return Ok(if args.ray_file.is_some() {
            Wanted::default()
        } else {
            Wanted {
                primary: true,
                incoherent: true,
                shadow: true,
                uniform: true,
            }
        });
    };
    let mut w = Wanted::default();
    for n in names {
        match n.trim() {
            "primary" => w.primary = true,
            "incoherent" => w.incoherent = true,
            "shadow" => w.shadow = true,
            "uniform" => w.uniform = true,
            "file" if args.ray_file.is_some() => {}
            "file" => bail!("--rays file needs --ray-file"),
            other => bail!(
                "--rays: unknown ray set \"{other}\" (expected primary, incoherent, shadow, uniform or file)"
            ),
        }
    }
    if !w.any() && args.ray_file.is_none() {
        bail!("--rays: no ray set given");
    }
    Ok(w)
}

fn parse_specs(args: &BenchArgs) -> Result<Vec<AccelSpec>> {
    let mut specs: Vec<AccelSpec> = Vec::new();
    for s in &args.accel {
        let spec: AccelSpec = s.parse().map_err(|e| anyhow::anyhow!("--accel {s}: {e}"))?;
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
pub fn run(args: &BenchArgs) -> Result<()> {
    let specs = parse_specs(args)?;
    let wanted = parse_sets(args)?;
    let threads = match args.threads {
        Some(t) if t == 0 || t > MAX_THREADS => {
            bail!("--threads: thread count must be between 1 and {MAX_THREADS}, got {t}")
        }
        Some(t) => t,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    let info = |msg: &str| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    // Cheap checks of the ray file before the (possibly slow) scene.
    let file_rays = match &args.ray_file {
        Some(path) => {
            let query = if args.ray_file_occlusion {
                Query::Occluded
            } else {
                Query::Closest
            };
            Some(rays::read_set(path, "file", query)?)
        }
        None => None,
    };

    let t = Instant::now();
    let input = input::load(&args.input, args.camera.as_deref())?;
    for w in &input.warnings {
        info(&format!("warning: {w}"));
    }
    if args.view.is_some() && !input.is_mesh {
        bail!(
            "--view: {} is not a mesh file; it is seen through its own camera",
            input.name
        );
    }
    let scene = &input.scene;
    info(&format!(
        "{}: {} triangles, loaded in {:.2} s",
        input.name,
        scene.triangle_count(),
        t.elapsed().as_secs_f64()
    ));
    let pool = rt_session::job::thread_pool(Some(threads))?;

    // The reference every structure is checked against, which also generates the rays.
    let reference_spec: AccelSpec = "bvh".parse().expect("static spec");
    let t = Instant::now();
    let reference = pool.install(|| reference_spec.build(&scene.triangles));
    let reference_ms = t.elapsed().as_secs_f64() * 1e3;

    let (camera, fallback_light) = match args.view {
        Some(input::View::Inside) if input.is_mesh => {
            rt_scene::views::inside_view(&input.bounds, reference.as_ref())
        }
        _ => (input.camera.clone(), input.fallback_light),
    };

    let mut sets: Vec<RaySet> = Vec::new();
    if wanted.any() || args.dump_rays.is_some() {
        let (width, height) = input::resolution(&camera, args.width, args.height)?;
        let camera = camera.resized(width, height);
        let lights = rays::Lights::of(scene, fallback_light);
        info(&format!("shadow rays aim at {}", lights.describe()));
        let t = Instant::now();
        let generated =
            pool.install(|| rays::generate(scene, &camera, reference.as_ref(), &lights, args.seed));
        info(&format!(
            "rays: {} primary ({width}x{height}), {} incoherent, {} shadow, {} uniform, generated \
             in {:.2} s",
            generated.primary.rays.len(),
            generated.incoherent.rays.len(),
            generated.shadow.rays.len(),
            generated.uniform.rays.len(),
            t.elapsed().as_secs_f64()
        ));
        if let Some(dir) = &args.dump_rays {
            rays::dump(dir, &generated)?;
            info(&format!("rays written to {}", dir.display()));
        }
        let on = [
            wanted.primary,
            wanted.incoherent,
            wanted.shadow,
            wanted.uniform,
        ];
        for (set, on) in generated.into_sets().into_iter().zip(on) {
            if on {
                sets.push(set);
            }
        }
    }
    if let Some(set) = file_rays {
        sets.push(set);
    }
    if let Some(empty) = sets.iter().find(|s| s.rays.is_empty()) {
        bail!(
            "{}: no {} rays (does the camera see any geometry?)",
            input.name,
            empty.name
        );
    }

    let mut rows = Vec::new();
    for spec in &specs {
        let name = spec.to_string();
        let reuse = *spec == reference_spec;
        let (fresh, build_ms) = if reuse {
            (None, reference_ms)
        } else {
            let t = Instant::now();
            // From the scene, so two-level kinds place its instances (over bare triangles they
            // would be one static object); every kind keeps the triangle order the rays use.
            let a = pool
                .install(|| spec.try_build_scene(scene))
                .map_err(|e| anyhow::anyhow!("{}: --accel {name}: {e}", args.input))?;
            (Some(a), t.elapsed().as_secs_f64() * 1e3)
        };
        let accel = fresh.as_deref().unwrap_or(reference.as_ref());
        info(&format!("{name}: built in {build_ms:.1} ms"));
        let check = if reuse {
            measure::CheckResult::default()
        } else {
            let c = pool.install(|| measure::check(accel, reference.as_ref(), &sets, args.check));
            info(&format!("{name}: {}", c.summary()));
            if !args.quiet {
                for line in c.examples.iter().take(3) {
                    eprintln!("  {line}");
                }
            }
            if c.mismatches as f64 > MAX_MISMATCH_FRACTION * c.checked.max(1) as f64 {
                bail!(
                    "{name}: {} of {} checked rays disagree with bvh (more than {}%)",
                    c.mismatches,
                    c.checked,
                    MAX_MISMATCH_FRACTION * 100.0
                );
            }
            c
        };
        for set in &sets {
            let thread_counts: &[usize] = if threads == 1 { &[1] } else { &[1, threads] };
            let first_row = rows.len();
            for &n in thread_counts {
                let timing = if n == 1 && args.cpu_time {
                    measure::time_cpu(accel, set, args.repeat)
                } else {
                    measure::time(accel, set, (n > 1).then_some(&pool), args.repeat)
                };
                info(&format!(
                    "{name}: {} rays, {n} thread{}: {:.2} Mrays/s",
                    set.name,
                    if n == 1 { "" } else { "s" },
                    set.rays.len() as f64 / timing.seconds / 1e6
                ));
                rows.push(report::Row {
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
            // Counted after the timed runs, so that with `--check 0 --repeat 1` the first
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
    report::print_table(&rows, threads);
    if let Some(path) = &args.csv {
        report::write_csv(path, &rows)?;
        info(&format!("wrote {}", path.display()));
    }
    Ok(())
}
