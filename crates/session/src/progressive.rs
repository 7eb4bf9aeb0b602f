//! Progressive rendering of one configuration: a list of budgets (samples per pixel or
//! seconds) rendered pass after pass into one film, so a list of budgets costs only its largest,
//! and the image at N spp is bit for bit the one a single N-spp render gives (the passes draw
//! sample indices `a..b` of the same streams).

use crate::MAX_SPP;
use rt_core::SampleStream;
use rt_film::{Film, FilmBuffers};
use rt_integrators::{Ctx, SamplePass, Technique};

/// How much to render: samples per pixel, or a time.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// Stop at each of these sample counts (ascending, distinct).
    Spp(Vec<u32>),
    /// Stop as soon as the render time reaches each of these seconds (ascending, distinct).
    Seconds(Vec<f64>),
}

impl Budgets {
    /// How many stops.
    pub fn len(&self) -> usize {
        match self {
            Budgets::Spp(v) => v.len(),
            Budgets::Seconds(v) => v.len(),
        }
    }

    /// True when there is no stop (nothing would be rendered).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Where a progressive render stands at one of its stops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Checkpoint {
    /// Index of the budget just reached.
    pub budget: usize,
    /// Samples per pixel so far.
    pub spp: u32,
    /// Render time so far (the passes only: not scene loading, acceleration structure build,
    /// or what the caller does at checkpoints).
    pub seconds: f64,
    /// Camera samples so far.
    pub samples: u64,
    /// Rays traced so far (closest-hit and shadow).
    pub rays: u64,
    /// Samples dropped as non-finite or negative so far.
    pub discarded: u64,
}

/// One configuration ready to render.
pub struct Session<'a> {
    /// Scene, acceleration structure and camera (already resized).
    pub ctx: Ctx<'a>,
    /// The estimator.
    pub integrator: &'a dyn Technique,
    /// Seed of the sample streams.
    pub seed: u32,
    /// Normal or reference streams.
    pub stream: SampleStream,
    /// The buffers the film keeps besides the mean ([`FilmBuffers::for_outputs`] of the AOVs
    /// written, and what a denoiser reads).
    pub buffers: FilmBuffers,
}

impl Session<'_> {
    /// Renders into one film, pass after pass, and calls `checkpoint` each time the next of
    /// `budgets` is reached; returns the final film. Call it inside the thread pool that should
    /// do the work. `progress` gets the fraction of the largest budget done (from worker
    /// threads).
    ///
    /// Errors are the checkpoint's own: rendering itself cannot fail.
    ///
    /// Sample budgets are exact. A time budget is reached by passes whose size is predicted
    /// from the time per sample so far, never more than doubling the samples taken (a bad
    /// prediction overshoots by at most one pass), rounded to whole samples per pixel: the
    /// reported time is the real one, within about half a sample's time of the budget.
    pub fn render<E>(
        &self,
        budgets: &Budgets,
        progress: &(dyn Fn(f64) + Sync),
        checkpoint: &mut dyn FnMut(&Film, &Checkpoint) -> Result<(), E>,
    ) -> Result<Film, E> {
        let camera = self.ctx.camera;
        let mut film = Film::new(camera.width, camera.height, self.buffers);
        let mut at = Checkpoint::default();
        let rows = camera.height.max(1) as f64;
        let pass = |film: &mut Film,
                    at: &mut Checkpoint,
                    n: u32,
                    done_fraction: &(dyn Fn(f64) -> f64 + Sync)| {
            let pass = SamplePass {
                indices: at.spp..at.spp + n,
                stream: self.stream,
                pixels: None,
                centre_first: false,
            };
            let stats = self
                .integrator
                .render_pass(&self.ctx, film, self.seed, &pass, &|r| {
                    progress(done_fraction(r as f64 / rows))
                });
            at.spp += n;
            at.seconds += stats.elapsed.as_secs_f64();
            at.samples += stats.samples;
            at.rays += stats.rays.rays + stats.rays.shadow_rays;
            at.discarded += stats.discarded;
        };
        match budgets {
            Budgets::Spp(list) => {
                let last = f64::from(list.last().copied().unwrap_or(1).max(1));
                for (i, &spp) in list.iter().enumerate() {
                    if spp > at.spp {
                        let count = spp - at.spp;
                        let (from, n) = (f64::from(at.spp), f64::from(count));
                        pass(&mut film, &mut at, count, &|f| (from + f * n) / last);
                    }
                    at.budget = i;
                    checkpoint(&film, &at)?;
                }
            }
            Budgets::Seconds(list) => {
                let last = list.last().copied().unwrap_or(1.0).max(1e-9);
                for (i, &budget) in list.iter().enumerate() {
                    while at.spp < MAX_SPP {
                        let n = if at.spp == 0 {
                            1
                        } else {
                            let per_spp = at.seconds / f64::from(at.spp);
                            let fit = ((budget - at.seconds) / per_spp.max(1e-12)).round();
                            fit.clamp(0.0, f64::from(at.spp.min(MAX_SPP - at.spp))) as u32
                        };
                        if n == 0 {
                            break;
                        }
                        let t0 = at.seconds;
                        pass(&mut film, &mut at, n, &|_| t0 / last);
                        progress((at.seconds / last).min(1.0));
                    }
                    at.budget = i;
                    checkpoint(&film, &at)?;
                }
            }
        }
        Ok(film)
    }
}
