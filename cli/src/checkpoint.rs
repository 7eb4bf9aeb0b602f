//! `--checkpoint` and `--resume`: a long render that loses nothing.
//!
//! The render runs one sample per pixel per pass (passes add up to the bits of one pass, and
//! the film's sums are exact, so where it stops does not matter). After a pass it writes the
//! checkpoint, a part file of kind `checkpoint` holding the sums so far, when
//! `--checkpoint-every` seconds have passed or SIGINT or SIGTERM has arrived; on a signal it
//! stops there, and the caller writes the image so far and exits non-zero. A resumed render
//! starts from the checkpoint's sums at its next sample index.

use crate::args::Args;
use crate::job::Job;
use anyhow::{bail, Result};
use rt_film::{Film, Rect};
use rt_integrators::{Ctx, RenderStats, SamplePass, Technique};
use rt_parts::{Part, PartKind};
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The signal that stopped a render.
#[derive(Clone, Copy, Debug)]
pub struct Interrupted {
    /// Its name.
    pub signal: &'static str,
    /// Samples per pixel taken.
    pub samples: u32,
}

/// Watches SIGINT and SIGTERM: the first is noted for the next pass boundary, a second ends
/// the process at once (exit status 130).
fn watch_signals() -> Result<Arc<AtomicUsize>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let which = Arc::new(AtomicUsize::new(0));
    let seen = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // Registered first, so it runs before `seen` is set by this same signal.
        signal_hook::flag::register_conditional_shutdown(sig, 130, seen.clone())?;
        signal_hook::flag::register(sig, seen.clone())?;
        signal_hook::flag::register_usize(sig, which.clone(), sig as usize)?;
    }
    Ok(which)
}

fn signal_name(sig: usize) -> &'static str {
    match sig as i32 {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// Refuses `--checkpoint` with what it cannot resume exactly.
pub fn check(args: &Args, job: &Job) -> Result<()> {
    let Some(path) = &args.checkpoint else {
        return Ok(());
    };
    let p = path.display();
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rpart"))
    {
        bail!("--checkpoint {p}: the file must end in .rpart");
    }
    let refuse = |what: &str| -> Result<()> { bail!("--checkpoint {p}: cannot checkpoint {what}") };
    if job.stop.is_some() {
        return refuse(
            "an adaptive render (--error, --time-limit): its stopping state is not kept",
        );
    }
    if args.frames.is_some() {
        return refuse("a sequence (--frames): checkpoint each frame's render (--frame F)");
    }
    if crate::parts::writes_part(args) {
        return refuse("a part: render smaller parts instead");
    }
    if args.gree.is_some() || args.cache.is_some() {
        return refuse("GREE or a world-space cache: their state is not kept");
    }
    if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
        bail!("--checkpoint-every must be a number of seconds >= 0");
    }
    Ok(())
}

/// Where and how often to write the checkpoint.
pub struct Checkpointer<'a> {
    /// The render's arguments and job (for the header).
    pub args: &'a Args,
    /// The job.
    pub job: &'a Job,
    /// The camera.
    pub camera: &'a rt_core::Camera,
    /// The scene's content hash.
    pub scene_hash: &'a str,
}

impl Checkpointer<'_> {
    /// The checkpoint of a film holding samples `0..samples` of every pixel.
    pub fn part(&self, film: &Film, samples: u32) -> Part {
        let full = Rect::full(film.width(), film.height());
        let slice = crate::parts::Slice {
            samples: 0..samples,
            region: full,
        };
        Part {
            header: crate::parts::header(
                self.args,
                self.job,
                self.camera,
                film,
                &slice,
                self.scene_hash,
                PartKind::Checkpoint,
            ),
            sums: film.encode_sums(full),
        }
    }

    fn write(&self, film: &Film, samples: u32, seconds: f64) -> Result<()> {
        let path = self.args.checkpoint.as_ref().expect("checkpointing");
        let mut part = self.part(film, samples);
        part.header.seconds = seconds;
        part.write(path)
            .map_err(|e| anyhow::anyhow!("--checkpoint {}: {e}", path.display()))
    }

    /// Renders samples `range` into `film` pass by pass, writing checkpoints; stops early at a
    /// pass boundary after SIGINT or SIGTERM (the checkpoint then holds every finished pass).
    pub fn render(
        &self,
        ctx: &Ctx<'_>,
        integrator: &dyn Technique,
        film: &mut Film,
        range: Range<u32>,
        progress: &(dyn Fn(u32) + Sync),
    ) -> Result<(RenderStats, Option<Interrupted>)> {
        let signals = watch_signals()?;
        // Render time of the samples a resumed render started from.
        let before = self
            .job
            .resume
            .as_ref()
            .map_or(0.0, |(_, p)| p.header.seconds);
        let every = Duration::from_secs_f64(self.args.checkpoint_every);
        let mut last = Instant::now();
        let mut stats = RenderStats::default();
        for i in range.clone() {
            let pass = SamplePass {
                indices: i..i + 1,
                stream: rt_core::SampleStream::Render,
                pixels: None,
                centre_first: false,
            };
            stats += integrator.render_pass(ctx, film, self.job.settings.seed, &pass, &|_| {});
            progress(i + 1);
            let sig = signals.load(Ordering::Relaxed);
            if sig != 0 {
                self.write(film, i + 1, before + stats.elapsed.as_secs_f64())?;
                let signal = signal_name(sig);
                return Ok((
                    stats,
                    Some(Interrupted {
                        signal,
                        samples: i + 1,
                    }),
                ));
            }
            if i + 1 < range.end && last.elapsed() >= every {
                self.write(film, i + 1, before + stats.elapsed.as_secs_f64())?;
                last = Instant::now();
            }
        }
        Ok((stats, None))
    }
}

/// `render --resume FILE`: the checkpoint and the arguments it was started with (`--threads`
/// and `-q` from this command line replace theirs).
pub fn resume_args(args: &Args) -> Result<Option<(Args, Part)>> {
    let Some(path) = &args.resume else {
        return Ok(None);
    };
    let p = path.display();
    let part = Part::read(path).map_err(|e| anyhow::anyhow!("{p}: {e}"))?;
    if part.header.kind != PartKind::Checkpoint {
        bail!("{p}: a part, not a checkpoint: merge it with render merge");
    }
    use clap::Parser;
    let argv = std::iter::once("render".to_string()).chain(part.header.args.iter().cloned());
    let mut old = Args::try_parse_from(argv).map_err(|e| {
        anyhow::anyhow!(
            "{p}: its command line no longer parses: {}",
            e.to_string().lines().next().unwrap_or_default()
        )
    })?;
    if old.checkpoint.is_none() {
        bail!("{p}: its command line has no --checkpoint");
    }
    if args.threads.is_some() {
        old.threads = args.threads;
    }
    old.quiet |= args.quiet;
    Ok(Some((old, part)))
}

/// Starts `film` from the checkpoint `part` after checking that it belongs to this render;
/// returns the next sample index.
pub fn restore(part: &Part, fresh: &Part, film: &mut Film, name: &str) -> Result<u32> {
    rt_parts::check_belongs((name, &part.header), ("this render", &fresh.header))
        .map_err(|e| anyhow::anyhow!("--resume: {e}"))?;
    let full = Rect::full(film.width(), film.height());
    film.add_encoded(full, &part.sums, true)
        .map_err(|e| anyhow::anyhow!("--resume {name}: {e}"))?;
    Ok(part.header.samples[1])
}
