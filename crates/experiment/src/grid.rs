//! Running the grid: references first (from the cache or rendered into it), then every method
//! on every scene, each as one progressive render stopped at its budgets, or, for an adaptive
//! method (`error`, `time_limit`), one render per stopping rule, stopped the way `render --error
//! --time-limit` stops. Each is a [`rt_session::RenderJob`] of the method on the scene
//! ([`crate::config::Pair::job`]) that hands the grid its film at every stop
//! ([`rt_session::RenderJob::render_stops`]); every stop writes its image and is measured
//! against the scene's reference.
//!
//! A method with a denoiser renders the channels the denoiser reads
//! ([`AovSet::for_channels`] of [`rt_denoise::Denoiser::needs`]), denoises every stop's frame (timed
//! apart from the render) and is measured by the denoised image; the noisy image's error is
//! kept beside it.

use crate::cache::Cache;
use crate::config::{Plan, ReferencePlan, Runs};
use crate::error::{io, ExperimentError, Result};
use crate::Progress;
use crate::ProgressSink;
use rt_core::{Accel, Rgb, RgbImage};
use rt_denoise::NoisyFrame;
use rt_film::{read_rgb, AovSet};
use rt_integrators::{Ctx, Technique};
use rt_metrics::{compare, CompareOptions, Metrics};
use rt_session::{Budgets, FilmStop, RenderJob, StopReason, StopRule};
use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Progress units per run, so the bar moves within long runs.
const UNITS: u64 = 100;

/// A scene's reference, loaded.
pub struct Reference {
    /// Its pixels.
    pub image: RgbImage,
    /// The variance of each pixel mean, when the file has it (our references do).
    pub variance: Option<Vec<Rgb>>,
    /// Where it came from, for the report.
    pub origin: String,
}

/// One row of results.csv: a method on a scene at one budget.
pub struct Row {
    /// Index into the plan's pairs.
    pub pair: usize,
    /// The budget asked for (spp or seconds; for an adaptive run its error threshold, or its
    /// time limit when it has no threshold).
    pub budget: f64,
    /// Samples per pixel taken (for an adaptive run: by the pixels that sampled longest).
    pub spp: u32,
    /// Samples actually taken over the whole image (camera samples, or light paths for the
    /// splatting techniques).
    pub samples: u64,
    /// Samples per pixel on average: `spp` for uniform sampling, `samples` over the pixel
    /// count for an adaptive run.
    pub mean_spp: f64,
    /// How an adaptive run stopped (`None` for a progressive one).
    pub stop: Option<AdaptiveRun>,
    /// Render time in seconds (without denoising).
    pub seconds: f64,
    /// Seconds spent denoising this image (taking the frame from the film and filtering it;
    /// 0 without a denoiser).
    pub denoise_seconds: f64,
    /// Rays traced.
    pub rays: u64,
    /// Camera samples per second.
    pub samples_per_second: f64,
    /// Error against the reference: of the denoised image when the method has a denoiser.
    pub metrics: Metrics,
    /// Error of the noisy (rendered, not denoised) image, when the method has a denoiser.
    pub raw: Option<Metrics>,
    /// The rendered image (with the channels its denoiser reads), relative to the output
    /// folder.
    pub image: String,
    /// The denoised image, relative to the output folder.
    pub denoised_image: Option<String>,
}

impl Row {
    /// Render and denoise time: what the method's image cost.
    pub fn total_seconds(&self) -> f64 {
        self.seconds + self.denoise_seconds
    }
}

/// What an adaptive run asked for and did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveRun {
    /// The rule it ran under.
    pub rule: StopRule,
    /// Why it stopped.
    pub reason: StopReason,
    /// Seconds spent in the stopping criterion's decisions (included in [`Row::seconds`]).
    pub decide_seconds: f64,
    /// Blocks still sampling when it stopped.
    pub blocks_left: usize,
}

