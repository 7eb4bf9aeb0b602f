//! What an experiment leaves behind besides its images: results.csv, slopes.csv, the plots,
//! the crops and report.md. Everything is computed from the rows, so the report and the CSV
//! files always agree.

use crate::config::{Plan, Runs};
use crate::error::{io, Result};
use crate::fit::{comparison_times, log_log_interpolate, log_log_slope, Fit};
use crate::grid::{Reference, Results, Row};
use crate::plot::{self, Chart, Series};
use rt_core::{Rgb, RgbImage};
use rt_session::Budgets;
use std::fmt::Write as _;
use std::path::Path;

/// The columns of results.csv, in order. The first thirteen are the fixed part of the format;
/// new metrics are appended.
pub const RESULTS_HEADER: &str = "scene,method,integrator,accel,spp,seconds,rays,\
samples_per_second,mse,relmse,rmse,psnr,ssim,budget,max_depth,seed,mse_floor,relmse_floor,image";

/// The columns appended to [`RESULTS_HEADER`] when the experiment has an adaptive method
/// (`error`, `time_limit`): the samples actually taken over the image and per pixel on average,
/// the rule (empty for progressive rows), why the run stopped, the time of the criterion's
/// decisions and the blocks still sampling.
pub const ADAPTIVE_COLUMNS: &str =
    "samples,mean_spp,error,time_limit,spp_cap,stop,decide_seconds,blocks_left";

/// The columns appended (after [`ADAPTIVE_COLUMNS`], if those are there) when a method has a
/// denoiser: its spec (empty for other methods), the denoising time, render plus denoising
/// time, the noisy image's errors (the main metric columns are the denoised image's) and the
/// denoised image.
pub const DENOISE_COLUMNS: &str = "denoiser,denoise_seconds,total_seconds,raw_mse,raw_relmse,\
raw_rmse,raw_psnr,raw_ssim,denoised_image";

/// True when some method of the plan has a denoiser.
pub fn any_denoiser(plan: &Plan) -> bool {
    plan.methods.iter().any(|m| m.denoiser.is_some())
}

/// The columns of slopes.csv.
pub const SLOPES_HEADER: &str = "scene,method,metric,floor,points,slope_vs_spp,se_vs_spp,\
slope_vs_seconds,se_vs_seconds";

/// How many times (or sample counts) the equal-time (equal-samples) table compares at when no
/// budgets fall in range.
const EQUAL_TIME_POINTS: usize = 5;

/// The reference's own expected contribution to the error: with `b` the reference, the
/// variance of its pixel means averaged like MSE, and divided by `b² + ε` like relMSE. An
/// independent, unbiased image `a` of the same scene has E[MSE(a, b)] = E[MSE(a, truth)] +
/// this, so subtracting it estimates the error against the truth.
pub struct Floor {
    /// MSE floor.
    pub mse: f64,
    /// relMSE floor.
    pub relmse: f64,
}

/// The floor of a reference; `None` when the file has no variance.
pub fn floor(reference: &Reference, epsilon: f64) -> Option<Floor> {
    let var = reference.variance.as_ref()?;
    let n = (var.len() * 3) as f64;
    let (mut mse, mut rel) = (0.0f64, 0.0f64);
    for (v, b) in var.iter().zip(reference.image.pixels()) {
        for c in 0..3 {
            let (v, b) = (f64::from(v[c]), f64::from(b[c]));
            mse += v;
            rel += v / (b * b + epsilon);
        }
    }
    Some(Floor {
        mse: mse / n,
        relmse: rel / n,
    })
}

fn num(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        format!("{v}")
    }
}

