//! `render reference SCENE --spp N`: a high-sample image to measure other renders against.
//!
//! A reference draws its samples from the reference family of streams
//! (`rt_core::SampleStream::Reference`), which no normal render uses whatever its seed, so its
//! noise is independent of the noise of any image it is compared with. It is cached on disk
//! (`cache.rs`) and rendered only when no entry with the same key exists; experiments go
//! through the same cache.

pub mod cache;

use crate::args::IntegratorKind;
use crate::progress::Progress;
use crate::session::{self, Budgets, Checkpoint, Estimator, ImageSize, Overrides, Session};
use anyhow::{anyhow, bail, Result};
use cache::{Cache, Key, ReferenceRequest, Sidecar, DEFAULT_CACHE_DIR};
use rt_core::{Accel, SampleStream};
use rt_film::{AovSet, Film};
use rt_integrators::Ctx;
use std::path::{Path, PathBuf};

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
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,

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
    #[arg(long, value_parser = session::parse_resolution, conflicts_with = "scale")]
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
}

/// A reference ready to use.
pub struct Obtained {
    /// The EXR (in the cache, or wherever it was written).
    pub path: PathBuf,
    /// True if it came from the cache.
    pub cached: bool,
    /// Render time (of the original render when cached).
    pub seconds: f64,
}

/// Finds `req` in `cache` or renders it (with `accel`) and stores it there. With no cache, the
/// reference is rendered and written to `write_to`. Call inside the thread pool to use.
pub fn obtain(
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
    cache: Option<&Cache>,
    write_to: Option<&Path>,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Obtained> {
    let key: Key = req.key()?;
    if let Some(cache) = cache {
        if let Some((path, sidecar)) = cache.lookup(req.scene_path, &key) {
            return Ok(Obtained {
                path,
                cached: true,
                seconds: sidecar.seconds,
            });
        }
    }
    let (film, at) = render(req, accel, progress)?;
    let sidecar = Sidecar {
        key: key.hex.clone(),
        description: key.description.clone(),
        scene: req.scene_path.display().to_string(),
        width: req.camera.width,
        height: req.camera.height,
        spp: req.spp,
        seconds: at.seconds,
        samples_per_second: at.samples as f64 / at.seconds.max(1e-9),
    };
    let path = match (cache, write_to) {
        (Some(cache), _) => cache.store(req.scene_path, &key, &film, &sidecar)?,
        (None, Some(out)) => {
            rt_film::write_image(out, &film, &rt_film::OutputOptions::default())
                .map_err(|e| anyhow!("{e}"))?;
            out.to_path_buf()
        }
        (None, None) => bail!("a reference needs a cache or an output file"),
    };
    Ok(Obtained {
        path,
        cached: false,
        seconds: at.seconds,
    })
}

/// Renders the reference: the reference stream, the variance AOV kept.
fn render(
    req: &ReferenceRequest<'_>,
    accel: &dyn Accel,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(Film, Checkpoint)> {
    let integrator = req.estimator.build();
    let session = Session {
        ctx: Ctx {
            scene: req.scene,
            accel,
            camera: req.camera,
        },
        integrator: integrator.as_ref(),
        seed: req.seed,
        stream: SampleStream::Reference,
        aovs: AovSet {
            variance: true,
            ..AovSet::default()
        },
    };
    let mut last = Checkpoint::default();
    let film = session.render(&Budgets::Spp(vec![req.spp]), progress, &mut |_, at| {
        last = *at;
        Ok(())
    })?;
    Ok((film, last))
}

/// Runs `render reference`.
pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.spp == 0 || args.spp > session::MAX_SPP {
        bail!(
            "--spp must be between 1 and {}, got {}",
            session::MAX_SPP,
            args.spp
        );
    }
    if let Some(out) = &args.output {
        if !out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
        {
            bail!("{}: a reference is written as .exr", out.display());
        }
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
    let loaded = crate::job::load_scene(&args.scene)?;
    let overrides = Overrides {
        integrator: args.integrator,
        max_depth: args.max_depth,
        ao_distance: args.ao_distance,
        seed: args.seed,
        accel,
    };
    let estimator: Estimator = overrides.estimator(&loaded.render, &args.scene)?;
    let accel_spec = overrides.accel(&loaded.render, &args.scene)?;
    let camera = size.apply(session::camera(
        &loaded.scene,
        &args.scene,
        args.camera.as_deref(),
    )?);
    let req = ReferenceRequest {
        scene_path: &args.scene,
        scene: &loaded.scene,
        camera: &camera,
        estimator,
        spp: args.spp,
        seed: overrides.seed(&loaded.render),
    };
    let pool = crate::experiment::thread_pool(args.threads)?;
    let progress = Progress::new(
        args.quiet,
        1000,
        "{spinner} [{elapsed_precise}] {bar:40} {percent}% reference (eta {eta})",
    );
    let cache = (!args.no_cache).then(|| Cache::new(&args.cache));
    let obtained = pool.install(|| {
        let accel = accel_spec.build(&loaded.scene.triangles);
        obtain(
            &req,
            accel.as_ref(),
            cache.as_ref(),
            args.output.as_deref(),
            &|f| progress.bar().set_position((f * 1000.0) as u64),
        )
    })?;
    progress.finish();
    if obtained.cached {
        progress.message(&format!(
            "reference: cached {} ({:.1} s when rendered)",
            obtained.path.display(),
            obtained.seconds
        ));
    } else {
        progress.message(&format!(
            "reference: rendered {}x{} at {} spp in {:.1} s -> {}",
            camera.width,
            camera.height,
            args.spp,
            obtained.seconds,
            obtained.path.display()
        ));
    }
    let printed = match &args.output {
        Some(out) if obtained.path != *out => {
            crate::atomic::copy(&obtained.path, out)?;
            out.clone()
        }
        _ => obtained.path,
    };
    println!("{}", printed.display());
    Ok(())
}
