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

/// GREE's options as one spec in the option grammar ([`rt_core::options`]), without a kind:
/// `fraction` (n/b), `sparsity`, `kappa`, `sigma-r`, `lambda`, `jacobi`, `metric` (`squared`
/// or `relative`), over [`GreeParams::default`]. The budget and the seed come from the render
/// ([`GreeSpec::params`]). It displays the options that differ from the defaults (nothing for
/// the defaults), which parse back to the same spec.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GreeSpec {
    /// n/b.
    pub fraction: f32,
    /// s.
    pub sparsity: f32,
    /// κ.
    pub kappa: f32,
    /// σ_r.
    pub sigma_r: f32,
    /// λ.
    pub lambda: f32,
    /// Jacobi iterations of the fusion.
    pub jacobi: u32,
    /// The caches' error metric.
    pub metric: rt_gree::ErrorMetric,
}

impl Default for GreeSpec {
    fn default() -> Self {
        let p = GreeParams::default();
        Self {
            fraction: p.noisy_fraction,
            sparsity: p.sparsity,
            kappa: p.kappa,
            sigma_r: p.sigma_r,
            lambda: p.lambda,
            jacobi: p.jacobi_iters,
            metric: p.metric,
        }
    }
}

impl GreeSpec {
    /// GREE's parameters at budget `budget` spp with placement seed `seed`, checked.
    pub fn params(&self, budget: u32, seed: u32) -> Result<GreeParams, GreeError> {
        let p = GreeParams {
            budget: budget as f32,
            seed,
            noisy_fraction: self.fraction,
            sparsity: self.sparsity,
            kappa: self.kappa,
            sigma_r: self.sigma_r,
            lambda: self.lambda,
            jacobi_iters: self.jacobi,
            metric: self.metric,
        };
        p.validate()?;
        Ok(p)
    }
}

fn metric_name(m: rt_gree::ErrorMetric) -> &'static str {
    match m {
        rt_gree::ErrorMetric::Squared => "squared",
        rt_gree::ErrorMetric::Relative => "relative",
    }
}

impl std::str::FromStr for GreeSpec {
    type Err = rt_core::options::OptionsError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let mut o = rt_core::options::Options::of("gree", text)?;
        let d = GreeSpec::default();
        let num = |o: &mut rt_core::options::Options, key: &str, default: f32| {
            o.value_in::<f32>(key, "a finite number", |v| v.is_finite())
                .map(|v| v.unwrap_or(default))
        };
        let spec = GreeSpec {
            fraction: num(&mut o, "fraction", d.fraction)?,
            sparsity: num(&mut o, "sparsity", d.sparsity)?,
            kappa: num(&mut o, "kappa", d.kappa)?,
            sigma_r: num(&mut o, "sigma-r", d.sigma_r)?,
            lambda: num(&mut o, "lambda", d.lambda)?,
            jacobi: o
                .value("jacobi", "a non-negative integer")?
                .unwrap_or(d.jacobi),
            metric: match o.choice("metric", &["squared", "relative"])? {
                Some("relative") => rt_gree::ErrorMetric::Relative,
                Some(_) => rt_gree::ErrorMetric::Squared,
                None => d.metric,
            },
        };
        o.finish()?;
        Ok(spec)
    }
}

impl std::fmt::Display for GreeSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let d = GreeSpec::default();
        let mut parts = Vec::new();
        for (key, v, dv) in [
            ("fraction", self.fraction, d.fraction),
            ("sparsity", self.sparsity, d.sparsity),
            ("kappa", self.kappa, d.kappa),
            ("sigma-r", self.sigma_r, d.sigma_r),
            ("lambda", self.lambda, d.lambda),
        ] {
            if v != dv {
                parts.push(format!("{key}={v}"));
            }
        }
        if self.jacobi != d.jacobi {
            parts.push(format!("jacobi={}", self.jacobi));
        }
        if self.metric != d.metric {
            parts.push(format!("metric={}", metric_name(self.metric)));
        }
        f.write_str(&parts.join(":"))
    }
}