/// results.csv; with [`ADAPTIVE_COLUMNS`] when a method is adaptive.
pub fn results_csv(plan: &Plan, results: &Results) -> String {
    let adaptive = plan
        .methods
        .iter()
        .any(|m| matches!(m.runs, Runs::Adaptive(_)));
    let denoised = any_denoiser(plan);
    let mut s = RESULTS_HEADER.to_string();
    if adaptive {
        s += &format!(",{ADAPTIVE_COLUMNS}");
    }
    if denoised {
        s += &format!(",{DENOISE_COLUMNS}");
    }
    s.push('\n');
    for row in &results.rows {
        let pair = &plan.pairs[row.pair];
        let f = floor(&results.references[pair.scene], plan.epsilon);
        let m = &row.metrics;
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            plan.scenes[pair.scene].name,
            plan.methods[pair.method].name,
            pair.estimator.kind,
            pair.accel,
            row.spp,
            row.seconds,
            row.rays,
            row.samples_per_second,
            m.mse,
            m.relmse,
            m.rmse,
            m.psnr,
            m.ssim,
            row.budget,
            pair.estimator.depth(),
            pair.seed,
            f.as_ref().map_or(String::new(), |f| num(f.mse)),
            f.as_ref().map_or(String::new(), |f| num(f.relmse)),
            row.image,
        );
        if adaptive {
            adaptive_cells(&mut s, row);
        }
        if denoised {
            let raw = row.raw.as_ref();
            let cell =
                |f: fn(&rt_metrics::Metrics) -> f64| raw.map_or(String::new(), |m| num(f(m)));
            let _ = write!(
                s,
                ",{},{},{},{},{},{},{},{},{}",
                plan.methods[pair.method]
                    .denoiser
                    .as_ref()
                    .map_or(String::new(), |d| crate::csv::field(&d.to_string())),
                row.denoise_seconds,
                row.total_seconds(),
                cell(|m| m.mse),
                cell(|m| m.relmse),
                cell(|m| m.rmse),
                cell(|m| m.psnr),
                cell(|m| m.ssim),
                row.denoised_image.as_deref().unwrap_or(""),
            );
        }
        s.push('\n');
    }
    s
}

/// The [`ADAPTIVE_COLUMNS`] of one row (empty rule cells for a progressive row).
fn adaptive_cells(s: &mut String, row: &Row) {
    let a = row.stop.as_ref();
    let _ = write!(
        s,
        ",{},{},{},{},{},{},{},{}",
        row.samples,
        row.mean_spp,
        a.and_then(|a| a.rule.error)
            .map_or(String::new(), |e| e.to_string()),
        a.and_then(|a| a.rule.time_limit)
            .map_or(String::new(), |t| t.as_secs_f64().to_string()),
        a.map_or(String::new(), |a| a.rule.max_spp.to_string()),
        a.map_or(String::new(), |a| a.reason.to_string()),
        a.map_or(String::new(), |a| a.decide_seconds.to_string()),
        a.map_or(String::new(), |a| a.blocks_left.to_string()),
    );
}

/// The rate fits of one method on one scene for one metric.
pub struct Slopes {
    /// Index into the plan's pairs.
    pub pair: usize,
    /// `mse` or `relmse`.
    pub metric: &'static str,
    /// Of the errors as measured, against spp and against seconds.
    pub raw: (Option<Fit>, Option<Fit>),
    /// Of the errors minus the reference's floor (when the reference has variance channels),
    /// against spp and against seconds.
    pub subtracted: Option<(Option<Fit>, Option<Fit>)>,
}

fn rows_of(results: &Results, pair: usize) -> impl Iterator<Item = &Row> {
    results.rows.iter().filter(move |r| r.pair == pair)
}

/// Fits of log error against log spp and log seconds, for MSE and relMSE, as measured and with
/// the reference's floor subtracted.
///
/// The two bracket the truth. The measured error contains the reference's own error, which
/// flattens the slope as the test images approach the reference's quality. The floor is the
/// reference's variance of the mean from its sample variance, which is exact for independent
/// samples but an overestimate for our stratified ones (their error falls faster than
/// variance/N), so subtracting it steepens the slope; where a test image beats the floor the
/// point cannot be used at all.
pub fn slopes(plan: &Plan, results: &Results) -> Vec<Slopes> {
    let mut out = Vec::new();
    for (pi, pair) in plan.pairs.iter().enumerate() {
        let fl = floor(&results.references[pair.scene], plan.epsilon);
        for metric in ["mse", "relmse"] {
            let (value, sub): (fn(&Row) -> f64, Option<f64>) = match metric {
                "mse" => (|r| r.metrics.mse, fl.as_ref().map(|f| f.mse)),
                _ => (|r| r.metrics.relmse, fl.as_ref().map(|f| f.relmse)),
            };
            let fits = |floor: f64| {
                let by = |x: fn(&Row) -> f64| -> Vec<(f64, f64)> {
                    rows_of(results, pi)
                        .map(|r| (x(r), value(r) - floor))
                        .collect()
                };
                (
                    log_log_slope(&by(|r| r.mean_spp)),
                    log_log_slope(&by(Row::total_seconds)),
                )
            };
            out.push(Slopes {
                pair: pi,
                metric,
                raw: fits(0.0),
                subtracted: sub.map(fits),
            });
        }
    }
    out
}

