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
            total.elapsed += s.elapsed;
            total.samples += s.samples;
            total.rays += s.rays;
            total.discarded += s.discarded;
        }
        total
    }

    fn camera_integrator(&self) -> Option<&dyn Integrator> {
        self.inner.camera_integrator()
    }

    fn motion_blur(&self) -> bool {
        self.inner.motion_blur()
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