/// Everything the report needs.
pub struct Results {
    /// One per scene.
    pub references: Vec<Reference>,
    /// In run order.
    pub rows: Vec<Row>,
    /// Each pair's image at its largest budget (denoised, for a method with a denoiser).
    pub finals: Vec<RgbImage>,
    /// Each pair's noisy image at its largest budget, for a method with a denoiser.
    pub noisy_finals: Vec<Option<RgbImage>>,
}

/// The file name of a budget: `16spp`, `0.5s`.
pub fn budget_label(budgets: &Budgets, value: f64) -> String {
    match budgets {
        Budgets::Spp(_) => format!("{value}spp"),
        Budgets::Seconds(_) => format!("{value}s"),
    }
}

/// The file name of an adaptive run: `e0.0002`, `t2s`, `e0.0002-t2s`, `cap64spp` (the cap
/// only when it is the only limit).
pub fn rule_label(rule: &StopRule) -> String {
    let mut parts = Vec::new();
    if let Some(e) = rule.error {
        parts.push(format!("e{e}"));
    }
    if let Some(t) = rule.time_limit {
        parts.push(format!("t{}s", t.as_secs_f64()));
    }
    if parts.is_empty() {
        parts.push(format!("cap{}spp", rule.max_spp));
    }
    parts.join("-")
}

/// Reads a reference EXR: its colour and, if present, its `variance.*` channels.
fn load_reference(path: &Path, origin: String) -> Result<Reference> {
    let image = read_rgb(path)?;
    let exr = rt_film::read_exr(path)?;
    let variance = exr
        .rgb("variance.")
        .filter(|v| v.len() == image.pixels().len());
    Ok(Reference {
        image,
        variance,
        origin,
    })
}

