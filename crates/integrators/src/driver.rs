//! The image loop: bands of rows in parallel, every sample from a deterministic stream.
//!
//! Each pixel's samples are taken in index order by one worker, and every random number is a
//! function of (seed, pixel, sample index, dimension), so the image is bit-identical whatever
//! the thread count or scheduling. The pixel filter is a box: a sample counts only in the pixel
//! it was taken in, which keeps pixel noise independent for the denoisers downstream.

use crate::{Ctx, Integrator, RayCounters, SampleAux};
use rayon::prelude::*;
use rt_core::{glam::Vec2, SampleStream, Sampler};
use rt_film::Film;
use std::ops::Range;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How many samples, with which seed.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Samples per pixel.
    pub spp: u32,
    /// Global seed of all sample streams.
    pub seed: u32,
}

/// What a render did.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    /// Wall-clock time.
    pub elapsed: Duration,
    /// Camera samples taken.
    pub samples: u64,
    /// Rays traced (closest hit and occlusion).
    pub rays: RayCounters,
    /// Samples dropped for being NaN, infinite or negative.
    pub discarded: u64,
}

impl RenderStats {
    /// Camera samples per second.
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// Rays (both kinds) per second.
    pub fn rays_per_second(&self) -> f64 {
        (self.rays.rays + self.rays.shadow_rays) as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// Rows per parallel work item: small enough to balance load on uneven images, large enough
/// that scheduling is noise.
const BAND_ROWS: u32 = 2;

/// Which samples of every pixel one call of [`render_samples`] takes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SamplePass {
    /// Sample indices, taken in order. Passes `0..a`, `a..b`, ... on one film give the same
    /// image, bit for bit, as one pass `0..b`: a pixel sees the same samples in the same order.
    pub indices: Range<u32>,
    /// The family of streams the samples come from (references use their own).
    pub stream: SampleStream,
}

/// Renders `opts.spp` samples into every pixel of `film`. `progress` is called with the number
/// of rows finished so far (from worker threads).
pub fn render(
    ctx: &Ctx<'_>,
    integrator: &dyn Integrator,
    film: &mut Film,
    opts: &RenderOptions,
    progress: &(dyn Fn(u32) + Sync),
) -> RenderStats {
    let pass = SamplePass {
        indices: 0..opts.spp,
        stream: SampleStream::Render,
    };
    render_samples(ctx, integrator, film, opts.seed, &pass, progress)
}

/// Adds the samples `pass.indices` of every pixel to `film`: one pass of a progressive render
/// (time budgets render pass after pass until the time is used). `progress` is called with the
/// number of rows of this pass finished so far (from worker threads).
pub fn render_samples(
    ctx: &Ctx<'_>,
    integrator: &dyn Integrator,
    film: &mut Film,
    seed: u32,
    pass: &SamplePass,
    progress: &(dyn Fn(u32) + Sync),
) -> RenderStats {
    let start = Instant::now();
    let discarded_before = film.discarded();
    let want_first_hit = film.aovs().any_first_hit();
    let totals = Mutex::new(RayCounters::default());
    let rows_done = std::sync::atomic::AtomicU32::new(0);
    let camera = ctx.camera;
    film.stripes_mut(BAND_ROWS)
        .into_par_iter()
        .for_each(|mut stripe| {
            let mut sampler = Sampler::with_stream(seed, pass.stream);
            let mut counters = RayCounters::default();
            for y in stripe.y0..stripe.y0 + stripe.rows() {
                for x in 0..stripe.width {
                    for i in pass.indices.clone() {
                        sampler.start(x, y, i);
                        let film_pos = Vec2::new(x as f32, y as f32) + sampler.next_2d();
                        let lens = sampler.next_2d();
                        let ray = camera.generate_ray(film_pos, lens);
                        let mut aux = SampleAux {
                            want_first_hit,
                            first_hit: None,
                        };
                        let l = integrator.li(ctx, ray, &mut sampler, &mut aux, &mut counters);
                        stripe.add_sample(x, y, i, l, aux.first_hit.as_ref());
                    }
                }
                let done = rows_done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(done);
            }
            *totals.lock().unwrap_or_else(|e| e.into_inner()) += counters;
        });
    let rays = totals.into_inner().unwrap_or_else(|e| e.into_inner());
    RenderStats {
        elapsed: start.elapsed(),
        samples: film.width() as u64 * film.height() as u64 * pass.indices.len() as u64,
        rays,
        discarded: film.discarded() - discarded_before,
    }
}
