//! `render SCENE [flags]`: the flags become an `rt_session::RenderJob`, which the library
//! runs; this prints its reports (a progress bar, the summary lines, `--stats`) and turns
//! SIGINT and SIGTERM into the job's stop flag when it checkpoints. `render --resume FILE`
//! runs the job a checkpoint holds; `render part` (`parts.rs`) a plan's.

use crate::args::Args;
use crate::progress::Progress;
use anyhow::{anyhow, Result};
use rt_session::{
    Checkpointing, FrameReport, Frames, GreeJob, JobError, JobScene, JobSink, Overrides, RenderJob,
    Rendered, Slice, StopRule, MAX_SPP,
};
use std::time::{Duration, Instant};

/// The job the flags describe, for the scene `loaded` (read from `args.scene`).
pub fn job(args: &Args, loaded: &rt_scene::LoadedScene) -> Result<RenderJob> {
    let scene = args.scene.as_deref().expect("clap requires SCENE");
    let accel = args
        .accel
        .as_ref()
        .map(|a| a.parse().map_err(|e| anyhow!("--accel {a}: {e}")))
        .transpose()?;
    let settings = Overrides {
        integrator: args.integrator,
        max_depth: args.max_depth,
        ao_distance: args.ao_distance,
        spp: args.spp,
        threads: args.threads,
        seed: args.seed,
        accel,
        aovs: args.aov.clone(),
        output: args.output.clone(),
        // GREE chooses among its own bank; the table's denoiser would be a second,
        // conflicting reconstruction (`--denoiser` itself conflicts with `--gree`).
        denoiser: if args.gree.is_some() {
            Some("none".into())
        } else {
            args.denoiser.clone()
        },
    }
    .resolve(loaded, scene)?;
    let mut job = RenderJob::new(scene, settings);
    job.confine = args.confine.clone();
    job.defines = args.define.clone();
    job.camera = args.camera.clone();
    job.frames = match (&args.frames, args.frame) {
        (Some(r), _) => Frames::Range(r.clone()),
        (None, Some(f)) => Frames::One(f),
        (None, None) => Frames::Still,
    };
    (job.fps, job.shutter, job.exposure) = (args.fps, args.shutter, args.exposure);
    if args.error.is_some() || args.time_limit.is_some() {
        let cap = args.spp.unwrap_or(MAX_SPP);
        let rule = StopRule::new(args.error, args.time_limit, cap);
        job.stop = Some(rule.map_err(|e| anyhow!(e.named("--error", "--time-limit")))?);
    }
    job.slice = Slice {
        samples: args.sample_range.clone(),
        region: args.region.map(|r| [r.x0, r.y0, r.x1, r.y1]),
    };
    job.checkpoint = args.checkpoint.as_ref().map(|path| Checkpointing {
        path: path.clone(),
        every: args.checkpoint_every,
    });
    if let Some(text) = &args.cache {
        job.cache = Some(text.parse().map_err(|e| anyhow!("--cache {text}: {e}"))?);
    }
    if let Some(text) = &args.gree {
        job.gree = Some(GreeJob {
            options: text.parse().map_err(|e| anyhow!("--gree {text}: {e}"))?,
            bank: args.bank.clone(),
            labels: args.labels.clone(),
            error_maps: args.error_maps.clone(),
        });
    }
    job.max_memory = args
        .max_memory
        .as_deref()
        .map(rt_session::memory::parse_size)
        .transpose()?;
    job.check()?;
    Ok(job)
}

/// `render SCENE ...` and `render --resume FILE`.
pub fn run(args: &Args) -> Result<()> {
    if let Some(path) = &args.resume {
        let mut job = RenderJob::resume(path)?;
        if args.threads.is_some() {
            job.settings.threads = args.threads;
        }
        return run_job(&job, None, args.quiet, args.stats);
    }
    let scene = args.scene.as_deref().expect("clap requires SCENE");
    let t = Instant::now();
    let loaded = rt_session::load_scene(scene, args.confine.as_deref(), &args.define)?;
    let load = t.elapsed();
    if !args.quiet {
        for w in &loaded.loaded.warnings {
            eprintln!("warning: {w}");
        }
    }
    let job = job(args, &loaded.loaded)?;
    run_job(&job, Some((loaded, load)), args.quiet, args.stats)
}

/// Runs `job` (over `scene` if already loaded), printing its reports; a checkpointed job
/// stops at the next pass on SIGINT or SIGTERM.
pub fn run_job(
    job: &RenderJob,
    scene: Option<(JobScene, Duration)>,
    quiet: bool,
    stats: bool,
) -> Result<()> {
    let signals = if job.checkpoint.is_some() {
        rt_session::signals::StopOnSignal::watch()?
    } else {
        Default::default()
    };
    let stop = &signals.stop;
    let printer = Printer {
        bar: Progress::new(
            quiet,
            1000,
            "{spinner} [{elapsed_precise}] {bar:40} {percent:>3}% (eta {eta})",
        ),
        quiet,
        stats,
    };
    let result = match scene {
        Some((scene, load)) => job.run_loaded(scene, load, &printer, stop),
        None => job.run(&printer, stop),
    };
    printer.bar.finish();
    match result {
        Ok(report) => {
            let line = report.to_string();
            if !quiet && !line.is_empty() {
                println!("{}: {line}", job.scene.display());
            }
            Ok(())
        }
        Err(JobError::Interrupted {
            samples,
            spp,
            output,
            checkpoint,
        }) => {
            let ck = checkpoint.display();
            Err(anyhow!(
                "interrupted by {} after {samples} of {spp} samples per pixel: wrote {} and the checkpoint {ck} (render --resume {ck} continues)",
                signals.signal_name(),
                output.display()
            ))
        }
        Err(e) => Err(e.into()),
    }
}

/// Prints a job's reports: the bar, warnings, a summary line per image and the `--stats`
/// table.
struct Printer {
    bar: Progress,
    quiet: bool,
    stats: bool,
}

impl JobSink for Printer {
    fn progress(&self, done: f64) {
        self.bar.bar().set_position((done * 1000.0) as u64);
    }

    fn warning(&self, text: &str) {
        self.bar.message(&format!("warning: {text}"));
    }

    fn frame(&self, r: &FrameReport) {
        self.bar.bar().suspend(|| {
            let table = r.stages.as_ref().filter(|_| self.stats);
            // A denoised image's table comes first (its denoising stands where the write
            // would); the others' after the summary line. The table prints even with -q.
            if let (Rendered::Denoised { .. }, Some(t)) = (&r.rendered, table) {
                print!("{t}");
            }
            if !self.quiet {
                println!("{r}");
            }
            if let (false, Some(t)) = (matches!(r.rendered, Rendered::Denoised { .. }), table) {
                print!("{t}");
            }
        });
        self.bar.bar().set_position(0);
    }
}