/// Runs the plan, writing images under `out`.
pub fn run(plan: &Plan, out: &Path, cache: &Cache, progress: &dyn Progress) -> Result<Results> {
    let total_runs: usize = plan.scenes.len()
        + plan
            .pairs
            .iter()
            .map(|p| plan.methods[p.method].runs.len())
            .sum::<usize>();
    let bar = progress;
    bar.set_length(total_runs as u64 * UNITS);
    let mut done_runs = 0u64;
    let opts = CompareOptions {
        epsilon: plan.epsilon,
        peak: rt_metrics::DEFAULT_PEAK,
    };

    let mut references = Vec::new();
    for scene in &plan.scenes {
        let dir = out.join("images").join(&scene.name);
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        let copy = dir.join("reference.exr");
        bar.set_message(format!("{}: reference", scene.name));
        let reference = match &scene.reference {
            ReferencePlan::File { path, image } => {
                rt_film::write_rgb(&copy, image, &Default::default())?;
                let variance = rt_film::read_exr(path)
                    .ok()
                    .and_then(|e| e.rgb("variance."))
                    .filter(|v| v.len() == image.pixels().len());
                Reference {
                    image: image.clone(),
                    variance,
                    origin: format!("the file {}", path.display()),
                }
            }
            ReferencePlan::Render {
                spp,
                estimator,
                seed,
                accel,
            } => {
                let req = scene.reference_request(*estimator, *spp, *seed);
                let base = done_runs * UNITS;
                let built = accel
                    .build(&scene.loaded.scene)
                    .map_err(|e| ExperimentError::Run(format!("{}: {accel}: {e}", scene.name)))?;
                let got = crate::reference::obtain(
                    &req,
                    (accel, built.as_ref()),
                    Some(cache),
                    None,
                    &|f| bar.set_position(base + (f * UNITS as f64) as u64),
                )?;
                let origin = if got.cached {
                    progress.message(&format!(
                        "{}: reference from the cache: {}",
                        scene.name,
                        got.path.display()
                    ));
                    format!("the cache ({spp} spp, {:.1} s when rendered)", got.seconds)
                } else {
                    progress.message(&format!(
                        "{}: reference rendered at {spp} spp in {:.1} s: {}",
                        scene.name,
                        got.seconds,
                        got.path.display()
                    ));
                    format!("rendered ({spp} spp, {:.1} s)", got.seconds)
                };
                rt_film::copy_atomic(&got.path, &copy)?;
                load_reference(&got.path, origin)?
            }
        };
        references.push(reference);
        done_runs += 1;
        bar.set_position(done_runs * UNITS);
    }

    let mut rows = Vec::new();
    let mut finals = Vec::new();
    let mut noisy_finals = Vec::new();
    let mut accels: HashMap<(usize, String), Box<dyn Accel>> = HashMap::new();
    for (pi, pair) in plan.pairs.iter().enumerate() {
        let scene = &plan.scenes[pair.scene];
        let method = &plan.methods[pair.method];
        let reference = &references[pair.scene];
        let accel = match accels.entry((pair.scene, pair.accel.to_string())) {
            Entry::Occupied(built) => built.into_mut(),
            Entry::Vacant(slot) => {
                slot.insert(pair.accel.build(&scene.loaded.scene).map_err(|e| {
                    ExperimentError::Run(format!("{}: {}: {e}", scene.name, pair.accel))
                })?)
            }
        };
        let technique = pair.estimator.build();
        let ctx = Ctx {
            scene: &scene.loaded.scene,
            accel: accel.as_ref(),
            camera: &scene.camera,
        };
        bar.set_message(format!("{}: {}", scene.name, method.name));
        let runs = method.runs.len() as u64;
        let base = done_runs * UNITS;
        if let Some(g) = &method.gree {
            let (last, noisy) = run_gree(
                GreeMethod {
                    plan: g,
                    pair: pi,
                    method: &method.name,
                    scene: &scene.name,
                    reference,
                    opts: &opts,
                    out,
                },
                (&ctx, technique.as_ref()),
                &|b| pair.job(scene, method, Some(&Budgets::Spp(vec![b])), None),
                &method.runs,
                &mut rows,
                progress,
            )?;
            finals.push(last);
            noisy_finals.push(Some(noisy));
            done_runs += runs;
            bar.set_position(done_runs * UNITS);
            continue;
        }
        // The grid denoises each stop itself, to time and measure it apart from the render.
        let denoiser = pair
            .job(scene, method, None, None)
            .frame_denoiser()
            .map_err(|e| ExperimentError::Run(format!("{}: {e}", method.name)))?;
        let aovs = denoiser
            .as_ref()
            .map_or(AovSet::default(), |d| AovSet::for_channels(d.needs()));
        if aovs.any_split() && !technique.writes_split() {
            return Err(ExperimentError::Run(format!(
                "{}: its denoiser reads the lighting split, which the {} technique does not write",
                method.name,
                technique.name()
            )));
        }
        let pixels = (scene.camera.width as f64 * scene.camera.height as f64).max(1.0);
        let mut last_image = None;
        let mut last_noisy = None;
        // Writes the image of one stop (the `budget` asked for, or the adaptive `rule`), denoises
        // it if the method says so, measures it and records its row.
        let mut record = |stop: &FilmStop<'_>,
                          budget: f64,
                          label: String,
                          rule: Option<&StopRule>|
         -> Result<()> {
            let film = stop.film;
            let at = stop.at;
            let dir: PathBuf = ["images", &scene.name].iter().collect();
            let rel = dir.join(format!("{}-{label}.exr", method.name));
            rt_film::write_image(&out.join(&rel), film, &Default::default())?;
            let measure = |image: &RgbImage, rel: &Path| {
                compare(image, &reference.image, &opts).map_err(|e| {
                    ExperimentError::Run(format!(
                        "{} against the reference of {}: {e}",
                        rel.display(),
                        scene.name
                    ))
                })
            };
            let slash = |p: &Path| p.to_string_lossy().replace('\\', "/");
            let noisy = RgbImage::new(
                film.width() as usize,
                film.height() as usize,
                film.mean_image(),
            )?;
            let raw = measure(&noisy, &rel)?;
            let mut row = Row {
                pair: pi,
                budget,
                spp: at.spp,
                samples: at.samples,
                // An adaptive run's pixels took different counts.
                mean_spp: match rule {
                    Some(_) => at.samples as f64 / pixels,
                    None => f64::from(at.spp),
                },
                stop: rule
                    .zip(stop.adaptive.as_ref())
                    .map(|(rule, a)| AdaptiveRun {
                        rule: *rule,
                        reason: a.reason,
                        decide_seconds: a.decisions.as_secs_f64(),
                        blocks_left: a.blocks_left,
                    }),
                seconds: at.seconds,
                denoise_seconds: 0.0,
                rays: at.rays,
                samples_per_second: at.samples as f64 / at.seconds.max(1e-9),
                metrics: raw,
                raw: None,
                image: slash(&rel),
                denoised_image: None,
            };
            let Some(d) = &denoiser else {
                rows.push(row);
                last_image = Some(noisy);
                return Ok(());
            };
            let t0 = Instant::now();
            let denoised = d
                .denoise(&NoisyFrame::from_film(film, aovs))
                .map_err(|e| ExperimentError::Run(format!("{}: {e}", method.name)))?;
            row.denoise_seconds = t0.elapsed().as_secs_f64();
            let drel = dir.join(format!("{}-{label}-denoised.exr", method.name));
            rt_film::write_rgb(&out.join(&drel), &denoised, &Default::default())?;
            row.metrics = measure(&denoised, &drel)?;
            row.raw = Some(raw);
            row.denoised_image = Some(slash(&drel));
            rows.push(row);
            last_image = Some(denoised);
            last_noisy = Some(noisy);
            Ok(())
        };
        match &method.runs {
            Runs::Progressive(budgets) => {
                let values: Vec<f64> = match budgets {
                    Budgets::Spp(v) => v.iter().map(|&n| f64::from(n)).collect(),
                    Budgets::Seconds(v) => v.clone(),
                };
                let job = pair.job(scene, method, Some(budgets), None);
                let progress = |f: f64| bar.set_position(base + (f * (runs * UNITS) as f64) as u64);
                let sink = ProgressSink(&progress);
                job.render_stops(
                    &ctx,
                    technique.as_ref(),
                    Some(budgets),
                    &sink,
                    &mut |stop| {
                        let budget = values[stop.at.budget];
                        record(stop, budget, budget_label(budgets, budget), None)
                    },
                )?;
            }
            Runs::Sequence { .. } => {
                return Err(ExperimentError::Run(format!(
                    "{}: a sequence method runs in a sequence experiment (crate::sequence)",
                    method.name
                )))
            }
            Runs::Adaptive(rules) => {
                for (i, rule) in rules.iter().enumerate() {
                    let run_base = base + i as u64 * UNITS;
                    let budget = match (rule.error, rule.time_limit) {
                        // As written (0.05, not the f32's 0.0500000007).
                        (Some(e), _) => e.to_string().parse().unwrap_or(f64::from(e)),
                        (None, Some(t)) => t.as_secs_f64(),
                        (None, None) => f64::from(rule.max_spp),
                    };
                    let job = pair.job(scene, method, None, Some(*rule));
                    let progress =
                        |f: f64| bar.set_position(run_base + (f.min(1.0) * UNITS as f64) as u64);
                    let sink = ProgressSink(&progress);
                    job.render_stops(&ctx, technique.as_ref(), None, &sink, &mut |stop| {
                        record(stop, budget, rule_label(rule), Some(rule))
                    })?;
                }
            }
        }
        finals.push(last_image.expect("every method has at least one budget"));
        noisy_finals.push(last_noisy);
        done_runs += runs;
        bar.set_position(done_runs * UNITS);
    }
    Ok(Results {
        references,
        rows,
        finals,
        noisy_finals,
    })
}

