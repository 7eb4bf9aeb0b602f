//! The one interface every compared structure is driven through.

use rt_core::Ray;

/// Work done by one query, for the structures that can tell (`None`: cannot count that).
#[derive(Clone, Copy, Debug, Default)]
pub struct Work {
    /// Bounding boxes tested.
    pub boxes: Option<u64>,
    /// Leaves entered.
    pub leaves: Option<u64>,
    /// Ray–triangle tests.
    pub tris: Option<u64>,
}

/// A built acceleration structure over the mesh's triangles (indices in file order).
pub trait Peer: Send + Sync {
    /// Name in reports (`qbvh`, `obvhs-cwbvh`, ...).
    fn name(&self) -> &str;

    /// Bytes held by the structure including any triangle copies it keeps, if known.
    fn bytes(&self) -> Option<usize>;

    /// Closest hit with `t ∈ (0, t_max]`: its `t` and triangle index.
    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(f32, u32)>;

    /// True if anything is hit with `t ∈ (0, t_max)`.
    fn occluded(&self, ray: &Ray, t_max: f32) -> bool;

    /// True if the benchmark should hand this structure whole chunks of rays
    /// ([`Peer::closest_stream`], [`Peer::occluded_stream`]) instead of one ray per call.
    fn is_stream(&self) -> bool {
        false
    }

    /// [`Peer::closest`] of every ray of `rays` into `out`; one by one unless overridden.
    fn closest_stream(&self, rays: &[Ray], t_max: f32, out: &mut [Option<(f32, u32)>]) {
        for (r, o) in rays.iter().zip(out) {
            *o = self.closest(r, t_max);
        }
    }

    /// [`Peer::occluded`] of every ray of `rays` into `out`; one by one unless overridden.
    fn occluded_stream(&self, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        for (r, o) in rays.iter().zip(out) {
            *o = self.occluded(r, t_max);
        }
    }

    /// The query again (closest hit, or occlusion if `shadow`), counting its work. Not timed.
    fn work(&self, ray: &Ray, t_max: f32, shadow: bool) -> Work {
        let _ = (ray, t_max, shadow);
        Work::default()
    }
}

/// Builds the structure named `name` (see `--help`), or says which names exist.
pub fn build(name: &str, tris: &[[rt_core::glam::Vec3; 3]]) -> anyhow::Result<Box<dyn Peer>> {
    if let Some(rest) = name.strip_prefix("obvhs-") {
        crate::obvhs_peer::build(name, rest, tris)
    } else if name.starts_with("embree") {
        crate::embree_peer::build(name, tris)
    } else if name == "bvh-crate" || name == "bvh-crate-flat" {
        crate::bvh_peer::build(name, tris)
    } else {
        crate::ours::build(name, tris)
    }
}
