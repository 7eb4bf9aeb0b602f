//! On-demand (lazy) QBVH construction (Dammertz §3.4). Work in progress: builds eagerly for now.

use crate::qbvh::QbvhOptions;
use crate::{BuildParams, Qbvh};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray};

/// A QBVH whose subtrees are built the first time a ray reaches them.
pub struct OnDemandQbvh {
    inner: Qbvh,
}

impl OnDemandQbvh {
    /// Prepares the structure over `triangles`.
    pub fn new(triangles: &[[Vec3; 3]], params: &BuildParams, options: &QbvhOptions) -> Self {
        Self {
            inner: Qbvh::build_with(triangles, params, options),
        }
    }
}

impl Accel for OnDemandQbvh {
    fn name(&self) -> &str {
        "qbvh-lazy"
    }
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.inner.intersect(ray, t_max)
    }
    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.inner.occluded(ray, t_max)
    }
    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }
    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }
}
