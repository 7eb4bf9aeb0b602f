//! Ordered, stack-based traversal with a robust slab test (Ize, "Robust BVH Ray Traversal",
//! JCGT 2013).

use super::build::MAX_DEPTH;
use super::Bvh2;
use crate::traversal::{Closest, Counter, SlabRay, FAR_SCALE};
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
        let nodes = &self.nodes[..];
        let root = nodes.first()?;
        let slab = SlabRay::new(ray);
        counter.boxes(1);
        slab.hit(&root.bounds, t_max)?;
        let pre = RayPrecomp::new(ray);

        let mut closest = Closest::new(t_max);
        // (node index, entry distance) of far children still to visit.
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH];
        let mut sp = 0;
        let mut node = root;
        loop {
            if let Some(prims) = node.prims() {
                let (tris, ids) = (&self.triangles[..], &self.prim_ids[..]);
                if closest.test_leaf::<ANY_HIT, C>(&pre, tris, ids, prims, t_max, counter) {
                    return closest.hit;
                }
            } else {
                let first = node.index as usize;
                counter.boxes(2);
                let t_left = slab.hit(&nodes[first].bounds, closest.cull_t);
                let t_right = slab.hit(&nodes[first + 1].bounds, closest.cull_t);
                let next = match (t_left, t_right) {
                    (Some(tl), Some(tr)) => {
                        let (near, far, far_entry) = if tl <= tr {
                            (first, first + 1, tr)
                        } else {
                            (first + 1, first, tl)
                        };
                        stack[sp] = (far as u32, far_entry);
                        sp += 1;
                        Some(near)
                    }
                    (Some(_), None) => Some(first),
                    (None, Some(_)) => Some(first + 1),
                    (None, None) => None,
                };
                if let Some(next) = next {
                    node = &nodes[next];
                    continue;
                }
            }
            // Pop the nearest pending subtree that can still hold something closer.
            loop {
                if sp == 0 {
                    return closest.hit;
                }
                sp -= 1;
                let (index, t_entry) = stack[sp];
                if t_entry <= closest.cull_t * FAR_SCALE {
                    node = &nodes[index as usize];
                    break;
                }
            }
        }
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
