//! The seam between the integrators and a world-space radiance cache (implemented outside this
//! crate, e.g. by `rt-worldcache` through the `render` CLI), and the technique that ends a
//! cache pass after every sample index.
//!
//! How the path tracer uses a cache (the use NVIDIA's SHARC makes of such a cache): at a
//! secondary vertex on a diffuse-dominated surface, when the cache holds enough samples there,
//! the path ends with its throughput times the cached reflected radiance; every path records,
//! for each diffuse-dominated vertex it passed, the radiance it found beyond that vertex
//! divided by the throughput up to it. Records go into the cache's current pass; lookups read
//! only what earlier passes merged, and [`CachedPasses`] merges after every sample index, so
//! the image is the same for any thread count, and later passes (and later frames, when the
//! caller keeps the cache) start from what earlier ones learned.

use crate::driver::{RenderStats, SamplePass};
use crate::technique::{Technique, TechniqueStage};
use crate::{Ctx, Integrator};
use rt_core::glam::Vec3;
use rt_core::Rgb;
use rt_film::Film;
use std::sync::Arc;

/// A world-space cache of reflected radiance (or any per-point signal, e.g. occlusion).
pub trait RadianceCache: Send + Sync {
    /// The cached value at `p` (surface normal `n`) from passes already merged; `None` where
    /// the cache has nothing (or too few samples) there.
    fn lookup(&self, p: Vec3, n: Vec3) -> Option<Rgb>;

    /// Records one estimate `value` at `p` into the current pass; `xi` is a per-sample hash
    /// the cache may draw from (which point receives it).
    fn record(&self, p: Vec3, n: Vec3, value: Rgb, xi: u32);

    /// Merges the current pass; later lookups see it.
    fn end_pass(&self);

    /// One line on the cache's state for reports.
    fn describe(&self) -> String {
        String::new()
    }
}

/// A shared cache handle an integrator holds.
#[derive(Clone)]
pub struct CacheRef(pub Arc<dyn RadianceCache>);

impl std::fmt::Debug for CacheRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("CacheRef")
    }
}

/// A camera-ray technique whose integrator reads and writes `cache`: renders each pass one
/// sample index at a time and ends a cache pass after each.
pub struct CachedPasses {
    inner: Box<dyn Technique>,
    cache: Arc<dyn RadianceCache>,
}

impl CachedPasses {
    /// Wraps `inner` (whose integrator holds `cache`).
    pub fn new(inner: Box<dyn Technique>, cache: Arc<dyn RadianceCache>) -> Self {
        Self { inner, cache }
    }
}

impl Technique for CachedPasses {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn render_pass(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        seed: u32,
        pass: &SamplePass,
        progress: &(dyn Fn(u32) + Sync),
    ) -> RenderStats {
        let mut total = RenderStats::default();
        let n = pass.indices.len().max(1) as u64;
        let rows = u64::from(film.height());
        for (k, i) in pass.indices.clone().enumerate() {
            let sub = SamplePass {
                indices: i..i + 1,
                ..pass.clone()
            };
            let done = k as u64 * rows;
            let s = self.inner.render_pass(ctx, film, seed, &sub, &|r| {
                progress(((done + u64::from(r)) / n) as u32)
            });
            self.cache.end_pass();
            total += s;
        }
        total
    }

    fn camera_integrator(&self) -> Option<&dyn Integrator> {
        self.inner.camera_integrator()
    }

    fn motion_blur(&self) -> bool {
        self.inner.motion_blur()
    }

    fn delta_lights(&self) -> bool {
        self.inner.delta_lights()
    }

    fn stages(&self) -> Vec<TechniqueStage> {
        let mut s = self.inner.stages();
        s.push(TechniqueStage {
            name: "radiance cache",
            time: None,
            details: self.cache.describe(),
        });
        s
    }
}

/// A vertex's share of diffuse layers above which the path tracer reads and writes the cache
/// there: the cache has no direction, so only (nearly) diffuse vertices fit it.
pub(crate) const DIFFUSE_DOMINATED: f32 = 0.9;

/// Vertices of one path recorded into the cache (the first ones, if a path has more).
const TRAIL_VERTICES: usize = 16;

#[derive(Clone, Copy, Default)]
struct TrailVertex {
    p: Vec3,
    n: Vec3,
    beta: Rgb,
    l_before: Rgb,
    xi: u32,
}

/// The diffuse-dominated vertices a path passed, with its throughput and radiance so far at
/// each: at the path's end, the radiance found beyond a vertex over the throughput up to it
/// estimates the vertex's reflected radiance. A fixed array: no allocation per path.
pub(crate) struct CacheTrail {
    v: [TrailVertex; TRAIL_VERTICES],
    len: usize,
}

impl CacheTrail {
    pub(crate) fn new() -> Self {
        Self {
            v: [TrailVertex::default(); TRAIL_VERTICES],
            len: 0,
        }
    }

    /// Remembers a vertex at `p` (normal `n`) reached with throughput `beta` when the path's
    /// radiance was `l_before` (its own emission included); `u` are two of the vertex's random
    /// numbers, hashed into the cache's selection draw.
    #[inline]
    pub(crate) fn push(&mut self, p: Vec3, n: Vec3, beta: Rgb, l_before: Rgb, u: [f32; 2]) {
        if self.len < TRAIL_VERTICES {
            let xi = u[0].to_bits().wrapping_mul(0x9e37_79b1) ^ u[1].to_bits().rotate_left(16);
            self.v[self.len] = TrailVertex {
                p,
                n,
                beta,
                l_before,
                xi,
            };
            self.len += 1;
        }
    }

