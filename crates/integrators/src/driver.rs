//! The image loop: bands of rows in parallel, every sample from a deterministic stream.
//!
//! Each pixel's samples are taken in index order by one worker, and every random number is a
//! function of (seed, pixel, sample index, dimension), so the image is bit-identical whatever
//! the thread count or scheduling. A sample counts only in the pixel it was taken in (the box,
//! or a filter applied by importance sampling), which keeps pixel noise independent for the
//! denoisers downstream; a camera whose filter splats ([`rt_core::pixel_filter`]) has the
//! film add it to every pixel under the filter instead (`CameraSampling::add_to_film`).
//!
//! Dimension layout of one sample: the film position (one 2D draw), the lens position (one 2D
//! draw, only for a thin-lens camera: a pinhole ignores it, so it is not drawn), then whatever
//! the integrator draws. Pinhole images therefore use the integrator's dimensions one draw
//! earlier than thin-lens images do. With motion blur (something moves while the scene's
//! shutter is open) the shutter time follows the lens (one 1D draw): every ray of the sample
//! carries it, and a moving camera is placed at it.

use crate::{Ctx, Integrator, RayCounters, SampleAux};
use rayon::prelude::*;
use rt_core::{glam::Vec2, SampleStream, Sampler};
use rt_film::{Film, FilmStripe, SampleRecords};
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

impl std::ops::AddAssign for RenderStats {
    /// The stats of two passes together (their times add: passes run one after another).
    fn add_assign(&mut self, other: Self) {
        self.elapsed += other.elapsed;
        self.samples += other.samples;
        self.rays += other.rays;
        self.discarded += other.discarded;
    }
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
    /// Per pixel (row-major), whether it takes this pass's samples; `None`: every pixel. The
    /// stopping criterion leaves out the pixels of finished blocks. Light-path techniques
    /// cannot aim their splats and ignore it.
    pub pixels: Option<std::sync::Arc<[bool]>>,
    /// Sample 0 of every pixel goes through the pixel's centre instead of a jittered point:
    /// the "guide ray" of a sequence frame (Bauszat et al. 2011), whose first hit is the one
    /// [`crate::render_guides`] describes. The jitter is still drawn, so every later
    /// dimension is the same as without it.
    pub centre_first: bool,
}

impl SamplePass {
    /// Samples `indices` of every pixel from the render streams, jittered: a plain render's
    /// pass.
    pub fn render(indices: Range<u32>) -> Self {
        Self {
            indices,
            stream: SampleStream::Render,
            pixels: None,
            centre_first: false,
        }
    }
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
    let pass = SamplePass::render(0..opts.spp);
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
    let keep_samples = film.buffers().samples;
    let want_first_hit = film.aovs().any_first_hit() || keep_samples;
    // Callers refuse split AOVs for integrators that cannot write them; this keeps a film's
    // split sums from being filled with zeros if one slips through.
    let want_split = film.aovs().any_split() && integrator.writes_split();
    let totals = Mutex::new(RayCounters::default());
    let rows_done = std::sync::atomic::AtomicU32::new(0);
    let camera = CameraSampling::new(ctx).centre_first(pass.centre_first);
    // Per-sample records: one slot per pass sample of every pixel, filled band by band
    // alongside the film's stripes, so their order is fixed whatever the thread count.
    let (w, h) = (film.width(), film.height());
    let mut records = keep_samples.then(|| SampleRecords::pass(w, h, pass.indices.len() as u32));
    let bands = records.as_mut().map(|r| r.bands_mut(BAND_ROWS));
    let bands = bands
        .into_iter()
        .flatten()
        .map(Some)
        .chain(std::iter::repeat_with(|| None));
    let stripes: Vec<_> = film.stripes_mut(BAND_ROWS).into_iter().zip(bands).collect();
    stripes
        .into_par_iter()
        .for_each(|(mut stripe, mut record)| {
            let mut sampler = Sampler::with_stream(seed, pass.stream);
            let mut counters = RayCounters::default();
            for y in stripe.y0..stripe.y0 + stripe.rows() {
                for x in 0..stripe.width {
                    if let Some(mask) = &pass.pixels {
                        if !mask[(y * stripe.width + x) as usize] {
                            continue;
                        }
                    }
                    for i in pass.indices.clone() {
                        let mut aux = SampleAux {
                            want_first_hit,
                            want_split,
                            ..Default::default()
                        };
                        let l = camera.sample(
                            ctx,
                            integrator,
                            &mut sampler,
                            (x, y, i),
                            &mut aux,
                            &mut counters,
                        );
                        let split = want_split.then_some(&aux.split);
                        let hit = aux.first_hit.as_ref();
                        let kept =
                            camera.add_to_film(&mut stripe, &mut sampler, (x, y, i), l, hit, split);
                        if let (true, Some(r)) = (kept, &mut record) {
                            let hit = aux.first_hit.as_ref();
                            let coc = hit.map_or(ctx.camera.coc_at_infinity(), |h| {
                                ctx.camera.signed_coc_px(h.position)
                            });
                            r.record(x, y, i - pass.indices.start, l, hit, coc);
                        }
                    }
                }
                let done = rows_done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(done);
            }
            *totals.lock().unwrap_or_else(|e| e.into_inner()) += counters;
        });
    if let Some(r) = records {
        film.add_sample_records(r);
    }
    let rays = totals.into_inner().unwrap_or_else(|e| e.into_inner());
    pass_stats(film, pass, start, discarded_before, rays)
}