/// slopes.csv: one row per scene, method, metric and floor treatment (`none`, and
/// `subtracted` when the reference has variance channels).
pub fn slopes_csv(plan: &Plan, slopes: &[Slopes]) -> String {
    let mut s = format!("{SLOPES_HEADER}\n");
    for sl in slopes {
        let pair = &plan.pairs[sl.pair];
        let fit = |f: Option<Fit>| {
            f.map_or((String::new(), String::new()), |f| {
                (num(f.slope), num(f.se))
            })
        };
        let mut line = |(by_spp, by_time): (Option<Fit>, Option<Fit>), floor: &str| {
            let (a, ase) = fit(by_spp);
            let (b, bse) = fit(by_time);
            let points = by_spp.map_or(0, |f| f.points);
            let _ = writeln!(
                s,
                "{},{},{},{floor},{points},{a},{ase},{b},{bse}",
                plan.scenes[pair.scene].name, plan.methods[pair.method].name, sl.metric,
            );
        };
        line(sl.raw, "none");
        if let Some(sub) = sl.subtracted {
            line(sub, "subtracted");
        }
    }
    s
}

/// The equal-time comparison of one scene.
pub struct EqualTime {
    /// Index into the plan's scenes.
    pub scene: usize,
    /// Pairs compared (the scene's).
    pub pairs: Vec<usize>,
    /// Each time and every pair's interpolated relMSE there.
    pub table: Vec<(f64, Vec<f64>)>,
}

impl EqualTime {
    /// Index (into `pairs`) of the lowest error at row `i` (NaN, "no value", never wins).
    pub fn winner(&self, i: usize) -> usize {
        let errs = &self.table[i].1;
        (0..errs.len())
            .filter(|&k| !errs[k].is_nan())
            .min_by(|&a, &b| errs[a].total_cmp(&errs[b]))
            .unwrap_or(0)
    }

    /// The pair that wins most often (the earliest listed on ties), if any time was compared.
    pub fn overall(&self) -> Option<(usize, usize)> {
        let mut wins = vec![0usize; self.pairs.len()];
        for i in 0..self.table.len() {
            wins[self.winner(i)] += 1;
        }
        let best = (0..wins.len()).max_by(|&a, &b| wins[a].cmp(&wins[b]).then(b.cmp(&a)))?;
        (wins[best] > 0).then_some((self.pairs[best], wins[best]))
    }
}

/// What the methods of a scene are compared at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Render time.
    Time,
    /// Samples per pixel on average (the samples an adaptive run actually took).
    Samples,
}

/// A method's relMSE against `axis`. Time: render plus denoising time, with time budgets at
/// their nominal value (each run stops within about one sample's time of it), everything else
/// at its measured time. Samples: the mean samples per pixel taken.
fn curve(plan: &Plan, results: &Results, pair: usize, axis: Axis) -> Vec<(f64, f64)> {
    let seconds_budgets = matches!(
        plan.methods[plan.pairs[pair].method].runs,
        Runs::Progressive(Budgets::Seconds(_))
    );
    let mut c: Vec<(f64, f64)> = rows_of(results, pair)
        .map(|r| {
            let x = match axis {
                Axis::Time if seconds_budgets => r.budget + r.denoise_seconds,
                Axis::Time => r.total_seconds(),
                Axis::Samples => r.mean_spp,
            };
            (x, r.metrics.relmse)
        })
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .collect();
    c.sort_by(|a, b| a.0.total_cmp(&b.0));
    c
}

/// Which method has the lowest relMSE at equal time, per scene.
pub fn equal_time(plan: &Plan, results: &Results) -> Vec<EqualTime> {
    compare_at(plan, results, Axis::Time)
}

