//! Deliberately wrong renderers, built from the outside (no test hook in shipped code), for the
//! control cases that show a statistical test can see the bias it guards against.

use rt_core::{glam::Vec3, Aabb, Accel, Hit, Ray, TraversalCounters};

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

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        self.inner.closest_hit(ray, t_max, counters)
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        rt_validate::stress::transform::ray_uniform(ray) < self.fraction
            || self.inner.any_hit(ray, t_max, toward, counters)
    }

    fn bounds(&self) -> Aabb {
        self.inner.bounds()
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }
}

/// An acceleration structure that reports its bounds shrunk about their centre by `scale` (and
/// answers every query like `inner`): light paths from the environment, started on a
/// rectangle covering the reported box, then miss part of the scene, the bias plane sampling
/// must not have.
pub struct ShrunkBounds<'a> {
    /// The real structure.
    pub inner: &'a dyn Accel,
    /// Factor applied to the box's extent.
    pub scale: f32,
}

impl Accel for ShrunkBounds<'_> {
    fn name(&self) -> &str {
        "shrunk-bounds"
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        self.inner.closest_hit(ray, t_max, counters)
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        self.inner.any_hit(ray, t_max, toward, counters)
    }

    fn bounds(&self) -> Aabb {
        let b = self.inner.bounds();
        let (c, h) = (b.center(), b.extent() * (0.5 * self.scale));
        Aabb::new(c - h, c + h)
    }

    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes()
    }
}