/// What a camera-ray pass that began at `start` did: its samples (every pixel the pass takes,
/// each index), `rays`, and the samples the film dropped since it held `discarded_before`.
pub(crate) fn pass_stats(
    film: &Film,
    pass: &SamplePass,
    start: Instant,
    discarded_before: u64,
    rays: RayCounters,
) -> RenderStats {
    let pixels = match &pass.pixels {
        Some(mask) => mask.iter().filter(|&&m| m).count() as u64,
        None => film.width() as u64 * film.height() as u64,
    };
    RenderStats {
        elapsed: start.elapsed(),
        samples: pixels * pass.indices.len() as u64,
        rays,
        discarded: film.discarded() - discarded_before,
    }
}

/// How camera samples are taken: the film position, then the lens only for a thin lens, then
/// the shutter time only when something moves while the shutter is open (see the module doc).
pub(crate) struct CameraSampling<'a> {
    camera: &'a rt_core::Camera,
    thin_lens: bool,
    blurred: bool,
    camera_motion: Option<&'a rt_core::animation::CameraMotion>,
    open: f32,
    shutter: f32,
    centre_first: bool,
}

impl<'a> CameraSampling<'a> {
    pub(crate) fn new(ctx: &Ctx<'a>) -> Self {
        let camera = ctx.camera;
        Self {
            camera,
            thin_lens: !camera.is_pinhole(),
            blurred: ctx.scene.is_motion_blurred(&camera.name),
            camera_motion: ctx.scene.camera_motion(&camera.name),
            open: ctx.scene.time,
            shutter: ctx.scene.shutter,
            centre_first: false,
        }
    }

    pub(crate) fn centre_first(mut self, on: bool) -> Self {
        self.centre_first = on;
        self
    }

    /// Sample `i` of pixel `(x, y)`: its camera ray, traced by `integrator`.
    #[inline]
    fn sample(
        &self,
        ctx: &Ctx<'_>,
        integrator: &dyn Integrator,
        sampler: &mut Sampler,
        xyi: (u32, u32, u32),
        aux: &mut SampleAux,
        counters: &mut RayCounters,
    ) -> rt_core::Rgb {
        let ray = self.ray(sampler, xyi);
        integrator.li(ctx, ray, sampler, aux, counters)
    }

    /// The film position of sample `i` of pixel `(x, y)`: the first draw of its stream,
    /// placed by the pixel filter. Leaves `sampler` after that draw.
    #[inline]
    fn film_position(&self, sampler: &mut Sampler, (x, y, i): (u32, u32, u32)) -> Vec2 {
        sampler.start(x, y, i);
        let jitter = sampler.next_2d();
        let jitter = if self.centre_first && i == 0 {
            Vec2::splat(0.5)
        } else {
            jitter
        };
        self.camera.filter.film_position(x, y, jitter)
    }