/// Which method has the lowest relMSE at an equal number of samples (mean samples per pixel),
/// per scene: adaptive sampling against uniform sampling.
pub fn equal_samples(plan: &Plan, results: &Results) -> Vec<EqualTime> {
    compare_at(plan, results, Axis::Samples)
}

/// The comparison of every scene's methods along `axis`, at the budgets of that kind that
/// every curve covers (or evenly spaced points in log space).
pub fn compare_at(plan: &Plan, results: &Results, axis: Axis) -> Vec<EqualTime> {
    (0..plan.scenes.len())
        .map(|si| {
            let pairs: Vec<usize> = (0..plan.pairs.len())
                .filter(|&p| plan.pairs[p].scene == si)
                .collect();
            let curves: Vec<Vec<(f64, f64)>> = pairs
                .iter()
                .map(|&p| curve(plan, results, p, axis))
                .collect();
            let budgets: Vec<f64> = pairs
                .iter()
                .filter_map(
                    |&p| match (&plan.methods[plan.pairs[p].method].runs, axis) {
                        (Runs::Progressive(Budgets::Seconds(v)), Axis::Time) => Some(v.clone()),
                        (Runs::Progressive(Budgets::Spp(v)), Axis::Samples) => {
                            Some(v.iter().map(|&n| f64::from(n)).collect())
                        }
                        _ => None,
                    },
                )
                .flatten()
                .collect();
            let refs: Vec<&[(f64, f64)]> = curves.iter().map(Vec::as_slice).collect();
            let table = if pairs.len() < 2 {
                Vec::new()
            } else {
                comparison_times(&refs, &budgets, EQUAL_TIME_POINTS)
                    .into_iter()
                    .map(|t| {
                        let errs = refs
                            .iter()
                            .map(|c| log_log_interpolate(c, t).unwrap_or(f64::NAN))
                            .collect();
                        (t, errs)
                    })
                    .collect()
            };
            EqualTime {
                scene: si,
                pairs,
                table,
            }
        })
        .collect()
}

/// Draws the two plots of every scene: relMSE against time and against spp.
pub fn plots(plan: &Plan, results: &Results, out: &Path) -> Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    for (si, scene) in plan.scenes.iter().enumerate() {
        let pairs: Vec<usize> = (0..plan.pairs.len())
            .filter(|&p| plan.pairs[p].scene == si)
            .collect();
        let series = |x: fn(&Row) -> f64| -> Vec<Series> {
            pairs
                .iter()
                .map(|&p| Series {
                    name: plan.methods[plan.pairs[p].method].name.clone(),
                    points: rows_of(results, p)
                        .map(|r| (x(r), r.metrics.relmse))
                        .collect(),
                })
                .collect()
        };
        let title = format!("{}: relMSE (eps {})", scene.name, plan.epsilon);
        let time = series(Row::total_seconds);
        plot::write(
            &Chart {
                title: &title,
                x_label: if any_denoiser(plan) {
                    "render + denoise time (s)"
                } else {
                    "render time (s)"
                },
                y_label: "relMSE",
                x_base: 10.0,
                series: &time,
            },
            &dir.join(format!("{}.png", scene.name)),
            &dir.join(format!("{}.svg", scene.name)),
        )?;
        let spp = series(|r| r.mean_spp);
        plot::write(
            &Chart {
                title: &title,
                x_label: "samples per pixel (mean)",
                y_label: "relMSE",
                x_base: 2.0,
                series: &spp,
            },
            &dir.join(format!("{}-spp.png", scene.name)),
            &dir.join(format!("{}-spp.svg", scene.name)),
        )?;
    }
    Ok(())
}

