//! A job's world-space cache ([`crate::RenderJob::cache`], `render --cache
//! worldspace[:options]` / `grid[:options]`): the cache of `rt-worldcache` behind the
//! integrators' [`RadianceCache`] seam. One cache lives for the whole job, so it carries over
//! from pass to pass and from frame to frame of a sequence.

use crate::job::JobError;
use rt_core::{Rgb, Scene};
use rt_integrators::{IntegratorSpec, RadianceCache, Technique};
use rt_worldcache::{AnyPoints, CacheSpec, WorldCache};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, RwLock};

/// A [`WorldCache`] shared by the render's threads: lookups and records take the read lock
/// (records go to the cache's atomic pass accumulator), merges the write lock between passes.
pub struct SharedCache {
    cache: RwLock<WorldCache<AnyPoints>>,
    min_samples: f32,
    passes: AtomicU64,
    table_full: AtomicU64,
    spec: String,
}

/// Builds the cache `spec` for `scene`; the level-0 edge defaults to the largest extent of
/// the scene's triangles.
pub fn build(spec: &CacheSpec, scene: &Scene) -> Result<Arc<SharedCache>, JobError> {
    let mut bounds = rt_core::Aabb::EMPTY;
    for t in &scene.triangles {
        for &v in t {
            bounds = bounds.grown(v);
        }
    }
    let extent = (bounds.max - bounds.min).max_element();
    let extent = if extent.is_finite() && extent > 0.0 {
        extent
    } else {
        1.0
    };
    let cache = spec
        .build(extent)
        .map_err(|e| JobError::Refused(format!("--cache {spec}: {e}")))?;
    Ok(Arc::new(SharedCache {
        min_samples: spec.params.min_samples,
        cache: RwLock::new(cache),
        passes: AtomicU64::new(0),
        table_full: AtomicU64::new(0),
        spec: spec.to_string(),
    }))
}

/// The job's cache (`None` without one), refused with one line when `integrator` cannot use
/// one.
pub fn for_job(
    spec: Option<&CacheSpec>,
    integrator: &IntegratorSpec,
    scene: &Scene,
) -> Result<Option<Arc<dyn RadianceCache>>, JobError> {
    let Some(spec) = spec else {
        return Ok(None);
    };
    let c: Arc<dyn RadianceCache> = build(spec, scene)?;
    if integrator.build_cached(c.clone()).is_none() {
        return Err(JobError::Refused(format!(
            "--cache {spec}: the {integrator} technique cannot use a cache (path, path-bsdf or ao can)"
        )));
    }
    Ok(Some(c))
}

/// `integrator` built over `cache` when there is one (which [`for_job`] checked it takes).
pub fn technique(
    integrator: &IntegratorSpec,
    cache: Option<Arc<dyn RadianceCache>>,
) -> Result<Box<dyn Technique>, JobError> {
    match cache {
        Some(c) => integrator.build_cached(c).ok_or_else(|| {
            JobError::Refused(format!(
                "--cache: the {integrator} technique cannot use a cache"
            ))
        }),
        None => Ok(integrator.build()),
    }
}

impl RadianceCache for SharedCache {
    fn lookup(&self, p: glam::Vec3, n: glam::Vec3) -> Option<Rgb> {
        let c = self.cache.read().unwrap_or_else(|e| e.into_inner());
        c.lookup(p, n)
            .filter(|l| l.samples >= self.min_samples)
            .map(|l| l.value)
    }

    fn record(&self, p: glam::Vec3, n: glam::Vec3, value: Rgb, xi: u32) {
        let c = self.cache.read().unwrap_or_else(|e| e.into_inner());
        c.record(p, n, value, xi);
    }

    fn end_pass(&self) {
        let mut c = self.cache.write().unwrap_or_else(|e| e.into_inner());
        let s = c.end_pass();
        self.passes.fetch_add(1, Relaxed);
        self.table_full.fetch_add(s.table_full as u64, Relaxed);
    }

    fn describe(&self) -> String {
        let c = self.cache.read().unwrap_or_else(|e| e.into_inner());
        let t = c.table();
        format!(
            "{}: {} passes, {} of {} entries ({} B each, {:.1} MiB table), search distance {:.4}, {} keys lost to a full table",
            self.spec,
            self.passes.load(Relaxed),
            t.len(),
            t.capacity(),
            rt_worldcache::ENTRY_BYTES,
            t.bytes() as f64 / (1 << 20) as f64,
            c.search_distance(),
            self.table_full.load(Relaxed),
        )
    }
}
