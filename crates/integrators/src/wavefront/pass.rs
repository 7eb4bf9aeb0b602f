//! One pass of the wavefront tracer: bands of rows in parallel (as the scalar driver), each
//! band's samples streamed through one thread's batch.
//!
//! A batch holds up to `capacity` paths. Each round: finished lanes are refilled with the
//! band's next samples (camera rays), every lane's ray is traced in one stream, every lane's
//! vertex draws are made in one vectorised kernel, every lane is shaded (emission, light
//! sample, BSDF sample, roulette), the shadow rays are traced in one stream, and the paths
//! that ended are added to the film and compacted away. A sample's value does not depend on
//! its lane, its round or its neighbours, and the film's sums are exact integers, so the image
//! is the same bits for any capacity, thread count or split into passes.

use super::lanes::{draw_vertices, Batch, PathState, DIMS_PER_VERTEX};
use super::profile::{Profile, Stage};
use super::shade::Shader;
use super::Wavefront;
use crate::driver::{pass_stats, CameraSampling, RenderStats, SamplePass};
use crate::{Ctx, RayCounters};
use rayon::prelude::*;
use rt_core::{Rgb, Sampler};
use rt_film::{Film, FilmStripe};
use std::cell::RefCell;
use std::sync::Mutex;
use std::time::Instant;

/// Fewest rows per parallel work item, as in the scalar driver.
const BAND_ROWS: u32 = 2;

/// Rows per work item: enough samples to fill the batch several times over (a batch drains
/// at the end of its band, through the long tail of deep paths), but at least four items per
/// thread so the threads finish together.
fn band_rows(film: &Film, pass: &SamplePass, capacity: usize) -> u32 {
    let per_row = (u64::from(film.width()) * pass.indices.len() as u64).max(1);
    let wanted = (8 * capacity as u64).div_ceil(per_row);
    let most = film.height() / (4 * rayon::current_num_threads() as u32).max(1);
    (wanted.min(u64::from(u32::MAX)) as u32)
        .min(most)
        .max(BAND_ROWS)
}

/// Renders `pass` into `film` with `tracer`'s estimator and batch size; adds what the stages
/// did to its profile.
pub(super) fn render_pass(
    tracer: &Wavefront,
    ctx: &Ctx<'_>,
    film: &mut Film,
    seed: u32,
    pass: &SamplePass,
    progress: &(dyn Fn(u32) + Sync),
) -> RenderStats {
    let (settings, capacity, profile) = (&tracer.settings, tracer.lanes, &tracer.profile);
    let start = Instant::now();
    let discarded_before = film.discarded();
    let want_first_hit = film.aovs().any_first_hit();
    let lights = if settings.next_event {
        ctx.scene.lights()
    } else {
        &rt_core::lights::LightSampler::NONE
    };
    let shader = Shader {
        ctx: *ctx,
        settings,
        lights,
        use_nee: !lights.is_empty(),
        want_first_hit,
    };
    let camera = CameraSampling::new(ctx).centre_first(pass.centre_first);
    let totals = Mutex::new(RayCounters::default());
    let rows_done = std::sync::atomic::AtomicU32::new(0);
    let rows = band_rows(film, pass, capacity);
    film.stripes_mut(rows)
        .into_par_iter()
        .for_each_init(Profile::default, |local, mut stripe| {
            let mut counters = RayCounters::default();
            let mut samples = StripeSamples::new(&stripe, pass);
            with_batch(capacity, |batch| {
                render_stripe(
                    &shader,
                    &camera,
                    seed,
                    pass,
                    batch,
                    &mut samples,
                    &mut stripe,
                    &mut counters,
                    local,
                )
            });
            let done = rows_done.fetch_add(stripe.rows(), std::sync::atomic::Ordering::Relaxed);
            progress(done + stripe.rows());
            *totals.lock().unwrap_or_else(|e| e.into_inner()) += counters;
            profile
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take(local);
        });
    let rays = totals.into_inner().unwrap_or_else(|e| e.into_inner());
    pass_stats(film, pass, start, discarded_before, rays)
}

thread_local! {
    /// Each worker thread's batch, kept from band to band and pass to pass: allocated once
    /// per thread (and again only for another batch size), never per sample or per band.
    static BATCH: RefCell<Option<Batch>> = const { RefCell::new(None) };
}

/// Runs `f` on this thread's batch of `capacity` lanes.
fn with_batch<R>(capacity: usize, f: impl FnOnce(&mut Batch) -> R) -> R {
    BATCH.with(|cell| {
        let mut slot = cell.borrow_mut();
        let batch = match slot.take() {
            Some(b) if b.capacity == capacity => slot.insert(b),
            _ => slot.insert(Batch::new(capacity)),
        };
        batch.paths.clear();
        f(batch)
    })
}

/// The samples of one band in order: pixels row by row, each pixel's indices in order,
/// skipping the pixels the pass leaves out.
struct StripeSamples {
    x: u32,
    y: u32,
    i: u32,
    width: u32,
    y_end: u32,
}

