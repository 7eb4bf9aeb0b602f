//! The whole of GREE (thesis §5.1, Fig. 5.3): place caches, render them, measure each filter's
//! error at the caches, interpolate dense error maps, label by graph cut, fuse.

use crate::error::GreeError;
use crate::errors::sparse_errors;
use crate::fusion::{composite_image, fuse};
use crate::graph_cut::{alpha_expansion, CutOptions, LabelProblem};
use crate::interpolate::Interpolator;
use crate::params::GreeParams;
use crate::placement::{place, PlacementParams};
use crate::renderer::CacheRenderer;
use crate::scale::mean_radiance;
use rt_core::RgbImage;
use std::time::{Duration, Instant};

/// Wall-clock time of each stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    /// Cache placement (bank variance, P_FN, blue noise, importance draw).
    pub placement: Duration,
    /// The renderer's [`CacheRenderer::render_caches`].
    pub cache_render: Duration,
    /// Sparse errors at the caches.
    pub errors: Duration,
    /// Triangulation, weights and the dense maps.
    pub interpolation: Duration,
    /// Argmin and α-expansion.
    pub graph_cut: Duration,
    /// Composite and Poisson fusion.
    pub fusion: Duration,
}

impl StageTimes {
    /// The sum of all stages.
    pub fn total(&self) -> Duration {
        self.placement
            + self.cache_render
            + self.errors
            + self.interpolation
            + self.graph_cut
            + self.fusion
    }

    /// GREE's own time: everything but the cache render.
    pub fn own(&self) -> Duration {
        self.total() - self.cache_render
    }
}

/// What [`composite`] returns.
#[derive(Clone, Debug)]
pub struct Composite {
    /// The fused composite.
    pub image: RgbImage,
    /// The graph-cut labels, row-major (index into the bank).
    pub labels: Vec<u16>,
    /// The dense error map of each filter, row-major, in the metric's units (unscaled).
    pub error_maps: Vec<Vec<f32>>,
    /// The cache pixels, in placement order.
    pub caches: Vec<(u32, u32)>,
    /// The per-pixel argmin of the error maps, without graph cut or fusion (for comparisons).
    pub argmin_image: RgbImage,
    /// The per-pixel argmin labels.
    pub argmin_labels: Vec<u16>,
    /// The labelling energy at the argmin and after the graph cut.
    pub energy: (f64, f64),
    /// α-expansion sweeps run and expansions accepted.
    pub cut_moves: (u32, u32),
    /// Wall-clock time of each stage.
    pub timings: StageTimes,
    /// Samples the caches traced (`caches · c`).
    pub samples_traced: u64,
}

fn check_image<E>(what: String, img: &RgbImage, size: (usize, usize)) -> Result<(), GreeError<E>> {
    if (img.width(), img.height()) != size {
        return Err(GreeError::SizeMismatch {
            what,
            expected: size,
            got: (img.width(), img.height()),
        });
    }
    if let Some(i) = img.pixels().iter().position(|p| !p.is_finite()) {
        return Err(GreeError::NonFinite {
            what,
            x: i % size.0,
            y: i / size.0,
        });
    }
    Ok(())
}

fn check_inputs<E>(
    noisy: &RgbImage,
    variance_of_mean: &RgbImage,
    bank: &[RgbImage],
) -> Result<(), GreeError<E>> {
    let size = (noisy.width(), noisy.height());
    if size.0 == 0 || size.1 == 0 {
        return Err(GreeError::EmptyImage {
            width: size.0,
            height: size.1,
        });
    }
    if bank.is_empty() {
        return Err(GreeError::EmptyBank);
    }
    if bank.len() > u16::MAX as usize {
        return Err(GreeError::TooManyFilters { count: bank.len() });
    }
    check_image("the noisy image".into(), noisy, size)?;
    check_image("variance_of_mean".into(), variance_of_mean, size)?;
    if let Some(i) = variance_of_mean
        .pixels()
        .iter()
        .position(|p| p.min_element() < 0.0)
    {
        return Err(GreeError::NegativeVariance {
            x: i % size.0,
            y: i / size.0,
        });
    }
    for (i, f) in bank.iter().enumerate() {
        check_image(format!("bank[{i}]"), f, size)?;
    }
    Ok(())
}

/// Runs GREE: `noisy` is N (n spp, checked for size and finiteness; the bank already carries
/// it), `variance_of_mean` its per-channel variance of the pixel mean, `bank` the filtered
/// images F_1..F_m of N, `renderer` renders the caches at `params.budget_split().c` spp.
pub fn composite<R: CacheRenderer>(
    noisy: &RgbImage,
    variance_of_mean: &RgbImage,
    bank: &[RgbImage],
    renderer: &mut R,
    params: &GreeParams,
) -> Result<Composite, GreeError<R::Error>> {
    params.validate().map_err(GreeError::widen)?;
    check_inputs(noisy, variance_of_mean, bank)?;
    let (w, h) = (noisy.width(), noisy.height());
    let budget = params.budget_split();
    let mut timings = StageTimes::default();
    let mu = mean_radiance(bank);

    let t = Instant::now();
    let placement = PlacementParams {
        count: budget.caches(w * h),
        kappa: params.kappa,
        sigma_r: params.sigma_r,
        mu,
        seed: params.seed,
    };
    let caches = place(bank, variance_of_mean, &placement);
    timings.placement = t.elapsed();

    let t = Instant::now();
    let values = renderer
        .render_caches(&caches, budget.c)
        .map_err(GreeError::Renderer)?;
    timings.cache_render = t.elapsed();
    if values.len() != caches.len() {
        return Err(GreeError::CacheCount {
            expected: caches.len(),
            got: values.len(),
        });
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(GreeError::NonFiniteCache {
            x: caches[k].0,
            y: caches[k].1,
        });
    }
    let samples_traced = caches.len() as u64 * budget.c as u64;

    let t = Instant::now();
    let sparse = sparse_errors(bank, &caches, &values, params.metric);
    timings.errors = t.elapsed();

    let t = Instant::now();
    let interp = Interpolator::new(w, h, &caches).map_err(GreeError::Interpolation)?;
    let error_maps: Vec<Vec<f32>> = sparse.iter().map(|e| interp.apply(e)).collect();
    timings.interpolation = t.elapsed();

    let t = Instant::now();
    let problem = LabelProblem::with_mean(bank, &error_maps, params.lambda, params.metric, mu);
    let argmin_labels = problem.argmin();
    let cut = alpha_expansion(&problem, argmin_labels.clone(), &CutOptions::default());
    timings.graph_cut = t.elapsed();

    let t = Instant::now();
    let image = fuse(bank, &cut.labels, params.jacobi_iters);
    let argmin_image = composite_image(bank, &argmin_labels);
    timings.fusion = t.elapsed();

    Ok(Composite {
        image,
        labels: cut.labels,
        error_maps,
        caches,
        argmin_image,
        argmin_labels,
        energy: (cut.initial_energy, cut.energy),
        cut_moves: (cut.sweeps, cut.accepted),
        timings,
        samples_traced,
    })
}
