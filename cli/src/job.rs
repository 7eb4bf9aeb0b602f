//! Turning arguments and the scene's `[render]` table into a render, and running it.

use crate::args::Args;
use crate::frame_pattern::frame_path;
use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rt_accel::AccelSpec;
use rt_core::{Accel, Scene};
use rt_film::{AovSet, Film, FilmBuffers, OutputOptions};
use rt_integrators::{Ctx, RadianceCache, RenderStats, SamplePass, Technique};
use rt_scene::{FileAccess, LoadedScene, RenderDesc};
use rt_session::{
    frame_seed, pick_camera, render_adaptive, Adaptive, Overrides, RenderReport, ReportInputs,
    Settings, StopRule, MAX_SPP,
};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Fully resolved settings of one render: the library's [`Settings`] plus what only the
/// command line has.
#[derive(Debug)]
pub struct Job {
    pub scene_path: PathBuf,
    pub output: PathBuf,
    pub settings: Settings,
    pub camera: Option<String>,
    pub exposure: f32,
    pub quiet: bool,
    /// Adaptive stopping (`--error`, `--time-limit`), if asked for.
    pub stop: Option<StopRule>,
    /// The frame of a sequence being rendered (`--frame`, or the current one of `--frames`).
    pub frame: Option<u32>,
    /// The command line after the program name (a resumed render keeps its first one), for
    /// part and checkpoint headers.
    pub command: Vec<String>,
    /// The scene's content hash, when a part or a checkpoint will name it.
    pub scene_hash: Option<String>,
    /// The checkpoint a resumed render starts from (`--resume`), and its file.
    pub resume: Option<(PathBuf, rt_parts::Part)>,
}

/// The scene path; clap requires it whenever there is no subcommand.
fn scene_arg(args: &Args) -> &Path {
    args.scene
        .as_deref()
        .expect("clap requires SCENE when no subcommand is given")
}

/// What the loaders may read: anything, or with `--confine DIR` only files inside DIR.
pub fn file_access(confine: Option<&Path>) -> Result<FileAccess> {
    match confine {
        Some(dir) => FileAccess::confined_to(dir).map_err(|e| anyhow::anyhow!("{e}")),
        None => Ok(FileAccess::open()),
    }
}

/// Loads a scene file or `gen:NAME`.
pub fn load_scene(path: &Path) -> Result<LoadedScene> {
    load_scene_with(path, &FileAccess::open())
}

/// [`load_scene`] reading only what `access` allows (`--confine`).
pub fn load_scene_with(path: &Path, access: &FileAccess) -> Result<LoadedScene> {
    rt_scene::load_any_with(path, access).map_err(|e| anyhow::anyhow!("{e}"))
}

