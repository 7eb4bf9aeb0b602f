//! Turning arguments and the scene's `[render]` table into a render, and running it.

use crate::args::{Args, IntegratorKind};
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rt_accel::AccelSpec;
use rt_core::{Accel, Scene};
use rt_film::{AovSet, Film, FilmBuffers, OutputOptions};
use rt_integrators::{Ctx, Integrator, RenderOptions, RenderStats};
use rt_scene::{LoadedScene, RenderDesc};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

const MAX_SPP: u32 = 1 << 20;
const MAX_THREADS: usize = 1024;
const MAX_DEPTH: u32 = 10_000;

/// Fully resolved settings of one render.
#[derive(Debug)]
pub struct Job {
    pub scene_path: PathBuf,
    pub output: PathBuf,
    pub spp: u32,
    pub integrator: IntegratorKind,
    pub accel: AccelSpec,
    pub max_depth: u32,
    pub threads: Option<usize>,
    pub seed: u32,
    pub camera: Option<String>,
    pub aovs: AovSet,
    pub exposure: f32,
    pub ao_distance: f32,
    pub quiet: bool,
}

fn enum_from_table<T: ValueEnum>(scene: &Path, key: &str, value: &str) -> Result<T> {
    T::from_str(value, true).map_err(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        anyhow::anyhow!(
            "{}: [render] {key} = \"{value}\" is not one of {}",
            scene.display(),
            names.join(", ")
        )
    })
}

/// The scene path; clap requires it whenever there is no subcommand.
fn scene_arg(args: &Args) -> &Path {
    args.scene
        .as_deref()
        .expect("clap requires SCENE when no subcommand is given")
}

/// Loads a scene file, or generates the procedural scene `gen:NAME` (`rt_scene::procedural`).
pub fn load_scene(path: &Path) -> Result<LoadedScene> {
    if let Some(name) = path.to_str().and_then(|p| p.strip_prefix("gen:")) {
        let scene = rt_scene::procedural::generate(name)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        return Ok(LoadedScene {
            scene,
            render: RenderDesc::default(),
            warnings: Vec::new(),
        });
    }
    rt_scene::load(path).map_err(|e| anyhow::anyhow!("{e}"))
}

impl Job {
    /// Command line first, then the scene's `[render]` table, then defaults.
    pub fn resolve(args: &Args, desc: &RenderDesc) -> Result<Job> {
        let scene = scene_arg(args);
        let integrator = match (args.integrator, &desc.integrator) {
            (Some(i), _) => i,
            (None, Some(s)) => enum_from_table(scene, "integrator", s)?,
            (None, None) => IntegratorKind::Path,
        };
        let accel = match (&args.accel, &desc.accel) {
            (Some(a), _) => a
                .parse::<AccelSpec>()
                .map_err(|e| anyhow::anyhow!("--accel {a}: {e}"))?,
            (None, Some(s)) => s.parse::<AccelSpec>().map_err(|e| {
                anyhow::anyhow!("{}: [render] accel = \"{s}\": {e}", scene.display())
            })?,
            (None, None) => AccelSpec::default(),
        };
        // Names where a value came from, so that a bad `[render]` default points at the file.
        let origin = |flag: &str, key: &str, from_cli: bool| {
            if from_cli {
                format!("--{flag}")
            } else {
                format!("{}: [render] {key}", scene.display())
            }
        };
        let spp = args.spp.or(desc.spp).unwrap_or(64);
        if spp == 0 || spp > MAX_SPP {
            let at = origin("spp", "spp", args.spp.is_some());
            bail!("{at}: samples per pixel must be between 1 and {MAX_SPP}, got {spp}");
        }
        let max_depth = args.max_depth.or(desc.max_depth).unwrap_or(16);
        if max_depth > MAX_DEPTH {
            let at = origin("max-depth", "max_depth", args.max_depth.is_some());
            bail!("{at}: max depth must be at most {MAX_DEPTH}, got {max_depth}");
        }
        let threads = args.threads.or(desc.threads);
        if let Some(t) = threads {
            if t == 0 || t > MAX_THREADS {
                let at = origin("threads", "threads", args.threads.is_some());
                bail!("{at}: thread count must be between 1 and {MAX_THREADS}, got {t}");
            }
        }
        let seed = args.seed.or(desc.seed).unwrap_or(0);
        let aov_names: Vec<String> = args
            .aov
            .clone()
            .or_else(|| desc.aov.clone())
            .unwrap_or_default();
        let aovs = AovSet::parse_list(aov_names.iter().map(String::as_str))
            .map_err(|e| anyhow::anyhow!("{}: {e}", origin("aov", "aov", args.aov.is_some())))?;
        let output = match (&args.output, &desc.output) {
            (Some(o), _) => o.clone(),
            (None, Some(o)) => PathBuf::from(o),
            (None, None) => {
                PathBuf::from(scene.file_stem().unwrap_or_default()).with_extension("exr")
            }
        };
        match output
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") | Some("png") => {}
            _ => bail!("{}: output must end in .exr or .png", output.display()),
        }
        if aovs != AovSet::default()
            && output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            bail!(
                "{}: AOVs need an .exr output (PNG holds only the beauty image)",
                output.display()
            );
        }
        if !args.exposure.is_finite() {
            bail!("--exposure must be a finite number");
        }
        let ao_distance = args.ao_distance.unwrap_or(f32::INFINITY);
        if ao_distance.is_nan() || ao_distance <= 0.0 {
            bail!("--ao-distance must be positive, got {ao_distance}");
        }
        Ok(Job {
            scene_path: scene.to_path_buf(),
            output,
            spp,
            integrator,
            accel,
            max_depth,
            threads,
            // Fold the 64-bit seed into the 32-bit stream key without discarding the high half.
            seed: (seed ^ (seed >> 32)) as u32,
            camera: args.camera.clone(),
            aovs,
            exposure: args.exposure,
            ao_distance,
            quiet: args.quiet,
        })
    }
}

