//! `rt-experiment`: measured rendering experiments, the machinery behind `render reference` and
//! `render experiment`, usable without the CLI.
//!
//! - [`config`]: the experiment file (TOML; docs/experiments.md) read and validated into a
//!   [`Plan`] before the first sample: scenes load, cameras exist, budgets are sane.
//! - [`reference`](mod@reference) and [`cache`]: high-sample references from their own random streams, stored
//!   on disk under a key that changes with anything that changes the image.
//! - [`grid`]: every method on every scene, rendered progressively to its budgets (`spp`,
//!   `seconds`) or, for an adaptive method, once per stopping rule (`error` and `time_limit`
//!   with `spp` as the cap, as `render --error --time-limit --spp` stop), each a
//!   [`rt_session::RenderJob`] that hands the grid its film at every stop, and measured
//!   against the reference.
//! - [`fit`]: log-log slopes and interpolation; [`report`]: results.csv, slopes.csv, equal-time
//!   and equal-samples comparisons (the samples adaptive runs actually took), crops and
//!   report.md; [`plot`]: the log-log error plots.
//! - [`views`] and [`html`]: report.html, the page with the plots, the tables and a zoomable
//!   image comparison per scene (display PNGs of the references, the final, noisy and error
//!   images).
//! - A method may name a denoiser (`rt-denoise`); its images are denoised after each budget
//!   and measured as denoised, with the noisy error and the denoising time kept beside.
//! - [`sequence`] and [`seqreport`]: sequence experiments (scenes with `frames = [A, B]`):
//!   every method runs a job whose frames render in order
//!   (`rt_session::RenderJob::render_sequence`, denoised by SVGF or a per-frame denoiser),
//!   each frame measured against its own reference frame, with
//!   the temporal metrics of `rt_metrics::temporal`; frames.csv, sequences.csv, plots over
//!   frames, stills.
//!
//! [`run`] does all of it into one output folder. Beside it: [`bench`](mod@bench), the
//! acceleration-structure benchmarks (`render bench-accel`, `render bench-anim`); [`compare`],
//! the image and sequence comparisons of `render compare`; [`merge`], part files merged into
//! an image or the reference cache; [`csv`], the one CSV cell quoting.
//!
//! Depends on `rt-session` (progressive rendering of one configuration), `rt-metrics`
//! (errors, error images), `rt-denoise` (denoisers), `rt-film` (image files), `rt-scene`, `rt-accel`, `rt-integrators` and `rt-core`;
//! `plotters` draws, `sha2` keys the cache, `toml`/`serde` read the file.
//!
//! ```no_run
//! // Run configs/convergence.toml into a fresh folder, as `render experiment` does.
//! let plan = rt_experiment::config::load("configs/convergence.toml".as_ref())?;
//! let cache = rt_experiment::Cache::new(rt_experiment::DEFAULT_CACHE_DIR.as_ref());
//! let out = std::path::Path::new("experiments/mine");
//! rt_experiment::prepare_out(out)?;
//! let outcome = rt_experiment::run(&plan, out, &cache, &rt_experiment::Silent)?;
//! println!("{}", outcome.report.display());
//! # Ok::<(), rt_experiment::ExperimentError>(())
//! ```
#![forbid(unsafe_code)]

pub mod bench;
pub mod cache;
pub mod compare;
pub mod config;
pub mod csv;
mod error;
pub mod fit;
pub mod grid;
pub mod html;
pub mod merge;
mod method_job;
pub mod plot;
pub mod reference;
pub mod report;
pub mod seqreport;
pub mod sequence;
pub mod views;

pub use cache::{Cache, ReferenceRequest, CACHE_VERSION, DEFAULT_CACHE_DIR};
pub use config::Plan;
pub use error::{ExperimentError, Result};

use crate::error::io;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// Where a long run reports how far it is. Called from worker threads, hence `Sync`. Every
/// method does nothing by default.
pub trait Progress: Sync {
    /// The total amount of work, in the units of [`Progress::set_position`].
    fn set_length(&self, _units: u64) {}
    /// Work done so far.
    fn set_position(&self, _units: u64) {}
    /// What is running now.
    fn set_message(&self, _text: String) {}
    /// One line of information for the user.
    fn message(&self, _line: &str) {}
}

