//! `render experiment CONFIG.toml`: arguments, then `rt_experiment` does the work (a grid of
//! scenes × methods × budgets measured against references, with CSVs, slopes, plots, crops, a
//! Markdown report and an HTML one; docs/experiments.md), and this prints what it found.

use crate::progress::Progress;
use anyhow::Result;
use rt_experiment::{Cache, DEFAULT_CACHE_DIR};
use std::path::PathBuf;
use std::time::Instant;

/// `render experiment` arguments.
#[derive(clap::Args, Debug)]
pub struct ExperimentArgs {
    /// The experiment file (TOML; see docs/experiments.md).
    pub config: PathBuf,

    /// Output folder; it must not exist or be empty. [default: experiments/NAME-YYYYMMDD-HHMMSS]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Reference cache directory.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_CACHE_DIR)]
    pub cache: PathBuf,

    /// Worker threads. Images do not depend on it; times do. [default: all cores]
    #[arg(long)]
    pub threads: Option<usize>,

    /// No progress bar and no messages (the output folder is still printed).
    #[arg(short, long)]
    pub quiet: bool,

    /// Only read and validate the file (loading every scene and resolving every setting), print
    /// the size of the grid and exit: nothing is rendered or written.
    #[arg(long)]
    pub check: bool,

    /// Refuse any file the experiment, its scenes or their references refer to outside DIR
    /// (as `render --confine`).
    #[arg(long, value_name = "DIR")]
    pub confine: Option<PathBuf>,
}

/// Runs `render experiment`.
pub fn run(args: &ExperimentArgs) -> Result<()> {
    let wall = Instant::now();
    let plan = rt_experiment::config::load_confined(&args.config, args.confine.as_deref())?;
    if args.check {
        for w in &plan.warnings {
            eprintln!("warning: {w}");
        }
        println!(
            "{}: valid; {} scenes, {} methods, {} scene-method pairs",
            args.config.display(),
            plan.scenes.len(),
            plan.methods.len(),
            plan.pairs.len()
        );
        return Ok(());
    }
    let pool = rt_session::job::thread_pool(args.threads)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| rt_experiment::default_out_dir(&plan));
    rt_experiment::prepare_out(&out)?;
    let progress = Progress::new(
        args.quiet,
        1,
        "{spinner} [{elapsed_precise}] {bar:40} {percent:>3}% {msg} (eta {eta})",
    );
    for w in &plan.warnings {
        progress.message(&format!("warning: {w}"));
    }
    let cache = Cache::new(&args.cache);
    let outcome = pool.install(|| rt_experiment::run(&plan, &out, &cache, &progress))?;
    progress.finish();
    for line in outcome.winners(&plan) {
        progress.message(&line);
    }
    let runs = outcome.runs();
    progress.message(&format!(
        "{runs} in {:.1} s; to look at them, open {}",
        wall.elapsed().as_secs_f64(),
        outcome.html.display()
    ));
    println!("{}", outcome.report.display());
    Ok(())
}