    /// Records every vertex's reflected radiance given the path's final radiance `l`.
    pub(crate) fn record(&self, cache: &dyn RadianceCache, l: Rgb) {
        for v in &self.v[..self.len] {
            let beyond = l - v.l_before;
            let lr = Rgb::from_array(std::array::from_fn(|k| {
                if v.beta[k] > 0.0 {
                    (beyond[k] / v.beta[k]).max(0.0)
                } else {
                    0.0
                }
            }));
            if lr.is_finite() {
                cache.record(v.p, v.n, lr, v.xi);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CameraRays, PathIntegrator};
    use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

    /// A cache that answers every lookup with `value` and counts what it is asked.
    struct Fixed {
        value: Option<Rgb>,
        records: AtomicU64,
        passes: AtomicU64,
    }

    impl RadianceCache for Fixed {
        fn lookup(&self, _: Vec3, _: Vec3) -> Option<Rgb> {
            self.value
        }
        fn record(&self, _: Vec3, _: Vec3, value: Rgb, _: u32) {
            assert!(value.is_finite() && value.min_element() >= 0.0, "{value}");
            self.records.fetch_add(1, Relaxed);
        }
        fn end_pass(&self) {
            self.passes.fetch_add(1, Relaxed);
        }
    }

    fn fixed(value: Option<Rgb>) -> Arc<Fixed> {
        Arc::new(Fixed {
            value,
            records: AtomicU64::new(0),
            passes: AtomicU64::new(0),
        })
    }

    fn image(t: &dyn Technique, spp: u32) -> Vec<[u32; 3]> {
        let scene = rt_scene::procedural::generate("worst-case").unwrap();
        let mut camera = scene.cameras[0].clone();
        (camera.width, camera.height) = (24, 16);
        let accel = rt_accel::AccelSpec::default()
            .build(&scene.triangles)
            .expect("the default structure builds");
        let ctx = Ctx {
            scene: &scene,
            accel: accel.as_ref(),
            camera: &camera,
        };
        let mut film = Film::new(24, 16, rt_film::FilmBuffers::default());
        let pass = SamplePass {
            indices: 0..spp,
            stream: rt_core::SampleStream::Render,
            pixels: None,
            centre_first: false,
        };
        t.render_pass(&ctx, &mut film, 3, &pass, &|_| {});
        film.mean_image()
            .iter()
            .map(|c| c.to_array().map(f32::to_bits))
            .collect()
    }

    fn cached(path: PathIntegrator, cache: Arc<Fixed>) -> CachedPasses {
        let c: Arc<dyn RadianceCache> = cache;
        CachedPasses::new(
            Box::new(CameraRays(Box::new(path.with_cache(c.clone())))),
            c,
        )
    }

    /// What a path records at each vertex: the radiance found beyond it over the throughput
    /// up to it (zero where the throughput is).
    #[test]
    fn trail_records_radiance_beyond_each_vertex_over_its_throughput() {
        struct Log(std::sync::Mutex<Vec<(Vec3, Rgb)>>);
        impl RadianceCache for Log {
            fn lookup(&self, _: Vec3, _: Vec3) -> Option<Rgb> {
                None
            }
            fn record(&self, p: Vec3, _: Vec3, value: Rgb, _: u32) {
                self.0.lock().unwrap().push((p, value));
            }
            fn end_pass(&self) {}
        }
        let log = Log(Default::default());
        let mut trail = CacheTrail::new();
        trail.push(Vec3::X, Vec3::Z, Rgb::ONE, Rgb::splat(0.5), [0.1, 0.2]);
        trail.push(
            Vec3::Y,
            Vec3::Z,
            Rgb::new(0.5, 0.25, 0.0),
            Rgb::splat(1.0),
            [0.3, 0.4],
        );
        trail.record(&log, Rgb::splat(2.0));
        let got = log.0.into_inner().unwrap();
        assert_eq!(
            got,
            vec![
                (Vec3::X, Rgb::splat(1.5)),
                (Vec3::Y, Rgb::new(2.0, 4.0, 0.0)),
            ]
        );
    }

    /// A cache with nothing in it changes nothing: the same bits as plain path tracing,
    /// while every pass is ended and paths record their vertices.
    #[test]
    fn an_empty_cache_leaves_the_path_tracer_unchanged() {
        let plain = CameraRays(Box::new(PathIntegrator::new(5)));
        let cache = fixed(None);
        let with = cached(PathIntegrator::new(5), cache.clone());
        assert_eq!(image(&plain, 3), image(&with, 3));
        assert_eq!(cache.passes.load(Relaxed), 3);
        assert!(cache.records.load(Relaxed) > 24 * 16);
    }

    /// A cache holding zero everywhere ends every path at its first secondary (diffuse)
    /// vertex after that vertex's emission: exactly direct lighting (the scene is diffuse).
    #[test]
    fn a_zero_cache_turns_path_tracing_into_direct_lighting() {
        let direct = CameraRays(Box::new(PathIntegrator::direct()));
        let with = cached(PathIntegrator::new(5), fixed(Some(Rgb::ZERO)));
        let (a, b) = (image(&direct, 2), image(&with, 2));
        assert_eq!(a, b);
        // And a non-zero cache adds light.
        let lit = cached(PathIntegrator::new(5), fixed(Some(Rgb::splat(0.5))));
        let sum = |img: &[[u32; 3]]| -> f32 { img.iter().map(|p| f32::from_bits(p[0])).sum() };
        assert!(sum(&image(&lit, 2)) > sum(&a) * 1.01);
    }
}
