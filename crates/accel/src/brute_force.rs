//! The reference structure: no structure at all.

use glam::Vec3;
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};

/// Tests every triangle against every ray. Too slow for rendering anything but tiny scenes, it
/// is the oracle that the real structures are checked against: its answer is, by definition, the
/// closest of all hits [`intersect_triangle`] reports, with ties going to the lowest index.
#[derive(Clone, Debug)]
pub struct BruteForce {
    triangles: Vec<[Vec3; 3]>,
    bounds: Aabb,
}

impl BruteForce {
    /// Copies `triangles`; their indices become [`Hit::prim`].
    ///
    /// # Panics
    ///
    /// If there are more than `u32::MAX` triangles.
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        assert!(triangles.len() <= u32::MAX as usize, "too many triangles");
        Self {
            triangles: triangles.to_vec(),
            bounds: triangles
                .iter()
                .fold(Aabb::EMPTY, |b, t| b.union(Aabb::from_points(t))),
        }
    }

    fn query(&self, ray: &Ray, t_max: f32, any_hit: bool, tested: &mut u64) -> Option<Hit> {
        let pre = RayPrecomp::new(ray);
        let mut closest: Option<Hit> = None;
        let mut closest_t = f32::INFINITY;
        for (i, tri) in self.triangles.iter().enumerate() {
            *tested += 1;
            // Tested against the caller's t_max and compared exactly, as Bvh2 does, so the two
            // agree bit for bit; a NaN or infinite distance never compares less.
            let Some(h) = intersect_triangle(&pre, tri, t_max) else {
                continue;
            };
            if h.t < closest_t {
                closest_t = h.t;
                closest = Some(Hit {
                    t: h.t,
                    prim: i as u32,
                    b1: h.b1,
                    b2: h.b2,
                });
                if any_hit {
                    break;
                }
            }
        }
        closest
    }
}

impl Accel for BruteForce {
    fn name(&self) -> &str {
        "brute-force"
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        match counters {
            Some(c) => self.query(ray, t_max, false, &mut c.prims_tested),
            None => self.query(ray, t_max, false, &mut 0),
        }
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        _toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        match counters {
            Some(c) => self.query(ray, t_max, true, &mut c.prims_tested),
            None => self.query(ray, t_max, true, &mut 0),
        }
        .is_some()
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(0)
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_of_two_and_ties_to_lowest_index() {
        let near = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let far = near.map(|v| v - Vec3::Z);
        let bf = BruteForce::new(&[far, near, near]);
        let ray = Ray::new(Vec3::new(0.2, 0.2, 3.0), -Vec3::Z);
        let h = bf.intersect(&ray, f32::INFINITY).unwrap();
        assert_eq!((h.prim, h.t), (1, 2.0));
        assert!(bf.occluded(&ray, 2.5));
        assert!(!bf.occluded(&ray, 1.5));
        let mut c = TraversalCounters::default();
        bf.closest_hit(&ray, f32::INFINITY, Some(&mut c));
        assert_eq!(c.prims_tested, 3);
    }

    #[test]
    fn empty_scene_hits_nothing() {
        let bf = BruteForce::new(&[]);
        assert!(bf.bounds().is_empty());
        assert!(bf
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY)
            .is_none());
    }
}