/// The corner and side of the crop shown for a scene: the `crop`-sized block, on a grid of
/// half-block steps, where the methods' final images have the largest summed relative squared
/// error (the per-pixel term of relMSE): where they differ most from the reference, and so
/// from each other.
pub fn crop_block(
    reference: &RgbImage,
    finals: &[&RgbImage],
    crop: u32,
    epsilon: f64,
) -> (usize, usize, usize) {
    let (w, h) = (reference.width(), reference.height());
    let c = (crop as usize).min(w).min(h).max(1);
    let step = (c / 2).max(1);
    let err = |img: &RgbImage, x: usize, y: usize| -> f64 {
        let (a, b) = (img.pixel(x, y), reference.pixel(x, y));
        (0..3)
            .map(|k| {
                let (a, b) = (f64::from(a[k]), f64::from(b[k]));
                (a - b) * (a - b) / (b * b + epsilon)
            })
            .sum()
    };
    let starts = |n: usize| {
        let mut v: Vec<usize> = (0..=n - c).step_by(step).collect();
        if v.last() != Some(&(n - c)) {
            v.push(n - c);
        }
        v
    };
    let mut best = (0, 0, f64::NEG_INFINITY);
    for &y0 in &starts(h) {
        for &x0 in &starts(w) {
            let mut score = 0.0;
            for img in finals {
                for y in y0..y0 + c {
                    for x in x0..x0 + c {
                        score += err(img, x, y);
                    }
                }
            }
            if score > best.2 {
                best = (x0, y0, score);
            }
        }
    }
    (best.0, best.1, c)
}

/// Cuts the block out of `img` and enlarges it `zoom` times (nearest neighbour, so pixels
/// and their noise stay visible).
fn cut(img: &RgbImage, (x0, y0, c): (usize, usize, usize), zoom: usize) -> Vec<Rgb> {
    let side = c * zoom;
    let mut px = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            px.push(img.pixel(x0 + x / zoom, y0 + y / zoom));
        }
    }
    px
}

/// How much crops are enlarged: to at least 128 pixels across.
pub fn zoom(c: usize) -> usize {
    (128 / c.max(1)).max(1)
}

/// Writes `crops/<scene>/reference.png` and `crops/<scene>/<method>.png`; returns the blocks.
pub fn crops(plan: &Plan, results: &Results, out: &Path) -> Result<Vec<(usize, usize, usize)>> {
    let mut blocks = Vec::new();
    for (si, scene) in plan.scenes.iter().enumerate() {
        let dir = out.join("crops").join(&scene.name);
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        let reference = &results.references[si].image;
        let pairs: Vec<usize> = (0..plan.pairs.len())
            .filter(|&p| plan.pairs[p].scene == si)
            .collect();
        let finals: Vec<&RgbImage> = pairs.iter().map(|&p| &results.finals[p]).collect();
        let block = crop_block(reference, &finals, plan.crop, plan.epsilon);
        let z = zoom(block.2);
        let side = block.2 * z;
        let write = |name: &str, img: &RgbImage| {
            let crop = RgbImage::new(side, side, cut(img, block, z))?;
            rt_film::write_rgb(&dir.join(format!("{name}.png")), &crop, &Default::default())
                .map_err(crate::ExperimentError::from)
        };
        write("reference", reference)?;
        for (&p, img) in pairs.iter().zip(&finals) {
            write(&plan.methods[plan.pairs[p].method].name, img)?;
        }
        blocks.push(block);
    }
    Ok(blocks)
}

/// "METHOD (W of N WHAT)": the method that wins most of a comparison, or "–".
pub(crate) fn winner(plan: &Plan, e: &EqualTime, what: &str) -> String {
    match e.overall() {
        Some((p, wins)) => format!(
            "{} ({wins} of {} {what})",
            plan.methods[plan.pairs[p].method].name,
            e.table.len()
        ),
        None => "–".into(),
    }
}

pub(crate) fn sci(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else if v.is_infinite() {
        "∞".into()
    } else {
        format!("{v:.3e}")
    }
}

pub(crate) fn fit_text(f: Option<Fit>) -> String {
    match f {
        None => "–".into(),
        Some(f) if f.se.is_nan() => format!("{:.3} ({} pts)", f.slope, f.points),
        Some(f) => format!("{:.3} ± {:.3}", f.slope, f.se),
    }
}

/// Header facts for report.md.
pub struct RunInfo {
    /// When the experiment started (UTC, `YYYY-MM-DD HH:MM`).
    pub started: String,
    /// Worker threads.
    pub threads: usize,
    /// Wall-clock seconds of the whole experiment.
    pub wall_seconds: f64,
}

