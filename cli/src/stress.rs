//! `render stress`: the numerical stress suite (`rt_validate::stress`) with a large budget.
//!
//! The cases are the ones `cargo test` runs with a small budget (`tests/tests/stress.rs`):
//! transformed scenes compared within noise, self-intersection counts, bad geometry. One line
//! per case; the exit code is 1 if any case fails. See `docs/experiments.md`, "Numerical
//! stress tests".

use anyhow::{bail, Result};
use rt_validate::stress::{cases_named, run_cases, Budget};
use std::path::PathBuf;
use std::time::Instant;

/// `render stress` arguments.
#[derive(clap::Args, Debug)]
pub struct StressArgs {
    /// The long run: more samples, rays and pixels, and the extreme transformations (10⁻⁶,
    /// 10⁶, 10⁷ from the origin); about two minutes on two cores. Without it, the budget of
    /// `cargo test` (a few seconds).
    #[arg(long)]
    pub long: bool,
    /// Samples per pixel of every render. [default: 256, or 1024 with --long]
    #[arg(long)]
    pub spp: Option<u32>,
    /// Seed of every render and random ray set.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Only the cases whose name starts with this (e.g. `transform/`, `bad/`, `self-hit/`).
    #[arg(long, value_name = "PREFIX", default_value = "")]
    pub only: String,
    /// Directory of the shared test meshes (for the conference room's case).
    #[arg(long, value_name = "DIR", default_value = "../shared/data")]
    pub data: PathBuf,
    /// Worker threads. [default: all cores]
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs the suite and prints one line per case.
pub fn run(args: &StressArgs) -> Result<()> {
    let mut budget = if args.long {
        Budget::long()
    } else {
        Budget::ci()
    };
    if let Some(spp) = args.spp {
        if spp == 0 || spp > 1 << 16 {
            bail!("--spp: samples per pixel must be between 1 and 65536, got {spp}");
        }
        budget.spp = spp;
    }
    budget.data_dir = Some(args.data.clone());
    let cases = cases_named(&args.only);
    if cases.is_empty() {
        bail!("--only {}: no stress case has that prefix", args.only);
    }
    let pool = rt_session::job::thread_pool(args.threads)?;
    println!(
        "stress ({}): {} spp, {}x{} images, {} rays per surface, seed {}",
        if args.long { "long" } else { "short" },
        budget.spp,
        budget.resolution,
        budget.resolution,
        budget.rays_per_surface,
        args.seed
    );
    let start = Instant::now();
    let failed = run_cases(&cases, &budget, args.seed, &pool, &mut |r| println!("{r}"));
    println!(
        "{} passed, {} failed ({:.1} s)",
        cases.len() - failed.len(),
        failed.len(),
        start.elapsed().as_secs_f64()
    );
    if !failed.is_empty() {
        bail!("stress cases failed: {}", failed.join(", "));
    }
    Ok(())
}