/// What [`run_gree`] needs to know about its method.
struct GreeMethod<'a> {
    plan: &'a crate::config::GreePlan,
    pair: usize,
    method: &'a str,
    scene: &'a str,
    reference: &'a Reference,
    opts: &'a CompareOptions,
    out: &'a Path,
}

/// Renders a GREE method at each of its budgets, each the job `job_at(b)` run from scratch
/// ([`RenderJob::gree_run`] with the plan's bank; GREE's split of a budget is not a prefix of
/// a larger one's), measures the composite and its noisy image, and
/// records the rows; returns the last composite and noisy image. The row's `samples` are every
/// sample traced (noisy image and caches), its `seconds` the render of both, its
/// `denoise_seconds` the bank plus GREE's own stages.
fn run_gree(
    m: GreeMethod<'_>,
    (ctx, technique): (&Ctx<'_>, &dyn Technique),
    job_at: &dyn Fn(u32) -> RenderJob,
    runs: &Runs,
    rows: &mut Vec<Row>,
    progress: &dyn Progress,
) -> Result<(RgbImage, RgbImage)> {
    let fail = |e: String| ExperimentError::Run(format!("{}: {e}", m.method));
    let Some(Budgets::Spp(budgets)) = runs.budgets() else {
        return Err(fail("GREE needs spp budgets".into()));
    };
    let bank = rt_denoise::Bank::from_specs(&m.plan.bank).map_err(|e| fail(e.to_string()))?;
    let dir: PathBuf = ["images", m.scene].iter().collect();
    let slash = |p: &Path| p.to_string_lossy().replace('\\', "/");
    let measure = |image: &RgbImage| {
        compare(image, &m.reference.image, m.opts)
            .map_err(|e| fail(format!("against the reference of {}: {e}", m.scene)))
    };
    let mut last = None;
    for &b in budgets {
        let job = job_at(b);
        let run = job
            .gree_run(ctx, technique, &bank, job.settings.seed, &())
            .map_err(|e| fail(e.to_string()))?;
        let label = format!("{b}spp");
        let rel = dir.join(format!("{}-{label}.exr", m.method));
        run.frame.write_exr(&m.out.join(&rel), &[])?;
        let drel = dir.join(format!("{}-{label}-denoised.exr", m.method));
        rt_film::write_rgb(
            &m.out.join(&drel),
            &run.composite.image,
            &Default::default(),
        )?;
        let metrics = measure(&run.composite.image)?;
        let raw = measure(&run.frame.colour)?;
        // Only for the message: relMSE alone (no SSIM) of the per-pixel argmin and of the bank's
        // members on the same noisy image, how far the per-pixel choice is from each filter alone
        // (at n spp, not at equal samples).
        let relmse = |image: &RgbImage| {
            rt_metrics::relmse(image, &m.reference.image, m.opts.epsilon)
                .map_err(|e| fail(format!("against the reference of {}: {e}", m.scene)))
        };
        let argmin = relmse(&run.composite.argmin_image)?;
        let members: Vec<String> = bank
            .members()
            .iter()
            .zip(&run.bank.images)
            .map(|(d, img)| Ok(format!("{} {:.4e}", d.name(), relmse(img)?)))
            .collect::<Result<_>>()?;
        progress.message(&format!(
            "{}: {} b={b}: relMSE composite {:.4e}, per-pixel argmin {:.4e}, noisy {:.4e}; bank on the noisy image: {}; GREE's own stages {:.3} s of {:.3} s denoising",
            m.scene,
            m.method,
            metrics.relmse,
            argmin,
            raw.relmse,
            members.join(", "),
            run.composite.timings.own().as_secs_f64(),
            run.denoise_time().as_secs_f64(),
        ));
        let seconds = (run.render.elapsed + run.caches.elapsed).as_secs_f64();
        let samples = run.samples_traced();
        let pixels = run.frame.colour.len().max(1) as f64;
        rows.push(Row {
            pair: m.pair,
            budget: f64::from(b),
            spp: b,
            samples,
            mean_spp: samples as f64 / pixels,
            stop: None,
            seconds,
            denoise_seconds: run.denoise_time().as_secs_f64(),
            rays: run.render.rays.rays
                + run.render.rays.shadow_rays
                + run.caches.rays.rays
                + run.caches.rays.shadow_rays,
            samples_per_second: samples as f64 / seconds.max(1e-9),
            metrics,
            raw: Some(raw),
            image: slash(&rel),
            denoised_image: Some(slash(&drel)),
        });
        last = Some((run.composite.image, run.frame.colour));
    }
    last.ok_or_else(|| fail("no budget".into()))
}
