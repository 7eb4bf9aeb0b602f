//! Deliberately wrong renderers, built from the outside (no test hook in shipped code), for the
//! control cases that show a statistical test can see the bias it guards against.

use rt_core::{Aabb, Accel, Hit, Ray};

/// An acceleration structure that reports a fixed fraction of the shadow rays occluded
/// (chosen by a hash of the ray, so renders stay deterministic) and answers every other query
/// like `inner`. Shadow rays carry next-event estimation only, so this scales the NEE
/// contribution by `1 − fraction` and leaves paths that find emitters by BSDF sampling alone.
pub struct DroppedShadowRays<'a> {
    /// The real structure.
    pub inner: &'a dyn Accel,
    /// Fraction of shadow rays reported occluded.
    pub fraction: f64,
}

impl Accel for DroppedShadowRays<'_> {
    fn name(&self) -> &str {
        "dropped-shadow-rays"
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.inner.intersect(ray, t_max)
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        rt_validate::stress::transform::ray_uniform(ray) < self.fraction
            || self.inner.occluded(ray, t_max)
    }

    // `occluded_toward` and its counted twin keep their defaults, which call `occluded` above.

    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }
}
