//! GREE over the renderer (Bauszat, thesis ch. 5): render the noisy image N at the budget's
//! `n` spp with the channels the bank reads, run the filter bank, render the filter caches
//! through a sparse re-render from [`SampleStream::Cache`] (independent of N's samples), and
//! let `rt_gree` choose a filter per pixel and composite.
//!
//! Every sample is counted: [`GreeRun::samples_traced`] is N's plus the caches', which is what
//! an equal-budget comparison must give the other methods (the thesis' formula charges a cache
//! pixel `c` samples in total; ours renders N at every pixel and the caches on top, so it
//! traces `(1 − s)·n` more per pixel than `b`, and says so).

use rt_core::{Rgb, SampleStream};
use rt_denoise::{Bank, BankOutput, DenoiseError, NoisyFrame};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_gree::{composite, Budget, CacheRenderer, Composite, GreeError, GreeParams};
use rt_integrators::{render_pixels, Ctx, Integrator, RenderStats, SamplePass};
use std::time::Duration;

/// Why a GREE render failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GreeRunError {
    /// The bank could not run on the frame.
    #[error(transparent)]
    Denoise(#[from] DenoiseError),
    /// The bank reads the lighting split, which the integrator does not write.
    #[error("the filter bank reads the lighting split, which the {0} integrator does not write")]
    SplitUnsupported(String),
    /// GREE's own checks or stages failed.
    #[error("GREE: {0}")]
    Gree(#[from] GreeError),
}

/// Everything a GREE render produced.
pub struct GreeRun {
    /// N, with the channels the bank read and its variance.
    pub frame: NoisyFrame,
    /// The bank's images and times.
    pub bank: BankOutput,
    /// GREE's choice, composite and stage times.
    pub composite: Composite,
    /// How the budget was split.
    pub budget: Budget,
    /// Rendering N.
    pub render: RenderStats,
    /// Rendering the caches.
    pub caches: RenderStats,
}

impl GreeRun {
    /// Samples traced in all: N's and the caches'.
    pub fn samples_traced(&self) -> u64 {
        self.render.samples + self.caches.samples
    }

    /// Time spent denoising (bank, then GREE's own stages without the cache render).
    pub fn denoise_time(&self) -> Duration {
        self.bank.times.iter().sum::<Duration>() + self.composite.timings.own()
    }
}

/// Renders caches with the camera-ray integrator of the render, from the cache stream.
struct Caches<'a> {
    ctx: &'a Ctx<'a>,
    integrator: &'a dyn Integrator,
    seed: u32,
    stats: RenderStats,
}

impl CacheRenderer for Caches<'_> {
    type Error = std::convert::Infallible;

    fn render_caches(&mut self, pixels: &[(u32, u32)], spp: u32) -> Result<Vec<Rgb>, Self::Error> {
        let (means, stats) = render_pixels(
            self.ctx,
            self.integrator,
            pixels,
            spp,
            self.seed,
            SampleStream::Cache,
        );
        self.stats = stats;
        Ok(means)
    }
}

/// The AOVs N needs for `bank` and GREE: the bank's channels and the variance of the mean
/// (cache placement prefers low-noise pixels).
pub fn gree_aovs(bank: &Bank) -> AovSet {
    let mut a = AovSet::for_channels(&bank.needs());
    a.variance = true;
    a
}