/// A distinct colour per label (golden-angle hues), the same in the label PNG and the legend.
pub fn label_colour(label: u16) -> Rgb {
    let h = (label as f32 * 0.618_034).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    // Linear values whose sRGB encoding is the saturated hue at 80 % value.
    Rgb::new(r, g, b) * 0.6
}

impl GreeRun {
    /// Writes the chosen filter per pixel as a colour-coded image ([`label_colour`]).
    pub fn write_labels(&self, path: &std::path::Path) -> Result<(), rt_film::FilmError> {
        let (w, h) = self.frame.colour.size();
        let colours = self
            .composite
            .labels
            .iter()
            .map(|&l| label_colour(l))
            .collect();
        let img = rt_core::Image::new(w, h, colours).expect("one label per pixel");
        rt_film::write_rgb(path, &img, &rt_film::OutputOptions::default())
    }

    /// Writes each filter's dense error map into `dir` as EXR (the value in every channel)
    /// and as a false-colour PNG on one log scale shared by all filters (1st to 99th
    /// percentile of all values), so that the maps compare at a glance; `names` are the
    /// bank's members.
    pub fn write_error_maps(
        &self,
        dir: &std::path::Path,
        names: &[&str],
    ) -> Result<(), rt_film::FilmError> {
        std::fs::create_dir_all(dir).map_err(|source| rt_film::FilmError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let (w, h) = self.frame.colour.size();
        let mut all: Vec<f32> = self
            .composite
            .error_maps
            .iter()
            .flatten()
            .copied()
            .filter(|v| *v > 0.0 && v.is_finite())
            .collect();
        all.sort_by(f32::total_cmp);
        let at = |q: f64| {
            all.get(((all.len().saturating_sub(1)) as f64 * q) as usize)
                .copied()
                .unwrap_or(1.0)
        };
        let (lo, hi) = (at(0.01).max(1e-12).log10(), at(0.99).max(1e-12).log10());
        let span = (hi - lo).max(1e-6);
        let opts = rt_film::OutputOptions::default();
        for (i, (map, name)) in self.composite.error_maps.iter().zip(names).enumerate() {
            let file = format!("{i:02}-{}", name.replace([':', '=', '/'], "_"));
            let raw = rt_core::RgbImage::new(w, h, map.iter().map(|&v| Rgb::splat(v)).collect())
                .expect("one error per pixel");
            rt_film::write_rgb(&dir.join(format!("{file}.exr")), &raw, &opts)?;
            let colour = raw.map(|v| {
                let t = (v.x.max(1e-12).log10() - lo) / span;
                rt_metrics::viridis(t as f64)
            });
            rt_film::write_rgb(&dir.join(format!("{file}.png")), &colour, &opts)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_parse_over_the_defaults_round_trip_and_refuse_bad_values() {
        let s: GreeSpec = "sparsity=0.9:kappa=0.5,metric=relative".parse().unwrap();
        let p = s.params(32, 7).unwrap();
        assert_eq!((p.budget, p.sparsity, p.kappa, p.seed), (32.0, 0.9, 0.5, 7));
        assert_eq!(p.metric, rt_gree::ErrorMetric::Relative);
        assert_eq!(s.to_string(), "sparsity=0.9:kappa=0.5:metric=relative");
        assert_eq!(s.to_string().parse::<GreeSpec>(), Ok(s));
        assert_eq!("".parse::<GreeSpec>(), Ok(GreeSpec::default()));
        assert_eq!(GreeSpec::default().to_string(), "");
        assert!("sparsity=1.5"
            .parse::<GreeSpec>()
            .unwrap()
            .params(32, 0)
            .is_err());
        for (bad, says) in [
            ("kappa=x", "gree: kappa: `x` is not a finite number"),
            ("colour=1", "gree: unknown option `colour`"),
            ("lambda", "gree: option `lambda` needs a value"),
            (
                "metric=l1",
                "gree: metric: `l1` is not one of squared, relative",
            ),
            ("kappa=1:kappa=2", "gree: option `kappa` given twice"),
        ] {
            let e = bad.parse::<GreeSpec>().unwrap_err().to_string();
            assert!(e.starts_with(says), "{bad}: {e}");
        }
    }
}