impl Job {
    /// Command line first, then the scene's `[render]` table, then defaults
    /// ([`Overrides::resolve`]); then the checks only the command line needs.
    pub fn resolve(args: &Args, desc: &RenderDesc) -> Result<Job> {
        let scene = scene_arg(args);
        let accel = match &args.accel {
            Some(a) => Some(
                a.parse::<AccelSpec>()
                    .map_err(|e| anyhow::anyhow!("--accel {a}: {e}"))?,
            ),
            None => None,
        };
        let mut settings = Overrides {
            integrator: args.integrator,
            max_depth: args.max_depth,
            ao_distance: args.ao_distance,
            spp: args.spp,
            threads: args.threads,
            seed: args.seed,
            accel,
            aovs: args.aov.clone(),
            output: args.output.clone(),
            denoiser: args.denoiser.clone(),
        }
        .resolve(desc, scene)?;
        if args.gree.is_some() {
            // GREE chooses among its own bank of filters; the table's denoiser would be a
            // second, conflicting reconstruction (`--denoiser` itself conflicts with `--gree`).
            settings.denoiser = None;
        }
        let output = settings.output.clone().unwrap_or_else(|| {
            PathBuf::from(scene.file_stem().unwrap_or_default()).with_extension("exr")
        });
        match output
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") | Some("png") | Some("rpart") => {}
            _ => bail!(
                "{}: output must end in .exr or .png (or .rpart for a part file)",
                output.display()
            ),
        }
        if settings.aovs != AovSet::default()
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
        if let Some(v) = args.error {
            if v.is_nan() || v <= 0.0 || !v.is_finite() {
                bail!("--error must be a positive number (the thesis uses 2e-4), got {v}");
            }
        }
        let time_limit = match args.time_limit {
            Some(t) if t.is_nan() || t <= 0.0 || !t.is_finite() => {
                bail!("--time-limit must be a positive number of seconds, got {t}")
            }
            Some(t) => Some(std::time::Duration::from_secs_f64(t)),
            None => None,
        };
        if settings.aovs.blocks && args.error.is_none() {
            bail!("--aov blocks writes the stopping criterion's blocks: it needs --error");
        }
        let stop = (args.error.is_some() || time_limit.is_some()).then(|| StopRule {
            error: args.error,
            time_limit,
            max_spp: args.spp.unwrap_or(MAX_SPP),
        });
        Ok(Job {
            scene_path: scene.to_path_buf(),
            output,
            settings,
            camera: args.camera.clone(),
            exposure: args.exposure,
            quiet: args.quiet,
            stop,
            frame: args.frame,
            command: std::env::args().skip(1).collect(),
            scene_hash: None,
            resume: None,
        })
    }
}

/// Loads, renders and writes; prints the summary line.
pub fn run(args: &Args) -> Result<()> {
    match crate::checkpoint::resume_args(args)? {
        Some((old, part)) => {
            let path = args.resume.clone().expect("resuming");
            run_job(&old, Some((path, part)))
        }
        None => run_job(args, None),
    }
}

/// [`run`], continuing from the checkpoint `resume` if given.
fn run_job(args: &Args, resume: Option<(PathBuf, rt_parts::Part)>) -> Result<()> {
    let t_load = Instant::now();
    let access = file_access(args.confine.as_deref())?;
    let loaded = load_scene_with(scene_arg(args), &access)?;
    // A part file names the scene's content; nothing else needs the files read twice.
    let scene_hash = (crate::parts::writes_part(args) || args.checkpoint.is_some())
        .then(|| rt_parts::content_hash(&access.files_used(), &scene_arg(args).to_string_lossy()));
    let load_time = t_load.elapsed();
    for w in &loaded.warnings {
        if !args.quiet {
            eprintln!("warning: {w}");
        }
    }
    let mut job = Job::resolve(args, &loaded.render)?;
    crate::checkpoint::check(args, &job)?;
    job.scene_hash = scene_hash;
    if let Some((path, part)) = resume {
        job.command = part.header.args.clone();
        job.resume = Some((path, part));
    }
    let mut scene = loaded.scene;
    let frames = frame_list(args, &job.output)?;
    if args.accel.is_none() && loaded.render.accel.is_none() {
        job.settings.accel = AccelSpec::default_for_scene(&scene);
    }
    set_shutter(args, &job, &mut scene)?;
    check_memory(args, &job, &scene)?;
    if let Some(spec) = crate::sequence::temporal_spec(&job)? {
        if crate::parts::writes_part(args) {
            bail!(
                "{}: a part file cannot hold a temporally denoised sequence: its history carries from frame to frame; render the frames' parts without it",
                job.output.display()
            );
        }
        return crate::sequence::run(args, &job, &spec, &mut scene, &frames);
    }

    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = job.settings.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("cannot start worker threads")?;
    // One cache for the whole job: it persists across passes and frames.
    let cache = crate::cache::for_job(args.cache.as_deref(), &job.settings.integrator, &scene)?;
    let (pattern, seed) = (job.output.clone(), job.settings.seed);
    let mut accel: Option<Box<dyn Accel>> = None;
    for frame in frames {
        job.frame = frame;
        if let Some(f) = frame {
            scene.set_time((f64::from(f) / args.fps) as f32);
            job.output = frame_path(&pattern, f);
            job.settings.seed = frame_seed(seed, f);
        }
        if let Some(e) = scene.motion_blur_error() {
            bail!("{}: --shutter: {e}", job.scene_path.display());
        }
        // Two-level structures follow rigid motion in place; flat ones are rebuilt.
        let t_build = Instant::now();
        let updated = accel
            .as_mut()
            .is_some_and(|a| pool.install(|| a.update(&scene)));
        if !updated {
            // IOSP reorders the scene's triangles to store nothing beyond them.
            let built = pool.install(|| job.settings.accel.try_build_scene_mut(&mut scene));
            accel = Some(built.map_err(|e| {
                anyhow::anyhow!(
                    "{}: --accel {}: {e}",
                    job.scene_path.display(),
                    job.settings.accel
                )
            })?);
        }
        let built = accel.as_deref().expect("built above");
        render_one(
            args,
            &job,
            &scene,
            &pool,
            built,
            cache.clone(),
            (load_time, t_build.elapsed()),
        )?;
    }
    Ok(())
}