/// Builds the chosen acceleration structure.
pub fn build_accel(spec: &AccelSpec, scene: &Scene) -> Box<dyn Accel> {
    spec.build(&scene.triangles)
}

/// Builds the chosen integrator.
pub fn build_integrator(job: &Job) -> Box<dyn Integrator> {
    crate::session::Estimator {
        integrator: job.integrator,
        max_depth: job.max_depth,
        ao_distance: job.ao_distance,
    }
    .build()
}

/// Loads, renders and writes; prints the summary line.
pub fn run(args: &Args) -> Result<()> {
    let t_load = Instant::now();
    let loaded = load_scene(scene_arg(args))?;
    let load_time = t_load.elapsed();
    let load_secs = load_time.as_secs_f64();
    for w in &loaded.warnings {
        if !args.quiet {
            eprintln!("warning: {w}");
        }
    }
    let job = Job::resolve(args, &loaded.render)?;
    let scene = loaded.scene;
    let camera = crate::session::camera(&scene, &job.scene_path, job.camera.as_deref())?;

    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = job.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("cannot start worker threads")?;

    let t_build = Instant::now();
    let accel = pool.install(|| build_accel(&job.accel, &scene));
    let build_time = t_build.elapsed();
    let build_secs = build_time.as_secs_f64();
    let integrator = build_integrator(&job);
    // Only the buffers the outputs read: no variance or half-buffers unless asked for.
    let mut film = Film::new(
        camera.width,
        camera.height,
        FilmBuffers::for_outputs(job.aovs),
    );
    let ctx = Ctx {
        scene: &scene,
        accel: accel.as_ref(),
        camera,
    };
    let opts = RenderOptions {
        spp: job.spp,
        seed: job.seed,
    };

    let bar = if job.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let b =
            ProgressBar::with_draw_target(Some(camera.height as u64), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} rows (eta {eta})",
            )
            .expect("static template"),
        );
        b
    };
    let stats: RenderStats = pool.install(|| {
        rt_integrators::render(&ctx, integrator.as_ref(), &mut film, &opts, &|rows| {
            bar.set_position(rows as u64)
        })
    });
    bar.finish_and_clear();

    let t_write = Instant::now();
    rt_film::write_image(
        &job.output,
        &film,
        &OutputOptions {
            exposure: job.exposure,
        },
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let write_time = t_write.elapsed();
    if !job.quiet {
        print_summary(
            &job,
            &scene,
            camera,
            accel.as_ref(),
            integrator.as_ref(),
            &stats,
            load_secs,
            build_secs,
            pool.current_num_threads(),
        );
    }
    if args.stats {
        print!(
            "{}",
            crate::stats::collect(&crate::stats::Inputs {
                scene: &scene,
                camera,
                accel: accel.as_ref(),
                accel_spec: job.accel.to_string(),
                film: &film,
                render: &stats,
                load_time,
                accel_time: build_time,
                write_time,
                output: &job.output,
            })
        );
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn print_summary(
    job: &Job,
    scene: &Scene,
    camera: &rt_core::Camera,
    accel: &dyn Accel,
    integrator: &dyn Integrator,
    stats: &RenderStats,
    load_secs: f64,
    build_secs: f64,
    threads: usize,
) {
    // Always printed, zero included: a valid scene must discard nothing, and a reader should
    // not have to know that silence means zero.
    println!(
        "{}: {}x{} {} spp {} {} ({} tris, {} threads): {:.2} s render ({:.2} s load, {:.2} s {} build), \
         {:.2} Msamples/s, {:.2} Mrays/s, {} invalid samples discarded -> {}",
        job.scene_path.display(),
        camera.width,
        camera.height,
        job.spp,
        integrator.name(),
        job.accel,
        scene.triangle_count(),
        threads,
        stats.elapsed.as_secs_f64(),
        load_secs,
        build_secs,
        accel.name(),
        stats.samples_per_second() / 1e6,
        stats.rays_per_second() / 1e6,
        stats.discarded,
        job.output.display(),
    );
}