/// A job's progress ([`rt_session::JobSink::progress`]) handed to a closure, e.g. one that
/// moves a [`Progress`] bar.
pub(crate) struct ProgressSink<'a>(pub &'a (dyn Fn(f64) + Sync));

impl rt_session::JobSink for ProgressSink<'_> {
    fn progress(&self, done: f64) {
        (self.0)(done)
    }
}

/// A [`Progress`] that reports nothing.
pub struct Silent;

impl Progress for Silent {}

/// The UTC calendar date and time of `secs` since the Unix epoch (Howard Hinnant's
/// civil-from-days), so that no date crate is needed for a time stamp.
pub fn utc(secs: u64) -> (i64, u32, u32, u32, u32, u32) {
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

/// `experiments/NAME-YYYYMMDD-HHMMSS` for the current UTC time: the default output folder.
pub fn default_out_dir(plan: &Plan) -> PathBuf {
    let (y, mo, d, h, mi, s) = utc(now_secs());
    PathBuf::from("experiments").join(format!(
        "{}-{y:04}{mo:02}{d:02}-{h:02}{mi:02}{s:02}",
        plan.name
    ))
}

fn now_secs() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// Refuses an output folder that already holds files, so no earlier result is overwritten;
/// creates it otherwise.
pub fn prepare_out(out: &Path) -> Result<()> {
    if out.exists() {
        let mut entries = std::fs::read_dir(out).map_err(io(out))?;
        if entries.next().is_some() {
            return Err(ExperimentError::Run(format!(
                "{}: the output folder is not empty; choose another --out or remove it",
                out.display()
            )));
        }
    }
    std::fs::create_dir_all(out).map_err(io(out))
}

/// What [`run`] produced.
pub struct Outcome {
    /// Every run's measurements and the references.
    pub results: grid::Results,
    /// The equal-time comparison of each scene.
    pub equal_time: Vec<report::EqualTime>,
    /// The equal-samples comparison of each scene (mean samples per pixel actually taken).
    pub equal_samples: Vec<report::EqualTime>,
    /// The Markdown report (inside the output folder).
    pub report: PathBuf,
    /// The HTML report (inside the output folder).
    pub html: PathBuf,
    /// A sequence experiment's measurements (then `results` holds no rows).
    pub sequences: Option<sequence::SequenceResults>,
}

impl Outcome {
    /// Per scene, the method with the lowest relMSE at equal time most often, one line each.
    pub fn winners(&self, plan: &Plan) -> Vec<String> {
        let mut lines = Vec::new();
        for e in &self.equal_time {
            if let Some((p, wins)) = e.overall() {
                lines.push(format!(
                    "{}: lowest relMSE at equal time: {} ({wins} of {} times)",
                    plan.scenes[e.scene].name,
                    plan.methods[plan.pairs[p].method].name,
                    e.table.len()
                ));
            }
        }
        lines
    }

    /// What ran: `N runs`, or `N frames of M sequences`.
    pub fn runs(&self) -> String {
        match &self.sequences {
            Some(s) => format!(
                "{} frames of {} sequences",
                s.frames.len(),
                s.sequences.len()
            ),
            None => format!("{} runs", self.results.rows.len()),
        }
    }
}

/// Runs `plan` (its file is copied beside the results) into the folder `out`
/// (see [`prepare_out`]): references, the grid, images, results.csv, slopes.csv, plots, crops,
/// report.md and report.html with its pictures. Call it inside the thread pool that should do
/// the work.
pub fn run(plan: &Plan, out: &Path, cache: &Cache, progress: &dyn Progress) -> Result<Outcome> {
    let wall = Instant::now();
    let (y, mo, d, h, mi, _) = utc(now_secs());
    let started = (y, mo, d, h, mi);
    if plan.is_sequence() {
        let results = sequence::run(plan, out, cache, progress)?;
        seqreport::plots(plan, &results, out)?;
        rt_film::write_bytes_atomic(
            &out.join("frames.csv"),
            seqreport::frames_csv(plan, &results).as_bytes(),
        )?;
        rt_film::write_bytes_atomic(
            &out.join("sequences.csv"),
            seqreport::sequences_csv(plan, &results).as_bytes(),
        )?;
        rt_film::copy_atomic(&plan.path, &out.join("config.toml"))?;
        let info = report::RunInfo::now(started, wall.elapsed());
        let report = out.join("report.md");
        rt_film::write_bytes_atomic(
            &report,
            seqreport::markdown(plan, &results, &info).as_bytes(),
        )?;
        let html = out.join("report.html");
        rt_film::write_bytes_atomic(&html, seqreport::html(plan, &results, &info).as_bytes())?;
        return Ok(Outcome {
            results: grid::Results {
                references: Vec::new(),
                rows: Vec::new(),
                finals: Vec::new(),
                noisy_finals: Vec::new(),
            },
            equal_time: Vec::new(),
            equal_samples: Vec::new(),
            report,
            html,
            sequences: Some(results),
        });
    }
    let results = grid::run(plan, out, cache, progress)?;
    let slopes = report::slopes(plan, &results);
    let equal_time = report::equal_time(plan, &results);
    let equal_samples = report::equal_samples(plan, &results);
    report::plots(plan, &results, out)?;
    let blocks = report::crops(plan, &results, out)?;
    rt_film::write_bytes_atomic(
        &out.join("results.csv"),
        report::results_csv(plan, &results).as_bytes(),
    )?;
    rt_film::write_bytes_atomic(
        &out.join("slopes.csv"),
        report::slopes_csv(plan, &slopes).as_bytes(),
    )?;
    rt_film::copy_atomic(&plan.path, &out.join("config.toml"))?;
    let info = report::RunInfo::now(started, wall.elapsed());
    let md = report::markdown(
        plan,
        &results,
        &slopes,
        &equal_time,
        &equal_samples,
        &blocks,
        &info,
    );
    let report = out.join("report.md");
    rt_film::write_bytes_atomic(&report, md.as_bytes())?;
    let views = views::write(plan, &results, out)?;
    let page = html::page(&html::Page {
        plan,
        results: &results,
        slopes: &slopes,
        equal_time: &equal_time,
        equal_samples: &equal_samples,
        views: &views,
        info: &info,
    });
    let html = out.join("report.html");
    rt_film::write_bytes_atomic(&html, page.as_bytes())?;
    Ok(Outcome {
        results,
        equal_time,
        equal_samples,
        report,
        html,
        sequences: None,
    })
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

    /// An adaptive method next to a uniform one: each threshold is its own render, its row
    /// gives the samples actually taken, and the report and results.csv say so.
    #[test]
    fn adaptive_methods_report_the_samples_they_took() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("x.toml");
        std::fs::write(
            &config,
            r#"
[[scene]]
path = "gen:rotated"
resolution = [24, 16]
reference = { spp = 32 }

[[method]]
name = "uniform"
spp = [2, 4, 8]

[[method]]
name = "adaptive"
error = [0.5, 0.05]
spp = 8

[[method]]
name = "timed"
time_limit = 0.01
spp = 4
"#,
        )
        .unwrap();
        let plan = config::load(&config).unwrap();
        let out = dir.path().join("out");
        prepare_out(&out).unwrap();
        let outcome = run(&plan, &out, &Cache::new(&dir.path().join("cache")), &Silent).unwrap();
        let rows = &outcome.results.rows;
        assert_eq!(rows.len(), 3 + 2 + 1);
        let pixels = 24.0 * 16.0;
        for r in rows {
            let name = &plan.methods[plan.pairs[r.pair].method].name;
            assert!(r.samples > 0 && r.spp <= 8, "{name}: {} spp", r.spp);
            assert!(
                (r.mean_spp - r.samples as f64 / pixels).abs() < 1e-9,
                "{name}"
            );
            assert_eq!(r.stop.is_some(), name != "uniform", "{name}");
            assert!(out.join(&r.image).exists(), "{}", r.image);
        }
        let adaptive: Vec<&grid::Row> = rows
            .iter()
            .filter(|r| r.stop.is_some_and(|a| a.rule.error == Some(0.05)))
            .collect();
        assert_eq!(adaptive.len(), 1);
        let a = adaptive[0].stop.unwrap();
        assert_eq!((adaptive[0].budget, a.rule.max_spp), (0.05, 8));
        // Adaptive renders never take more than the cap, and with a threshold they stop
        // sampling finished blocks, so the mean is at most the cap.
        assert!(adaptive[0].mean_spp <= 8.0);
        let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
        assert!(csv.lines().next().unwrap().ends_with(
            "samples,mean_spp,error,time_limit,spp_cap,stop,decide_seconds,blocks_left"
        ));
        assert!(csv.contains("adaptive-e0.05.exr"), "{csv}");
        let md = std::fs::read_to_string(&outcome.report).unwrap();
        assert!(md.contains("### Equal samples"), "{md}");
        assert!(md.contains("blocks left"), "{md}");
    }

    /// A GREE method: each budget is GREE's b, its row counts every sample traced (the noisy
    /// image's and the caches'), times the denoising apart, and measures the composite, which is
    /// the image written next to the noisy frame.
    #[test]
    fn gree_methods_count_every_sample_and_measure_the_composite() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("x.toml");
        std::fs::write(
            &config,
            r#"
[[scene]]
path = "gen:rotated"
resolution = [24, 16]
reference = { spp = 32 }

[[method]]
name = "g"
spp = [4, 8]
gree = "sparsity=0.9"
bank = ["box:radius=0", "box:radius=2"]
"#,
        )
        .unwrap();
        let plan = config::load(&config).unwrap();
        let out = dir.path().join("out");
        prepare_out(&out).unwrap();
        let outcome = run(&plan, &out, &Cache::new(&dir.path().join("cache")), &Silent).unwrap();
        let rows = &outcome.results.rows;
        assert_eq!(rows.len(), 2);
        let pixels = 24 * 16;
        for (r, b) in rows.iter().zip([4u32, 8]) {
            let spec: rt_session::GreeSpec = "sparsity=0.9".parse().unwrap();
            let params = spec.params(b, 0).unwrap();
            let budget = params.budget_split();
            assert_eq!(r.spp, b);
            assert_eq!(r.samples, budget.total_samples(pixels));
            assert!(
                r.samples > u64::from(budget.n) * pixels as u64,
                "caches are counted"
            );
            assert!(r.denoise_seconds > 0.0 && r.raw.is_some());
            let got = rt_film::read_rgb(&out.join(r.denoised_image.as_ref().unwrap())).unwrap();
            let reference = &outcome.results.references[0].image;
            let m = rt_metrics::compare(&got, reference, &Default::default()).unwrap();
            assert_eq!(m.relmse, r.metrics.relmse);
        }
        // An unknown GREE option or a bad bank is refused when the file loads.
        for (bad, says) in [("sparsity=2", "sparsity"), ("colour=1", "unknown option")] {
            let text = std::fs::read_to_string(&config)
                .unwrap()
                .replace("sparsity=0.9", bad);
            std::fs::write(&config, text).unwrap();
            let e = config::load(&config).err().unwrap().to_string();
            assert!(e.contains(says), "{e}");
            std::fs::write(
                &config,
                std::fs::read_to_string(&config)
                    .unwrap()
                    .replace(bad, "sparsity=0.9"),
            )
            .unwrap();
        }
    }

    /// A denoised method next to the same method without: its rows carry the denoised error
    /// (of the image the denoiser makes from the saved noisy frame, bit for bit), the noisy
    /// error beside it, in results.csv and both reports.
    #[test]
    fn denoised_methods_are_measured_after_denoising() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("x.toml");
        std::fs::write(
            &config,
            r#"
[[scene]]
path = "gen:rotated"
resolution = [24, 16]
reference = { spp = 32 }

[[method]]
name = "plain"
spp = [1, 4]

[[method]]
name = "boxed"
spp = [1, 4]
denoiser = "box:radius=1"
"#,
        )
        .unwrap();
        let plan = config::load(&config).unwrap();
        let out = dir.path().join("out");
        prepare_out(&out).unwrap();
        let outcome = run(&plan, &out, &Cache::new(&dir.path().join("cache")), &Silent).unwrap();
        let rows = &outcome.results.rows;
        assert_eq!(rows.len(), 4);
        let (plain, boxed) = rows.split_at(2);
        let denoiser = "box:radius=1"
            .parse::<rt_denoise::DenoiserSpec>()
            .unwrap()
            .build()
            .unwrap();
        for (p, b) in plain.iter().zip(boxed) {
            assert!(p.raw.is_none() && p.denoised_image.is_none() && p.denoise_seconds == 0.0);
            // Same seed and settings: the noisy images are the same, so the noisy error of
            // the denoised method is the plain method's error.
            assert_eq!(b.raw, Some(p.metrics));
            assert_ne!(b.metrics, p.metrics);
            assert!(b.denoise_seconds > 0.0);
            assert_eq!(b.total_seconds(), b.seconds + b.denoise_seconds);
            let noisy = rt_denoise::NoisyFrame::from_exr(&out.join(&b.image)).unwrap();
            let want = denoiser.denoise(&noisy).unwrap();
            let got = rt_film::read_rgb(&out.join(b.denoised_image.as_ref().unwrap())).unwrap();
            assert_eq!(got, want, "{}", b.image);
            let reference = &outcome.results.references[0].image;
            let m = rt_metrics::compare(&got, reference, &Default::default()).unwrap();
            assert_eq!(m.relmse, b.metrics.relmse);
        }
        assert_eq!(outcome.results.finals[1], {
            let last = &boxed[1];
            rt_film::read_rgb(&out.join(last.denoised_image.as_ref().unwrap())).unwrap()
        });
        assert!(
            outcome.results.noisy_finals[1].is_some() && outcome.results.noisy_finals[0].is_none()
        );
        let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
        let mut lines = csv.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert!(
            csv.lines()
                .next()
                .unwrap()
                .ends_with(report::DENOISE_COLUMNS),
            "{csv}"
        );
        let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
        let cells: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(cells[3][col("denoiser")], "box:radius=1");
        assert_eq!(
            cells[3][col("raw_relmse")],
            boxed[1].raw.unwrap().relmse.to_string()
        );
        assert_eq!(cells[3][col("relmse")], boxed[1].metrics.relmse.to_string());
        assert_eq!(cells[1][col("raw_relmse")], "");
        assert!(cells[3][col("denoised_image")].ends_with("boxed-4spp-denoised.exr"));
        let md = std::fs::read_to_string(&outcome.report).unwrap();
        assert!(
            md.contains("noisy relMSE") && md.contains("### Equal samples"),
            "{md}"
        );
        let html = std::fs::read_to_string(&outcome.html).unwrap();
        assert!(html.contains("view/rotated/boxed/noisy.png"), "{html}");
        assert!(!html.contains("view/rotated/plain/noisy.png"));

        // Equal time is at render + denoise time: with render times set to 1 and 4 s for both
        // methods and 1 s of denoising, the boxed curve spans 2..5 s, so the times compared
        // start at 2 s, where the boxed error is its first run's.
        let mut results = outcome.results;
        for r in &mut results.rows {
            r.seconds = if r.spp == 1 { 1.0 } else { 4.0 };
            if r.raw.is_some() {
                r.denoise_seconds = 1.0;
            }
        }
        let e = &report::equal_time(&plan, &results)[0];
        assert_eq!(e.table.first().map(|t| t.0), Some(2.0));
        let boxed_first = results.rows[2].metrics.relmse;
        assert!((e.table[0].1[1] - boxed_first).abs() <= 1e-9 * boxed_first);
        // Past every plain run's time, nothing is compared; at equal samples all still is.
        for r in results.rows.iter_mut().filter(|r| r.raw.is_some()) {
            r.denoise_seconds = 10.0;
        }
        assert!(report::equal_time(&plan, &results)[0].table.is_empty());
        assert!(!report::equal_samples(&plan, &results)[0].table.is_empty());
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
