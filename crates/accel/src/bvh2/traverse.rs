//! Ordered, stack-based traversal with a robust slab test (Ize, "Robust BVH Ray Traversal",
//! JCGT 2013).

use super::build::MAX_DEPTH;
use super::{Bvh2, Node};
#[cfg(test)]
use crate::traversal::SlabRay;
use crate::traversal::{walk_binary, BinaryNode, Closest, Counter, Step};
use rt_core::triangle::RayPrecomp;
use rt_core::{Hit, Ray};

impl Bvh2 {
    /// The one traversal loop behind every query. `ANY_HIT` returns the first hit found rather
    /// than the closest.
    ///
    /// The result agrees with brute force as explained at [`Closest`].
    #[inline(always)]
    pub(crate) fn traverse<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        let pre = RayPrecomp::new(ray);
        let mut closest = Closest::new(t_max);
        let (tris, ids) = (&self.triangles[..], &self.prim_ids[..]);
        walk_binary::<_, _, MAX_DEPTH>(&self.nodes, ray, t_max, counter, |node, _, counter| {
            let prims = node.prims().expect("a leaf");
            if closest.test_leaf::<ANY_HIT, C>(&pre, tris, ids, prims, t_max, counter) {
                Step::Done
            } else {
                Step::Closer(closest.cull_t)
            }
        });
        closest.hit
    }
}

impl BinaryNode for Node {
    #[inline(always)]
    fn planes(&self) -> &[f32; 6] {
        &self.bounds
    }
    #[inline(always)]
    fn first_child(&self) -> Option<usize> {
        (!self.is_leaf()).then_some(self.index as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    const UNIT: [f32; 6] = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];

    fn hit(o: Vec3, d: Vec3, b: &[f32; 6]) -> Option<f32> {
        SlabRay::new(&Ray::new(o, d)).hit(b, f32::INFINITY)
    }

    #[test]
    fn axis_parallel_rays_in_a_face_plane_are_not_culled() {
        // Origins exactly on the planes x = 0 and x = 1 make (plane - origin) * inf a NaN.
        for x in [0.0, 1.0, -0.0] {
            for dx in [0.0, -0.0] {
                let o = Vec3::new(x, 0.5, -1.0);
                assert_eq!(
                    hit(o, Vec3::new(dx, 0.0, 1.0), &UNIT),
                    Some(1.0),
                    "x={x} dx={dx}"
                );
            }
        }
        // A flat box (all of its slab on one plane) is still hit by a ray within that plane.
        let flat = [0.0, 0.0, 0.5, 1.0, 1.0, 0.5];
        assert!(hit(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, &flat).is_some());
        assert!(hit(Vec3::new(-1.0, 0.5, 0.5), Vec3::new(1.0, -0.0, -0.0), &flat).is_some());
    }

    #[test]
    fn parallel_rays_outside_a_slab_miss() {
        assert_eq!(hit(Vec3::new(1.5, 0.5, -1.0), Vec3::Z, &UNIT), None);
        assert_eq!(
            hit(
                Vec3::new(-1e-30, 0.5, -1.0),
                Vec3::new(-0.0, 0.0, 1.0),
                &UNIT
            ),
            None
        );
    }

    #[test]
    fn boxes_behind_or_beyond_t_max_miss() {
        let s = SlabRay::new(&Ray::new(Vec3::new(0.5, 0.5, 2.0), Vec3::Z));
        assert_eq!(s.hit(&UNIT, f32::INFINITY), None);
        let s = SlabRay::new(&Ray::new(Vec3::new(0.5, 0.5, -2.0), Vec3::Z));
        assert_eq!(s.hit(&UNIT, 1.5), None);
        assert_eq!(s.hit(&UNIT, 2.0), Some(2.0));
        // Origin inside: the entry distance is clamped to zero.
        let s = SlabRay::new(&Ray::new(Vec3::splat(0.5), -Vec3::Z));
        assert_eq!(s.hit(&UNIT, f32::INFINITY), Some(0.0));
    }
}
