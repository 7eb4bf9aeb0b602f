//! Our structures, through `rt_accel::AccelSpec` and the `rt_core::Accel` trait only.

use crate::peer::{Peer, Work};
use rt_core::glam::Vec3;
use rt_core::{Accel, Ray, TraversalCounters};

/// One of our structures, named by its spec (`qbvh`, `bvh`, `qbvh:order=distance`, ...).
pub struct Ours {
    name: String,
    accel: Box<dyn Accel>,
}

/// Builds the structure that `spec` names.
pub fn build(spec: &str, tris: &[[Vec3; 3]]) -> anyhow::Result<Box<dyn Peer>> {
    let parsed: rt_accel::AccelSpec = spec
        .parse()
        .map_err(|e| anyhow::anyhow!("--accel {spec}: {e}"))?;
    Ok(Box::new(Ours {
        name: spec.to_string(),
        accel: parsed.build(tris),
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
