//! Our structures, through `rt_accel::AccelSpec` and the `rt_core::Accel` trait only.

use crate::peer::{Peer, Work};
use rt_core::glam::Vec3;
use rt_core::{Accel, Ray, TraversalCounters};

/// One of our structures, named by its spec (`qbvh`, `bvh`, `qbvh:order=distance`, ...).
pub struct Ours {
    name: String,
    accel: Box<dyn Accel>,
    /// `SPEC@stream`: traced through `Accel::intersect_stream` / `occluded_stream`.
    stream: bool,
}

/// Builds the structure that `spec` names.
pub fn build(spec: &str, tris: &[[Vec3; 3]]) -> anyhow::Result<Box<dyn Peer>> {
    let (base, stream) = match spec.strip_suffix("@stream") {
        Some(base) => (base, true),
        None => (spec, false),
    };
    let parsed: rt_accel::AccelSpec = base
        .parse()
        .map_err(|e| anyhow::anyhow!("--accel {spec}: {e}"))?;
    Ok(Box::new(Ours {
        name: spec.to_string(),
        accel: parsed
            .build(tris)
            .map_err(|e| anyhow::anyhow!("--accel {spec}: {e}"))?,
        stream,
    }))
}

impl Peer for Ours {
    fn name(&self) -> &str {
        &self.name
    }

    fn bytes(&self) -> Option<usize> {
        Some(self.accel.memory_bytes())
    }

    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
        self.accel.intersect(ray, t_max).map(|h| (h.t, h.prim))
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel.occluded(ray, t_max)
    }

    fn is_stream(&self) -> bool {
        self.stream
    }

    fn closest_stream(&self, rays: &[Ray], t_max: f32, out: &mut [Option<(f32, u32)>]) {
        let t = vec![t_max; rays.len()];
        let mut hits = vec![None; rays.len()];
        self.accel.intersect_stream(rays, &t, &mut hits);
        for (o, h) in out.iter_mut().zip(&hits) {
            *o = h.map(|h| (h.t, h.prim));
        }
    }

    fn occluded_stream(&self, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        let t = vec![t_max; rays.len()];
        // No light point: the benchmark's shadow rays have no shadow-cache key.
        let toward = vec![Vec3::splat(f32::INFINITY); rays.len()];
        self.accel.occluded_stream(rays, &t, &toward, out);
    }

    fn work(&self, ray: &Ray, t_max: f32, shadow: bool) -> Work {
        // The Accel trait counts closest-hit queries only.
        if shadow || !self.accel.counts_traversal() {
            return Work::default();
        }
        let mut c = TraversalCounters::default();
        self.accel.closest_hit(ray, t_max, Some(&mut c));
        Work {
            boxes: Some(c.nodes_visited),
            leaves: Some(c.leaves_visited),
            tris: Some(c.prims_tested),
        }
    }
}