impl StripeSamples {
    fn new(stripe: &FilmStripe<'_>, pass: &SamplePass) -> Self {
        Self {
            x: 0,
            y: stripe.y0,
            i: pass.indices.start,
            width: stripe.width,
            y_end: stripe.y0 + stripe.rows(),
        }
    }

    #[inline]
    fn next(&mut self, pass: &SamplePass) -> Option<(u32, u32, u32)> {
        loop {
            if self.y >= self.y_end || pass.indices.is_empty() {
                return None;
            }
            let (x, y, i) = (self.x, self.y, self.i);
            let taken = pass
                .pixels
                .as_ref()
                .is_none_or(|m| m[(y * self.width + x) as usize]);
            // Advance: next index, else next pixel.
            if taken && self.i + 1 < pass.indices.end {
                self.i += 1;
            } else {
                self.i = pass.indices.start;
                self.x += 1;
                if self.x == self.width {
                    self.x = 0;
                    self.y += 1;
                }
            }
            if taken {
                return Some((x, y, i));
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn render_stripe(
    shader: &Shader<'_>,
    camera: &CameraSampling<'_>,
    seed: u32,
    pass: &SamplePass,
    batch: &mut Batch,
    samples: &mut StripeSamples,
    stripe: &mut FilmStripe<'_>,
    counters: &mut RayCounters,
    profile: &mut Profile,
) {
    let accel = shader.ctx.accel;
    let mut sampler = Sampler::with_stream(seed, pass.stream);
    let mut exhausted = false;
    loop {
        // Refill finished lanes with camera rays.
        let mut clock = Instant::now();
        while !exhausted && batch.paths.len() < batch.capacity {
            let Some(xyi) = samples.next(pass) else {
                exhausted = true;
                break;
            };
            let ray = camera.ray(&mut sampler, xyi);
            batch.paths.push(PathState {
                x: xyi.0,
                y: xyi.1,
                index: xyi.2,
                key: sampler.key(),
                dim0: sampler.dimension(),
                ray,
                beta: Rgb::ONE,
                l: Rgb::ZERO,
                prev_delta: true,
                prev_pdf: 0.0,
                prev_p: ray.origin,
                depth: 0,
                lambda: None,
                first_hit: None,
                done: false,
            });
        }
        let n = batch.paths.len();
        if n == 0 {
            break;
        }
        profile.lap(Stage::Generate, &mut clock);
        profile.round(n, batch.capacity);

        // Closest hits of every lane, one stream.
        batch.rays.clear();
        batch.rays.extend(batch.paths.iter().map(|p| p.ray));
        accel.intersect_stream(&batch.rays, &batch.t_max[..n], &mut batch.hits[..n]);
        counters.rays += n as u64;
        profile.lap(Stage::Trace, &mut clock);

        // Every lane's random numbers for this vertex.
        batch.keys.clear();
        batch.dims.clear();
        for p in &batch.paths {
            batch.keys.push(p.key);
            batch.dims.push(p.dim0 + DIMS_PER_VERTEX * p.depth);
        }
        draw_vertices(&batch.keys, &batch.dims, &mut batch.draws[..n]);
        profile.lap(Stage::Draw, &mut clock);

        // Shade; collect the shadow rays.
        batch.shadows.clear();
        batch.lambert.clear();
        for (k, path) in batch.paths.iter_mut().enumerate() {
            let shadow = shader.vertex(
                path,
                batch.hits[k],
                &batch.draws[k],
                k as u32,
                &mut batch.lambert,
            );
            batch.shadows.push(shadow);
        }
        profile.lap(Stage::Shade, &mut clock);

        // The plain Lambertian vertices' BSDF stage, eight lanes at a time.
        batch.lambert.run();
        for j in 0..batch.lambert.len() {
            let lane = batch.lambert.lane[j];
            let shadow = shader.finish_lambert(
                &mut batch.paths[lane as usize],
                &batch.lambert.surface[j],
                batch.lambert.light[j].as_ref(),
                &batch.lambert.result(j),
                batch.draws[lane as usize].rr,
                lane,
            );
            batch.shadows.push(shadow);
        }
        profile.lap(Stage::Bsdf, &mut clock);

        // Shadow rays, one stream.
        let shadows = &mut batch.shadows;
        let m = shadows.pending.len();
        if m > 0 {
            accel.occluded_stream(
                &shadows.rays,
                &shadows.t_max,
                &shadows.toward,
                &mut shadows.occluded[..m],
            );
            counters.shadow_rays += m as u64;
            for (s, &occluded) in shadows.pending.iter().zip(&shadows.occluded[..m]) {
                if !occluded {
                    batch.paths[s.lane as usize].l += s.contribution;
                }
            }
        }
        profile.lap(Stage::Shadow, &mut clock);

        // Finished paths go to the film; the rest move up.
        batch.paths.retain(|p| {
            if p.done {
                let (xyi, hit) = ((p.x, p.y, p.index), p.first_hit.as_ref());
                camera.add_to_film(stripe, &mut sampler, xyi, p.l, hit, None);
            }
            !p.done
        });
        profile.lap(Stage::Accumulate, &mut clock);
    }
}