/// The single-frame denoiser `--denoiser` names, built (`None` without one).
pub(crate) fn single_frame_denoiser(
    args: &Args,
    job: &Job,
) -> Result<Option<Box<dyn rt_denoise::Denoiser>>> {
    let Some(text) = &job.settings.denoiser else {
        return Ok(None);
    };
    let label = denoiser_label(args, job);
    if job.settings.aovs != AovSet::default() {
        if args.denoiser.is_none() {
            bail!("{label} writes the denoised image only; add --denoiser none to save a noisy frame's AOVs");
        }
        bail!("--denoiser writes the denoised image only; save a noisy frame's AOVs with a render without it");
    }
    let d = text
        .parse::<rt_denoise::DenoiserSpec>()
        .and_then(|s| s.build())
        .map_err(|e| anyhow::anyhow!("{label}: {e}"))?;
    Ok(Some(d))
}

/// Where the render's denoiser comes from, for messages: `--denoiser TEXT`, or the scene's
/// `[render] denoiser`.
pub(crate) fn denoiser_label(args: &Args, job: &Job) -> String {
    let text = job.settings.denoiser.as_deref().unwrap_or_default();
    if args.denoiser.is_some() {
        format!("--denoiser {text}")
    } else {
        format!(
            "{}: [render] denoiser = \"{text}\"",
            job.scene_path.display()
        )
    }
}

/// The film buffers a render keeps: only what its outputs and its denoiser read, no variance
/// or half-buffers unless asked for; the stopping criterion reads the even samples' half.
pub(crate) fn film_buffers(job: &Job, denoiser: Option<&dyn rt_denoise::Denoiser>) -> FilmBuffers {
    let denoise_aovs = denoiser.map_or(AovSet::default(), |d| AovSet::for_channels(d.needs()));
    let buffers = FilmBuffers::for_outputs(job.settings.aovs.union(denoise_aovs));
    if job.stop.is_some_and(|s| s.error.is_some()) {
        buffers.with_halves()
    } else {
        buffers
    }
}

/// `--max-memory`: refuses, before the structure and the film are allocated, a render whose
/// estimate exceeds the limit (`crate::memory`).
fn check_memory(args: &Args, job: &Job, scene: &Scene) -> Result<()> {
    let limit = args
        .max_memory
        .as_deref()
        .map(crate::memory::parse_size)
        .transpose()?;
    let camera = pick_camera(scene, &job.scene_path, job.camera.as_deref())?;
    // A temporal denoiser's needs are its own; the plain film is still the floor.
    let denoiser = if crate::sequence::temporal_spec(job)?.is_some() {
        None
    } else {
        single_frame_denoiser(args, job)?
    };
    let splats = job
        .settings
        .integrator
        .build()
        .camera_integrator()
        .is_none();
    crate::memory::Estimate::new(
        camera.width,
        camera.height,
        film_buffers(job, denoiser.as_deref()),
        job.settings.spp,
        splats,
        &job.settings.accel,
        scene.triangle_count(),
    )
    .check(&job.scene_path.display().to_string(), limit)
}

