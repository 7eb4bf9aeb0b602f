//! `render reference SCENE --spp N`: arguments, then `rt_experiment::reference` takes the
//! reference from the cache or renders it there (its own random streams, independent of any
//! normal render), and this prints its path.

use crate::progress::Progress;
use anyhow::{anyhow, bail, Result};
use rt_experiment::{Cache, DEFAULT_CACHE_DIR};
use rt_integrators::IntegratorSpec;
use rt_session::{parse_resolution, ImageSize, Overrides};
use std::path::PathBuf;

/// `render reference` arguments.
#[derive(clap::Args, Debug)]
pub struct ReferenceArgs {
    /// Scene file (TOML), or gen:NAME.
    pub scene: PathBuf,

    /// Samples per pixel.
    #[arg(long)]
    pub spp: u32,

    /// Also copy the reference to this EXR file (R, G, B and variance.R/G/B, the variance of
    /// each pixel mean). Without it, the cached file's path is printed.
    #[arg(short, long)]
    pub output: Option<PathBuf>,

    /// Seed of the reference stream (independent of a normal render with any seed).
    /// [default: `[render] seed`, else 0]
    #[arg(long)]
    pub seed: Option<u64>,

    /// Integrator (see `render --help`). [default: `[render] integrator`, else path]
    #[arg(long, value_name = "SPEC", value_parser = crate::args::parse_integrator)]
    pub integrator: Option<IntegratorSpec>,

    /// Maximum number of bounces. [default: `[render] max_depth`, else 16]
    #[arg(long)]
    pub max_depth: Option<u32>,

    /// Maximum occluder distance for the ao integrator. [default: unlimited]
    #[arg(long)]
    pub ao_distance: Option<f32>,

    /// Camera by name. [default: the first `[[camera]]` in the scene]
    #[arg(long)]
    pub camera: Option<String>,

    /// Render at WIDTHxHEIGHT instead of the camera's resolution (vertical field of view kept).
    #[arg(long, value_parser = resolution, conflicts_with = "scale")]
    pub resolution: Option<(u32, u32)>,

    /// Render at the camera's resolution times this factor.
    #[arg(long)]
    pub scale: Option<f64>,

    /// Acceleration structure (speed only: not part of the cache key).
    /// [default: `[render] accel`, else bvh8]
    #[arg(long, value_name = "SPEC")]
    pub accel: Option<String>,

    /// Reference cache directory.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_CACHE_DIR)]
    pub cache: PathBuf,

    /// Render even if the cache has the reference, and do not store it (needs -o).
    #[arg(long, requires = "output")]
    pub no_cache: bool,

    /// Worker threads. [default: all cores]
    #[arg(long)]
    pub threads: Option<usize>,

    /// No progress bar and no messages.
    #[arg(short, long)]
    pub quiet: bool,

    /// Render only sample indices A..B of the reference into a part file (-o NAME.rpart);
    /// `render merge --plan` stores the merged parts in the cache (`render plan --experiment`).
    #[arg(long, value_name = "A..B", value_parser = crate::args::parse_sample_range)]
    pub sample_range: Option<std::ops::Range<u32>>,

    /// Render only the pixels x0..x1 × y0..y1 of the reference into a part file.
    #[arg(long, value_name = "x0,y0,x1,y1", value_parser = crate::args::parse_region)]
    pub region: Option<rt_film::Rect>,

    /// Refuse any file the scene refers to outside DIR (as `render --confine`).
    #[arg(long, value_name = "DIR")]
    pub confine: Option<PathBuf>,
}

/// Parses `--resolution WxH`.
fn resolution(s: &str) -> Result<(u32, u32), String> {
    parse_resolution(s).map_err(|e| e.to_string())
}

/// Runs `render reference`.
pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.spp == 0 || args.spp > rt_session::MAX_SPP {
        bail!(
            "--spp must be between 1 and {}, got {}",
            rt_session::MAX_SPP,
            args.spp
        );
    }
    let ext =
        |o: &std::path::Path, e: &str| o.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    let part = args.output.as_ref().is_some_and(|o| ext(o, "rpart"));
    if let Some(out) = &args.output {
        if !part && !ext(out, "exr") {
            bail!(
                "{}: a reference is written as .exr (or .rpart for a part)",
                out.display()
            );
        }
    }
    if !part && (args.sample_range.is_some() || args.region.is_some()) {
        bail!("--sample-range and --region write a part file: -o must end in .rpart");
    }
    let size = match (args.resolution, args.scale) {
        (Some((w, h)), _) => ImageSize::Pixels(w, h),
        (None, Some(s)) => ImageSize::Scale(s),
        (None, None) => ImageSize::Native,
    };
    size.validate("--scale")?;
    let accel = match &args.accel {
        Some(a) => Some(a.parse().map_err(|e| anyhow!("--accel {a}: {e}"))?),
        None => None,
    };
    let t = std::time::Instant::now();
    let scene = rt_session::load_scene(&args.scene, args.confine.as_deref(), &[])?;
    let load = t.elapsed();
    let loaded = &scene.loaded;
    let overrides = Overrides {
        integrator: args.integrator,
        max_depth: args.max_depth,
        ao_distance: args.ao_distance,
        seed: args.seed,
        accel,
        ..Overrides::default()
    };
    let order = rt_experiment::reference::Order::new(
        &args.scene,
        loaded,
        &overrides,
        args.camera.as_deref(),
        size,
        args.spp,
    )?;
    if part {
        // A slice of the reference, as a part file.
        let out = args.output.as_ref().expect("a part has an output");
        let mut job = order.part_job(&args.scene, &loaded.scene, out)?;
        job.slice = rt_session::Slice {
            samples: args.sample_range.clone(),
            region: args.region.map(|r| [r.x0, r.y0, r.x1, r.y1]),
        };
        job.confine = args.confine.clone();
        job.settings.threads = args.threads;
        return crate::render::run_job(&job, Some((scene, load)), args.quiet, false);
    }
    let pool = rt_session::job::thread_pool(args.threads)?;
    let progress = Progress::new(
        args.quiet,
        1000,
        "{spinner} [{elapsed_precise}] {bar:40} {percent}% reference (eta {eta})",
    );
    let cache = (!args.no_cache).then(|| Cache::new(&args.cache));
    let obtained = pool.install(|| {
        let progress = |f: f64| progress.bar().set_position((f * 1000.0) as u64);
        let (path, scene) = (&args.scene, &loaded.scene);
        order.obtain(
            path,
            scene,
            cache.as_ref(),
            args.output.as_deref(),
            &progress,
        )
    })?;
    progress.finish();
    progress.message(&order.describe(&obtained));
    let printed = match &args.output {
        Some(out) if obtained.path != *out => {
            rt_film::copy_atomic(&obtained.path, out)?;
            out.clone()
        }
        _ => obtained.path,
    };
    println!("{}", printed.display());
    Ok(())
}