impl RunInfo {
    /// Facts of a run that started at `started` (UTC, `now_secs` seconds) and took `wall`, on
    /// the current thread pool.
    pub fn now(started: (i64, u32, u32, u32, u32), wall: std::time::Duration) -> Self {
        let (y, mo, d, h, mi) = started;
        Self {
            started: format!("{y:04}-{mo:02}-{d:02} {h:02}:{mi:02}"),
            threads: rayon::current_num_threads(),
            wall_seconds: wall.as_secs_f64(),
        }
    }

    /// report.md's title, run line, `data` (what the output folder holds) and the plan's
    /// warnings.
    pub fn header(&self, plan: &Plan, title: &str, data: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Experiment `{}`{title}\n", plan.name);
        let _ = writeln!(
            s,
            "Config `{}`, started {} UTC, {} worker threads, {:.1} s in all. relMSE uses ε = {}.\n{data}",
            plan.path.display(),
            self.started,
            self.threads,
            self.wall_seconds,
            plan.epsilon
        );
        if !plan.warnings.is_empty() {
            let _ = writeln!(s, "Warnings:\n");
            for w in &plan.warnings {
                let _ = writeln!(s, "- {w}");
            }
            s.push('\n');
        }
        s
    }
}

/// report.md.
pub fn markdown(
    plan: &Plan,
    results: &Results,
    slopes: &[Slopes],
    equal: &[EqualTime],
    equal_samples: &[EqualTime],
    blocks: &[(usize, usize, usize)],
    info: &RunInfo,
) -> String {
    let mut s = info.header(
        plan,
        "",
        "Data: [results.csv](results.csv) (one row per run), [slopes.csv](slopes.csv); images in \
         `images/<scene>/`.\n",
    );

    let _ = writeln!(s, "## Summary\n");
    // Equal samples matters where sample counts differ from the budgets (adaptive runs) or
    // time is not all rendering (denoisers).
    let any_adaptive = plan
        .methods
        .iter()
        .any(|m| matches!(m.runs, Runs::Adaptive(_)))
        || any_denoiser(plan);
    let winner = |e: &EqualTime, what: &str| winner(plan, e, what);
    if any_adaptive {
        let _ = writeln!(
            s,
            "| scene | lowest relMSE at equal time | lowest relMSE at equal samples | MSE slope vs spp |"
        );
        let _ = writeln!(s, "|---|---|---|---|");
    } else {
        let _ = writeln!(
            s,
            "| scene | lowest relMSE at equal time | MSE slope vs spp |"
        );
        let _ = writeln!(s, "|---|---|---|");
    }
    for (si, scene) in plan.scenes.iter().enumerate() {
        let mut cells = vec![winner(&equal[si], "times")];
        if any_adaptive {
            cells.push(winner(&equal_samples[si], "sample counts"));
        }
        let rates: Vec<String> = slopes
            .iter()
            .filter(|sl| sl.metric == "mse" && plan.pairs[sl.pair].scene == si)
            .map(|sl| {
                let name = &plan.methods[plan.pairs[sl.pair].method].name;
                format!("{name} {}", fit_text(sl.raw.0))
            })
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} |",
            scene.name,
            cells.join(" | "),
            rates.join("; ")
        );
    }
    s.push('\n');

    for (si, scene) in plan.scenes.iter().enumerate() {
        let _ = writeln!(s, "## Scene `{}`\n", scene.name);
        let _ = writeln!(
            s,
            "`{}`, camera `{}` at {}×{}; reference: {}.\n",
            scene.path.display(),
            scene.camera.name,
            scene.camera.width,
            scene.camera.height,
            results.references[si].origin
        );
        let _ = writeln!(
            s,
            "![relMSE against time](plots/{0}.png) ![relMSE against spp](plots/{0}-spp.png)\n",
            scene.name
        );
        let has_adaptive = plan
            .pairs
            .iter()
            .any(|p| p.scene == si && matches!(plan.methods[p.method].runs, Runs::Adaptive(_)));
        let has_denoiser = plan
            .pairs
            .iter()
            .any(|p| p.scene == si && plan.methods[p.method].denoiser.is_some());
        if has_denoiser {
            let _ = writeln!(
                s,
                "Methods with a denoiser are measured by the denoised image (`MSE` … `SSIM`); \
                 `noisy relMSE` is the rendered image's before denoising, `denoise s` the \
                 denoising time (not part of `seconds`, the render time; the equal-time \
                 comparison and the time plot use their sum).\n"
            );
        }
        if has_adaptive {
            let _ = writeln!(
                s,
                "Adaptive runs (`error`, `time_limit`) give the samples they actually took: `samples` \
             over the whole image, `mean spp` per pixel on average, `spp` for the pixels that \
             sampled longest; `stop` says why they stopped, with the time the stopping \
             criterion's decisions took (part of `seconds`).\n"
            );
        }
        let _ = writeln!(
            s,
            "| method | integrator | accel | budget | spp | samples | mean spp | stop | seconds | Msamples/s | MSE | relMSE | PSNR | SSIM |{}",
            if has_denoiser { " denoiser | denoise s | noisy relMSE |" } else { "" }
        );
        let _ = writeln!(
            s,
            "|---|---|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|{}",
            if has_denoiser { "---|---:|---:|" } else { "" }
        );
        for row in results
            .rows
            .iter()
            .filter(|r| plan.pairs[r.pair].scene == si)
        {
            let pair = &plan.pairs[row.pair];
            let m = &row.metrics;
            let (budget, stop) = match &row.stop {
                None => (
                    plan.methods[pair.method]
                        .runs
                        .budgets()
                        .map_or(String::new(), |b| crate::grid::budget_label(b, row.budget)),
                    "–".to_string(),
                ),
                Some(a) => (
                    crate::grid::rule_label(&a.rule),
                    format!(
                        "{}, {} blocks left, {:.3} s deciding",
                        a.reason, a.blocks_left, a.decide_seconds
                    ),
                ),
            };
            let denoise = if has_denoiser {
                format!(
                    " {} | {} | {} |",
                    plan.methods[pair.method]
                        .denoiser
                        .as_ref()
                        .map_or("–".into(), |d| format!("`{d}`")),
                    if row.raw.is_some() {
                        format!("{:.3}", row.denoise_seconds)
                    } else {
                        "–".into()
                    },
                    row.raw.map_or("–".into(), |m| sci(m.relmse))
                )
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {budget} | {} | {} | {:.2} | {stop} | {:.3} | {:.2} | {} | {} | {:.2} | {:.4} |{denoise}",
                plan.methods[pair.method].name,
                pair.estimator.kind,
                pair.accel,
                row.spp,
                row.samples,
                row.mean_spp,
                row.seconds,
                row.samples_per_second / 1e6,
                sci(m.mse),
                sci(m.relmse),
                m.psnr,
                m.ssim
            );
        }
        s.push('\n');

        let _ = writeln!(s, "### Convergence rates\n");
        let _ = writeln!(
            s,
            "Least-squares slopes of log error against log spp and log seconds, ± the standard \
             error from the residuals. Independent samples give −1; lower (steeper) is better. \
             The last column fits the errors minus the reference's own expected error (its \
             pixel variance of the mean, averaged like the metric; points below it are left \
             out): measured and subtracted slopes bracket the true rate (docs/experiments.md).\n"
        );
        let _ = writeln!(
            s,
            "| method | metric | slope vs spp | slope vs seconds | vs spp, reference noise subtracted |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|");
        for sl in slopes.iter().filter(|sl| plan.pairs[sl.pair].scene == si) {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                plan.methods[plan.pairs[sl.pair].method].name,
                sl.metric,
                fit_text(sl.raw.0),
                fit_text(sl.raw.1),
                sl.subtracted.map_or("–".into(), |f| fit_text(f.0))
            );
        }
        s.push('\n');

        comparison_table(
            &mut s,
            plan,
            &equal[si],
            "### Equal time",
            "seconds",
            "relMSE of each method at the same render time, plus denoising time for a method \
             with a denoiser (time budgets at their nominal value, other runs interpolated \
             linearly in log-log between measured points).",
        );
        if has_adaptive || has_denoiser {
            comparison_table(
                &mut s,
                plan,
                &equal_samples[si],
                "### Equal samples",
                "mean spp",
                "relMSE of each method at the same number of samples, counted as the mean \
                 samples per pixel actually taken (sample budgets at their value, adaptive runs \
                 interpolated linearly in log-log between measured points).",
            );
        }

        let (x0, y0, c) = blocks[si];
        let _ = writeln!(s, "### Crops\n");
        let _ = writeln!(
            s,
            "The {c}×{c} block at ({x0}, {y0}) where the methods' images at their largest budget \
             have the highest relative squared error, enlarged {}×.\n",
            zoom(c)
        );
        let pairs: Vec<usize> = (0..plan.pairs.len())
            .filter(|&p| plan.pairs[p].scene == si)
            .collect();
        let mut head = vec!["reference".to_string()];
        let mut cells = vec![format!("![reference](crops/{}/reference.png)", scene.name)];
        for &p in &pairs {
            let name = &plan.methods[plan.pairs[p].method].name;
            let last = rows_of(results, p).last();
            head.push(match last {
                Some(r) if r.stop.is_some() => {
                    format!("{name} ({:.1} mean spp, {:.2} s)", r.mean_spp, r.seconds)
                }
                Some(r) => format!("{name} ({} spp, {:.2} s)", r.spp, r.seconds),
                None => name.clone(),
            });
            cells.push(format!("![{name}](crops/{}/{name}.png)", scene.name));
        }
        let _ = writeln!(s, "| {} |", head.join(" | "));
        let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
        let _ = writeln!(s, "| {} |\n", cells.join(" | "));
    }
    s
}