/// Opens the scene's shutter for `--shutter` of a frame and checks that the render can blur
/// what moves: no moving emitter, a camera-ray technique, and a structure that places
/// instances per ray (the default for a scene whose instances move).
fn set_shutter(args: &Args, job: &Job, scene: &mut Scene) -> Result<()> {
    let s = args.shutter;
    if !(s.is_finite() && s >= 0.0) {
        bail!("--shutter must be a fraction of a frame >= 0, got {s}");
    }
    if s == 0.0 {
        return Ok(());
    }
    crate::args::check_fps(args.fps)?;
    scene.shutter = (s / args.fps) as f32;
    let path = job.scene_path.display();
    let moving_instances = scene.instances.iter().any(|i| i.is_animated());
    if !moving_instances && scene.camera_motions.is_empty() {
        return Ok(());
    }
    if !job.settings.integrator.build().motion_blur() {
        bail!(
            "{path}: --shutter: the {} integrator cannot motion blur (wavefront, path, path-bsdf, direct and ao can)",
            job.settings.integrator
        );
    }
    if moving_instances && !job.settings.accel.kind.is_two_level() {
        bail!(
            "{path}: --shutter: --accel {} holds the scene at one time; motion blur needs two-level or clusters",
            job.settings.accel
        );
    }
    Ok(())
}

/// The frames to render: `None` for a plain render (the scene at time 0).
fn frame_list(args: &Args, output: &Path) -> Result<Vec<Option<u32>>> {
    if args.frames.is_none() && args.frame.is_none() {
        return Ok(vec![None]);
    }
    crate::args::check_fps(args.fps)?;
    match (&args.frames, args.frame) {
        (Some(r), _) => {
            if !output.to_string_lossy().contains("{frame") {
                bail!(
                    "{}: --frames needs an output that names the frame, e.g. -o 'out/frame_{{frame:04}}.exr'",
                    output.display()
                );
            }
            Ok(r.clone().map(Some).collect())
        }
        (None, f) => Ok(vec![f]),
    }
}

