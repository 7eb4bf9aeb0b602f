//! `render experiment CONFIG.toml`: a grid of scenes × methods × budgets measured against
//! references, with a CSV of every run, convergence slopes, log-log plots, crops and a Markdown
//! report (docs/experiments.md has the file format and the output layout).
//!
//! `config.rs` reads and validates the file, `grid.rs` runs it, `stats.rs` fits slopes and
//! compares at equal time, `plot.rs` draws, `report.rs` writes the CSVs, crops and report.

mod config;
mod grid;
mod plot;
mod report;
mod stats;

use crate::progress::Progress;
use crate::reference::cache::{Cache, DEFAULT_CACHE_DIR};
use anyhow::{anyhow, bail, Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

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
}

/// A rayon pool of `threads` workers (all cores by default).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        if t == 0 || t > 1024 {
            bail!("--threads must be between 1 and 1024, got {t}");
        }
        pool = pool.num_threads(t);
    }
    pool.build().context("cannot start worker threads")
}

/// The UTC calendar date and time of `secs` since the Unix epoch (Howard Hinnant's
/// civil-from-days), so that no date crate is needed for a time stamp.
fn utc(secs: u64) -> (i64, u32, u32, u32, u32, u32) {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (
        y,
        m,
        d,
        (rem / 3600) as u32,
        (rem / 60 % 60) as u32,
        (rem % 60) as u32,
    )
}

/// Refuses an output folder that already holds files, so no earlier result is overwritten.
fn prepare_out(out: &Path) -> Result<()> {
    if out.exists() {
        let mut entries = std::fs::read_dir(out).map_err(|e| anyhow!("{}: {e}", out.display()))?;
        if entries.next().is_some() {
            bail!(
                "{}: the output folder is not empty; choose another --out or remove it",
                out.display()
            );
        }
    }
    crate::atomic::create_dir(out)
}

/// Runs `render experiment`.
pub fn run(args: &ExperimentArgs) -> Result<()> {
    let wall = Instant::now();
    let plan = config::load(&args.config)?;
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
    let pool = thread_pool(args.threads)?;
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, mo, d, h, mi, s) = utc(now);
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from("experiments").join(format!(
            "{}-{y:04}{mo:02}{d:02}-{h:02}{mi:02}{s:02}",
            plan.name
        ))
    });
    prepare_out(&out)?;
    let progress = Progress::new(
        args.quiet,
        1,
        "{spinner} [{elapsed_precise}] {bar:40} {percent:>3}% {msg} (eta {eta})",
    );
    for w in &plan.warnings {
        progress.message(&format!("warning: {w}"));
    }
    let cache = Cache::new(&args.cache);
    let results = pool.install(|| grid::run(&plan, &out, &cache, &progress))?;
    progress.finish();

    let slopes = report::slopes(&plan, &results);
    let equal = report::equal_time(&plan, &results);
    report::plots(&plan, &results, &out)?;
    let blocks = report::crops(&plan, &results, &out)?;
    crate::atomic::write(
        &out.join("results.csv"),
        report::results_csv(&plan, &results).as_bytes(),
    )?;
    crate::atomic::write(
        &out.join("slopes.csv"),
        report::slopes_csv(&plan, &slopes).as_bytes(),
    )?;
    crate::atomic::copy(&args.config, &out.join("config.toml"))?;
    let info = report::RunInfo {
        started: format!("{y:04}-{mo:02}-{d:02} {h:02}:{mi:02}"),
        threads: pool.current_num_threads(),
        wall_seconds: wall.elapsed().as_secs_f64(),
    };
    let md = report::markdown(&plan, &results, &slopes, &equal, &blocks, &info);
    crate::atomic::write(&out.join("report.md"), md.as_bytes())?;
    for e in &equal {
        if let Some((p, wins)) = e.overall() {
            progress.message(&format!(
                "{}: lowest relMSE at equal time: {} ({wins} of {} times)",
                plan.scenes[e.scene].name,
                plan.methods[plan.pairs[p].method].name,
                e.table.len()
            ));
        }
    }
    progress.message(&format!(
        "{} runs in {:.1} s",
        results.rows.len(),
        wall.elapsed().as_secs_f64()
    ));
    println!("{}", out.join("report.md").display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates() {
        assert_eq!(utc(0), (1970, 1, 1, 0, 0, 0));
        // 2000-02-29 12:34:56 (a leap day in a century leap year).
        assert_eq!(utc(951_827_696), (2000, 2, 29, 12, 34, 56));
        // 2026-11-22 00:00:00.
        assert_eq!(utc(1_795_305_600), (2026, 11, 22, 0, 0, 0));
    }

    #[test]
    fn output_folders_are_never_overwritten() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a/b");
        prepare_out(&out).unwrap();
        prepare_out(&out).unwrap();
        std::fs::write(out.join("results.csv"), "x").unwrap();
        let e = prepare_out(&out).unwrap_err().to_string();
        assert!(e.contains("not empty"), "{e}");
    }
}