/// One comparison section of report.md: each point of `e` and every method's relMSE there.
fn comparison_table(
    s: &mut String,
    plan: &Plan,
    e: &EqualTime,
    heading: &str,
    x_name: &str,
    explanation: &str,
) {
    let _ = writeln!(s, "{heading}\n");
    if e.table.is_empty() {
        let _ = writeln!(
            s,
            "Nothing to compare: one method, or no {x_name} value that every method's curve covers.\n"
        );
        return;
    }
    let names: Vec<&str> = e
        .pairs
        .iter()
        .map(|&p| plan.methods[plan.pairs[p].method].name.as_str())
        .collect();
    let _ = writeln!(s, "{explanation}\n");
    let _ = writeln!(s, "| {x_name} | {} | lowest |", names.join(" | "));
    let _ = writeln!(s, "|---:|{}---|", "---:|".repeat(names.len()));
    for (i, (t, errs)) in e.table.iter().enumerate() {
        let cells: Vec<String> = errs.iter().map(|&v| sci(v)).collect();
        let _ = writeln!(
            s,
            "| {t:.3} | {} | {} |",
            cells.join(" | "),
            names[e.winner(i)]
        );
    }
    s.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crop_goes_where_the_error_is() {
        let reference = RgbImage::from_fn(100, 80, |_, _| Rgb::splat(0.5));
        let test = RgbImage::from_fn(100, 80, |x, y| {
            if (70..75).contains(&x) && (10..15).contains(&y) {
                Rgb::splat(2.0)
            } else {
                Rgb::splat(0.5)
            }
        });
        let (x0, y0, c) = crop_block(&reference, &[&test], 32, 0.01);
        assert_eq!(c, 32);
        assert!(
            (x0..x0 + c).contains(&70) && (x0..x0 + c).contains(&74),
            "{x0}"
        );
        assert!(
            (y0..y0 + c).contains(&10) && (y0..y0 + c).contains(&14),
            "{y0}"
        );
        assert!(x0 + c <= 100 && y0 + c <= 80);
        // A crop larger than the image is the whole image.
        assert_eq!(crop_block(&reference, &[&test], 256, 0.01), (0, 0, 80));
        assert_eq!(cut(&test, (72, 12, 2), 2).len(), 16);
    }

    #[test]
    fn floors_average_the_reference_variance() {
        let r = Reference {
            image: RgbImage::from_fn(2, 1, |_, _| Rgb::splat(1.0)),
            variance: Some(vec![Rgb::splat(0.01), Rgb::splat(0.03)]),
            origin: String::new(),
        };
        let f = floor(&r, 0.01).unwrap();
        assert!((f.mse - 0.02).abs() < 1e-9);
        assert!((f.relmse - 0.02 / 1.01).abs() < 1e-9);
        let none = Reference {
            variance: None,
            ..r
        };
        assert!(floor(&none, 0.01).is_none());
    }
}