/// Renders one image of `scene` as it is now and writes it; prints the summary line.
/// `times`: the scene's load and the structure's build (or update) for this image.
fn render_one(
    args: &Args,
    job: &Job,
    scene: &Scene,
    pool: &rayon::ThreadPool,
    accel: &dyn Accel,
    cache: Option<Arc<dyn RadianceCache>>,
    (load_time, build_time): (std::time::Duration, std::time::Duration),
) -> Result<()> {
    let scene_hash = job.scene_hash.as_deref();
    let load_secs = load_time.as_secs_f64();
    let camera = pick_camera(scene, &job.scene_path, job.camera.as_deref())?;
    let build_secs = build_time.as_secs_f64();
    let integrator = crate::cache::technique(&job.settings.integrator, cache)?;
    let ctx = Ctx {
        scene,
        accel,
        camera,
    };
    if args.gree.is_some() {
        return pool.install(|| crate::gree::render(args, job, &ctx, integrator.as_ref()));
    }
    let denoiser = single_frame_denoiser(args, job)?;
    let denoise_aovs = denoiser
        .as_ref()
        .map_or(AovSet::default(), |d| AovSet::for_channels(d.needs()));
    if denoise_aovs.any_split() && !integrator.writes_split() {
        bail!(
            "{}: it reads the lighting split, which the {} technique does not write",
            denoiser_label(args, job),
            job.settings.integrator
        );
    }
    let mut film = Film::new(
        camera.width,
        camera.height,
        film_buffers(job, denoiser.as_deref()),
    );
    let slice = crate::parts::slice_of(args, job, camera, &film)?;
    let pass = SamplePass {
        indices: slice
            .as_ref()
            .map_or(0..job.settings.spp, |s| s.samples.clone()),
        stream: rt_core::SampleStream::Render,
        pixels: slice
            .as_ref()
            .and_then(|s| s.mask(camera.width, camera.height)),
        centre_first: false,
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
    let mut adaptive = None;
    let mut interrupted = None;
    let checkpointer = scene_hash.map(|scene_hash| crate::checkpoint::Checkpointer {
        args,
        job,
        camera,
        scene_hash,
    });
    let stats: RenderStats = match (&job.stop, &checkpointer) {
        (None, Some(ck)) if args.checkpoint.is_some() => {
            let start = match &job.resume {
                Some((path, part)) => {
                    let fresh = ck.part(&film, 1);
                    let name = path.display().to_string();
                    crate::checkpoint::restore(part, &fresh, &mut film, &name)?
                }
                None => 0,
            };
            bar.set_length(u64::from(job.settings.spp));
            bar.set_position(u64::from(start));
            let (stats, stop) = pool.install(|| {
                ck.render(
                    &ctx,
                    integrator.as_ref(),
                    &mut film,
                    start..job.settings.spp,
                    &|k| bar.set_position(u64::from(k)),
                )
            })?;
            interrupted = stop;
            stats
        }
        (None, _) => pool.install(|| {
            integrator.render_pass(&ctx, &mut film, job.settings.seed, &pass, &|rows| {
                bar.set_position(rows as u64)
            })
        }),
        (Some(rule), _) => {
            let rows = camera.height as f64;
            let a = pool.install(|| {
                render_adaptive(
                    &ctx,
                    integrator.as_ref(),
                    &mut film,
                    job.settings.seed,
                    rule,
                    &|f| bar.set_position((f * rows) as u64),
                )
            })?;
            let stats = a.stats;
            adaptive = Some(a);
            stats
        }
    };
    bar.finish_and_clear();

    if let (Some(slice), Some(hash)) = (&slice, scene_hash) {
        let seconds = stats.elapsed.as_secs_f64();
        crate::parts::write(args, job, camera, &film, slice, (hash, seconds))?;
        if !job.quiet {
            println!(
                "{}: samples {}..{} of pixels {} ({} {}, {:.2} s render, {} invalid samples discarded) -> {}",
                job.scene_path.display(),
                slice.samples.start,
                slice.samples.end,
                slice.region,
                integrator.name(),
                job.settings.accel,
                stats.elapsed.as_secs_f64(),
                stats.discarded,
                job.output.display()
            );
        }
        return Ok(());
    }
    // `--stats`: one row per stage, after the image is written.
    let report = |film: &rt_film::Film, write_time| {
        if args.stats {
            print!(
                "{}",
                RenderReport::collect(&ReportInputs {
                    scene,
                    camera,
                    accel,
                    accel_spec: job.settings.accel.to_string(),
                    film,
                    render: &stats,
                    technique: &integrator.stages(),
                    load_time,
                    accel_time: build_time,
                    write_time,
                    output: &job.output,
                })
            );
        }
    };
    if let Some(d) = &denoiser {
        let t = Instant::now();
        write_denoised(
            &mut film,
            d.as_ref(),
            &job.output,
            job.exposure,
            &job.scene_path,
        )?;
        let denoise_time = t.elapsed();
        // The denoiser's time stands where the plain image's write would.
        report(&film, denoise_time);
        if !job.quiet {
            println!(
                "{}: {}x{} {} spp {} ({:.2} s render), denoised by {} in {:.3} s -> {}",
                job.scene_path.display(),
                camera.width,
                camera.height,
                stats.samples / (camera.width as u64 * camera.height as u64).max(1),
                integrator.name(),
                stats.elapsed.as_secs_f64(),
                d.name(),
                denoise_time.as_secs_f64(),
                job.output.display()
            );
        }
        return end_checkpoint(args, job, interrupted);
    }
    let t_write = Instant::now();
    let extra = match adaptive.as_ref() {
        Some(a) if job.settings.aovs.blocks => block_channels(a, &film),
        _ => Vec::new(),
    };
    rt_film::write_image_with(
        &job.output,
        &film,
        &OutputOptions {
            exposure: job.exposure,
        },
        &extra,
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let write_time = t_write.elapsed();
    if !job.quiet {
        let sampling = match &adaptive {
            None => format!("{} spp", job.settings.spp),
            Some(a) => format!(
                "adaptive: {} after {} spp, {} samples, {} blocks left, {:.3} s deciding;",
                a.reason,
                a.spp,
                a.stats.samples,
                a.active_blocks.len(),
                a.decisions.as_secs_f64()
            ),
        };
        print_summary(
            job,
            scene,
            camera,
            accel,
            integrator.as_ref(),
            &sampling,
            &stats,
            load_secs,
            build_secs,
            pool.current_num_threads(),
        );
    }
    report(&film, write_time);
    end_checkpoint(args, job, interrupted)
}

/// After the image is written: an interrupted render says so and fails; a finished one
/// removes its checkpoint (everything in it is in the image).
fn end_checkpoint(
    args: &Args,
    job: &Job,
    interrupted: Option<crate::checkpoint::Interrupted>,
) -> Result<()> {
    let Some(path) = &args.checkpoint else {
        return Ok(());
    };
    if let Some(i) = interrupted {
        bail!(
            "interrupted by {} after {} of {} samples per pixel: wrote {} and the checkpoint {} (render --resume {} continues)",
            i.signal,
            i.samples,
            job.settings.spp,
            job.output.display(),
            path.display(),
            path.display()
        );
    }
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            bail!("--checkpoint {}: cannot remove it: {e}", path.display())
        }
        _ => Ok(()),
    }
}