/// Renders `ctx`'s camera with GREE at budget `params.budget` spp: see the module doc.
/// `progress` gets N's rows done.
pub fn render_gree(
    ctx: &Ctx<'_>,
    integrator: &dyn Integrator,
    bank: &Bank,
    params: &GreeParams,
    seed: u32,
    progress: &(dyn Fn(u32) + Sync),
) -> Result<GreeRun, GreeRunError> {
    params.validate()?;
    let budget = params.budget_split();
    let aovs = gree_aovs(bank);
    if aovs.any_split() && !integrator.writes_split() {
        return Err(GreeRunError::SplitUnsupported(
            integrator.name().to_string(),
        ));
    }
    let camera = ctx.camera;
    let mut film = Film::new(camera.width, camera.height, FilmBuffers::for_outputs(aovs));
    let pass = SamplePass {
        indices: 0..budget.n,
        stream: SampleStream::Render,
        pixels: None,
        centre_first: false,
    };
    let render = rt_integrators::render_samples(ctx, integrator, &mut film, seed, &pass, progress);
    let frame = NoisyFrame::from_film_taking_samples(&mut film, aovs);
    drop(film);
    let bank_out = bank.apply(&frame)?;
    let variance = frame
        .variance
        .clone()
        .expect("the film kept the variance it was asked for");
    let mut caches = Caches {
        ctx,
        integrator,
        seed,
        stats: RenderStats::default(),
    };
    let composite = composite(
        &frame.colour,
        &variance,
        &bank_out.images,
        &mut caches,
        params,
    )?;
    Ok(GreeRun {
        frame,
        bank: bank_out,
        composite,
        budget,
        render,
        caches: caches.stats,
    })
}

/// GREE's settings from `--gree` text: `:`-separated `key=value` options over the defaults,
/// with the budget `b` from `--spp`. Keys: `fraction` (n/b), `sparsity`, `kappa`, `sigma-r`,
/// `lambda`, `jacobi`, `metric` (`squared` or `relative`). Every error is one line naming the
/// key.
pub fn parse_gree_options(text: &str, budget: u32, seed: u32) -> Result<GreeParams, String> {
    let mut p = GreeParams {
        budget: budget as f32,
        seed,
        ..GreeParams::default()
    };
    for opt in text.split(':').map(str::trim).filter(|o| !o.is_empty()) {
        let (k, v) = opt
            .split_once('=')
            .ok_or_else(|| format!("--gree: option '{opt}' is not key=value"))?;
        let num = || {
            v.parse::<f32>()
                .map_err(|_| format!("--gree: {k}: '{v}' is not a number"))
        };
        match k {
            "fraction" => p.noisy_fraction = num()?,
            "sparsity" => p.sparsity = num()?,
            "kappa" => p.kappa = num()?,
            "sigma-r" => p.sigma_r = num()?,
            "lambda" => p.lambda = num()?,
            "jacobi" => {
                p.jacobi_iters = v
                    .parse()
                    .map_err(|_| format!("--gree: jacobi: '{v}' is not a non-negative integer"))?
            }
            "metric" => {
                p.metric = match v {
                    "squared" => rt_gree::ErrorMetric::Squared,
                    "relative" => rt_gree::ErrorMetric::Relative,
                    _ => return Err(format!("--gree: metric: '{v}' is not squared or relative")),
                }
            }
            _ => {
                return Err(format!(
                    "--gree: unknown option '{k}' (fraction, sparsity, kappa, sigma-r, lambda, jacobi, metric)"
                ))
            }
        }
    }
    p.validate().map_err(|e| format!("--gree: {e}"))?;
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_parse_over_the_defaults_and_refuse_bad_values() {
        let p = parse_gree_options("sparsity=0.9:kappa=0.5:metric=relative", 32, 7).unwrap();
        assert_eq!((p.budget, p.sparsity, p.kappa, p.seed), (32.0, 0.9, 0.5, 7));
        assert_eq!(p.metric, rt_gree::ErrorMetric::Relative);
        assert_eq!(
            parse_gree_options("", 16, 0).unwrap().lambda,
            GreeParams::default().lambda
        );
        for (bad, says) in [
            ("sparsity=1.5", "sparsity"),
            ("kappa=x", "kappa: 'x' is not a number"),
            ("colour=1", "unknown option 'colour'"),
            ("lambda", "not key=value"),
            ("metric=l1", "not squared or relative"),
        ] {
            let e = parse_gree_options(bad, 32, 0).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}