    /// Adds sample `i` of pixel `(x, y)`, of radiance `l`, to `stripe`: in its pixel, or, when
    /// the camera's filter splats, through the filter around the sample's film position
    /// (drawn again from `sampler`, which is restarted: one hash per sample, and no place
    /// in a path's state to keep it). Returns whether the film kept it.
    #[inline]
    pub(crate) fn add_to_film(
        &self,
        stripe: &mut FilmStripe<'_>,
        sampler: &mut Sampler,
        (x, y, i): (u32, u32, u32),
        l: rt_core::Rgb,
        hit: Option<&rt_film::FirstHit>,
        split: Option<&rt_film::LightSplit>,
    ) -> bool {
        if self.camera.filter.splats() {
            let pos = self.film_position(sampler, (x, y, i));
            stripe.add_filtered(&self.camera.filter, pos, (x, y), i, l)
        } else {
            stripe.add_sample_split(x, y, i, l, hit, split)
        }
    }

    /// The camera ray of sample `i` of pixel `(x, y)`, leaving `sampler` at the integrator's
    /// first dimension.
    #[inline]
    pub(crate) fn ray(&self, sampler: &mut Sampler, (x, y, i): (u32, u32, u32)) -> rt_core::Ray {
        let film_pos = self.film_position(sampler, (x, y, i));
        let lens = if self.thin_lens {
            sampler.next_2d()
        } else {
            Vec2::ZERO
        };
        let camera = self.camera;
        if self.blurred {
            let time = sampler.next_1d();
            match self.camera_motion {
                Some(m) => {
                    let key = m.at(self.open + time * self.shutter);
                    camera.generate_ray_at(&key, time, film_pos, lens)
                }
                None => camera.generate_ray(film_pos, lens).at_time(time),
            }
        } else {
            camera.generate_ray(film_pos, lens)
        }
    }
}