/// Denoises the film with `d` and writes the image: the end of a render with `--denoiser`, and
/// of `render merge` for one.
pub(crate) fn write_denoised(
    film: &mut Film,
    d: &dyn rt_denoise::Denoiser,
    output: &Path,
    exposure: f32,
    scene: &Path,
) -> Result<()> {
    let frame =
        rt_film::NoisyFrame::from_film_taking_samples(film, AovSet::for_channels(d.needs()));
    let image = d
        .denoise(&frame)
        .map_err(|e| anyhow::anyhow!("{}: {e}", scene.display()))?;
    rt_film::write_rgb(output, &image, &OutputOptions { exposure })?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn print_summary(
    job: &Job,
    scene: &Scene,
    camera: &rt_core::Camera,
    accel: &dyn Accel,
    integrator: &dyn Technique,
    sampling: &str,
    stats: &RenderStats,
    load_secs: f64,
    build_secs: f64,
    threads: usize,
) {
    // Always printed, zero included: a valid scene must discard nothing, and a reader should
    // not have to know that silence means zero.
    println!(
        "{}: {}x{} {} {} {} ({} tris, {} threads): {:.2} s render ({:.2} s load, {:.2} s {} build), \
         {:.2} Msamples/s, {:.2} Mrays/s, {} invalid samples discarded -> {}",
        job.scene_path.display(),
        camera.width,
        camera.height,
        sampling,
        integrator.name(),
        job.settings.accel,
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

/// The `blocks` AOV: each pixel's final block (`blocks.index`), its sample count
/// (`blocks.spp`; light-path techniques sample every pixel alike, so it is the passes' samples
/// per pixel) and whether its block met the threshold (`blocks.converged`, 0 or 1).
fn block_channels(a: &Adaptive, film: &Film) -> Vec<(&'static str, Vec<f32>)> {
    let Some(map) = a.block_map(film.width(), film.height()) else {
        return Vec::new();
    };
    let spp: Vec<f32> = if film.light_paths() > 0 {
        vec![a.spp as f32; map.index.len()]
    } else {
        film.pixels().map(|p| p.count() as f32).collect()
    };
    vec![
        (
            "blocks.index",
            map.index.iter().map(|&i| i as f32).collect(),
        ),
        ("blocks.spp", spp),
        (
            "blocks.converged",
            map.converged
                .iter()
                .map(|&c| f32::from(u8::from(c)))
                .collect(),
        ),
    ]
}