/// The mean radiance of samples `0..spp` of stream `stream` at each pixel of `pixels`, in
/// order: a sparse re-render (GREE's filter caches render a few pixels with many samples from
/// [`SampleStream::Cache`], independent of the image's own samples). Samples are taken exactly
/// as [`render_samples`] takes them, so a pixel's value does not depend on which other pixels
/// are asked for or on the thread count. Non-finite or negative samples are dropped, as the
/// film drops them; a pixel whose every sample was dropped is zero.
pub fn render_pixels(
    ctx: &Ctx<'_>,
    integrator: &dyn Integrator,
    pixels: &[(u32, u32)],
    spp: u32,
    seed: u32,
    stream: SampleStream,
) -> (Vec<rt_core::Rgb>, RenderStats) {
    let start = Instant::now();
    let camera = CameraSampling::new(ctx);
    let totals = Mutex::new(RayCounters::default());
    let discarded = std::sync::atomic::AtomicU64::new(0);
    // Chunks of pixels per work item; each pixel's samples are a function of its coordinates.
    let means: Vec<rt_core::Rgb> = pixels
        .par_chunks(64)
        .flat_map_iter(|chunk| {
            let mut sampler = Sampler::with_stream(seed, stream);
            let mut counters = RayCounters::default();
            let mut dropped = 0u64;
            let out: Vec<rt_core::Rgb> = chunk
                .iter()
                .map(|&(x, y)| {
                    let (mut sum, mut n) = (rt_core::Rgb::ZERO, 0u32);
                    for i in 0..spp {
                        let mut aux = SampleAux::default();
                        let l = camera.sample(
                            ctx,
                            integrator,
                            &mut sampler,
                            (x, y, i),
                            &mut aux,
                            &mut counters,
                        );
                        if rt_film::accepts_sample(l) {
                            sum += l;
                            n += 1;
                        } else {
                            dropped += 1;
                        }
                    }
                    if n == 0 {
                        rt_core::Rgb::ZERO
                    } else {
                        sum / n as f32
                    }
                })
                .collect();
            *totals.lock().unwrap_or_else(|e| e.into_inner()) += counters;
            discarded.fetch_add(dropped, std::sync::atomic::Ordering::Relaxed);
            out
        })
        .collect();
    let stats = RenderStats {
        elapsed: start.elapsed(),
        samples: pixels.len() as u64 * spp as u64,
        rays: totals.into_inner().unwrap_or_else(|e| e.into_inner()),
        discarded: discarded.into_inner(),
    };
    (means, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::{glam::Vec3, Camera, Ray, Rgb, Scene};
    use rt_film::AovSet;

    /// Returns the integrator's first random number as the radiance, so the image shows which
    /// sampler dimension the integrator starts at.
    struct FirstDimension;

    impl Integrator for FirstDimension {
        fn name(&self) -> &str {
            "first-dimension"
        }

        fn li(
            &self,
            _: &Ctx<'_>,
            _: Ray,
            sampler: &mut Sampler,
            _: &mut SampleAux,
            _: &mut RayCounters,
        ) -> Rgb {
            Rgb::splat(sampler.next_1d())
        }
    }

    fn first_dimension_image(aperture: f32, seed: u32) -> Vec<Rgb> {
        let scene = Scene::empty();
        let accel = rt_accel::BruteForce::new(&scene.triangles);
        let camera = Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 3, 2, aperture, 1.0);
        let ctx = Ctx {
            scene: &scene,
            accel: &accel,
            camera: &camera,
        };
        let mut film = Film::new(3, 2, AovSet::default());
        let opts = RenderOptions { spp: 1, seed };
        render(&ctx, &FirstDimension, &mut film, &opts, &|_| {});
        film.mean_image()
    }

    /// What the integrator's first draw is when `skipped_2d` 2D draws precede it.
    fn expected(seed: u32, skipped_2d: usize) -> Vec<Rgb> {
        let mut s = Sampler::new(seed);
        (0..2)
            .flat_map(|y| (0..3).map(move |x| (x, y)))
            .map(|(x, y)| {
                s.start(x, y, 0);
                for _ in 0..skipped_2d {
                    s.next_2d();
                }
                Rgb::splat(s.next_1d())
            })
            .collect()
    }

    /// A first hit at a random distance along the ray (misses in column 0), radiance from the
    /// sampler: every record field depends on the pixel, the sample and the stream.
    struct FakeHits;

    impl Integrator for FakeHits {
        fn name(&self) -> &str {
            "fake-hits"
        }

        fn li(
            &self,
            _: &Ctx<'_>,
            ray: Ray,
            sampler: &mut Sampler,
            aux: &mut SampleAux,
            _: &mut RayCounters,
        ) -> Rgb {
            let t = 0.5 + 4.0 * sampler.next_1d();
            if aux.want_first_hit && ray.dir.x > -0.3 {
                aux.first_hit = Some(rt_film::FirstHit {
                    albedo: Rgb::splat(sampler.next_1d()),
                    normal: -ray.dir,
                    depth: t,
                    position: ray.at(t),
                });
            }
            Rgb::splat(t)
        }
    }

    /// Records of the sample indices between consecutive `bounds`, one pass per pair.
    fn records(threads: usize, bounds: &[u32]) -> rt_film::SampleRecords {
        let scene = Scene::empty();
        let accel = rt_accel::BruteForce::new(&scene.triangles);
        let camera = Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 60.0, 7, 5, 0.1, 1.5);
        let ctx = Ctx {
            scene: &scene,
            accel: &accel,
            camera: &camera,
        };
        let buffers = rt_film::FilmBuffers::for_outputs(AovSet::default()).with_samples();
        let mut film = Film::new(7, 5, buffers);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for p in bounds.windows(2) {
            let pass = SamplePass {
                indices: p[0]..p[1],
                stream: SampleStream::Render,
                pixels: None,
                centre_first: false,
            };
            pool.install(|| render_samples(&ctx, &FakeHits, &mut film, 3, &pass, &|_| {}));
        }
        let rec = film.take_sample_records().unwrap();
        assert_eq!(film.sample_records().unwrap().len(), 0);
        // The film's own mean is the mean of the recorded radiance.
        let i = 2 * 7 + 3;
        let r = rec.pixel_range(i);
        let mean = rec.radiance()[r.clone()].iter().copied().sum::<Rgb>() / r.len() as f32;
        assert!((film.pixel(3, 2).mean() - mean).abs().max_element() < 1e-5);
        rec
    }

    #[test]
    fn sample_records_are_the_same_for_any_thread_count_and_pass_split() {
        let one = records(1, &[0, 4]);
        assert_eq!(one.len(), 7 * 5 * 4);
        assert!((0..5).all(|y| (0..7).all(|x| one.count(x, y) == 4)));
        assert_eq!(records(2, &[0, 4]), one, "two threads");
        assert_eq!(records(2, &[0, 1, 4]), one, "two passes");
        // Misses (left column) and hits both occur; misses carry the CoC at infinity.
        let camera = Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 60.0, 7, 5, 0.1, 1.5);
        let (hits, misses): (Vec<usize>, Vec<usize>) = (0..one.len()).partition(|&j| one.is_hit(j));
        assert!(!hits.is_empty() && !misses.is_empty());
        for &j in &misses {
            assert_eq!(one.coc()[j], camera.coc_at_infinity());
        }
        for &j in &hits {
            assert_eq!(one.coc()[j], camera.signed_coc_px(one.position()[j]));
            let x = one.pixel()[j] % 7;
            assert!(x > 0);
        }
        assert!(one.coc().iter().any(|&c| c < 0.0) && one.coc().iter().any(|&c| c > 0.0));
    }

    #[test]
    fn only_thin_lens_cameras_draw_a_lens_sample() {
        for seed in [0, 7] {
            // Pinhole: the film position alone precedes the integrator.
            assert_eq!(first_dimension_image(0.0, seed), expected(seed, 1));
            // Thin lens: the film position and the lens position.
            assert_eq!(first_dimension_image(0.1, seed), expected(seed, 2));
        }
        assert_ne!(
            expected(0, 1),
            expected(0, 2),
            "the test can tell them apart"
        );
    }

    #[test]
    fn sparse_re_renders_match_the_film_and_do_not_share_its_samples() {
        let scene = Scene::empty();
        let accel = rt_accel::BruteForce::new(&scene.triangles);
        let camera = Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 5, 4, 0.0, 1.0);
        let ctx = Ctx {
            scene: &scene,
            accel: &accel,
            camera: &camera,
        };
        let film_of = |stream| {
            let mut film = Film::new(5, 4, AovSet::default());
            let pass = SamplePass {
                indices: 0..6,
                stream,
                pixels: None,
                centre_first: false,
            };
            render_samples(&ctx, &FirstDimension, &mut film, 3, &pass, &|_| {});
            film.mean_image()
        };
        let cache_film = film_of(SampleStream::Cache);
        let pixels = [(4, 3), (0, 0), (2, 1)];
        let (means, stats) =
            render_pixels(&ctx, &FirstDimension, &pixels, 6, 3, SampleStream::Cache);
        assert_eq!(stats.samples, 18);
        for (&(x, y), m) in pixels.iter().zip(&means) {
            let want = cache_film[(y * 5 + x) as usize];
            assert!((*m - want).abs().max_element() < 1e-6, "{m} vs {want}");
        }
        // Asking for one pixel alone gives its value too.
        let (alone, _) = render_pixels(
            &ctx,
            &FirstDimension,
            &pixels[2..],
            6,
            3,
            SampleStream::Cache,
        );
        assert_eq!(alone[0], means[2]);
        // The render stream's samples are others.
        let render_film = film_of(SampleStream::Render);
        assert!(pixels
            .iter()
            .zip(&means)
            .all(|(&(x, y), m)| *m != render_film[(y * 5 + x) as usize]));
    }
}
