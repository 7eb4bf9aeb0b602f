//! 3D-DDA (Amanatides & Woo 1987) with early exit.

use super::UniformGrid;
use crate::grid::walkable;
use crate::traversal::{Closest, Counter, SlabRay};
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Hit, Ray};

impl UniformGrid {
    /// The one walk behind both queries; `ANY_HIT` returns the first hit in range.
    ///
    /// The result is the closest of the hits of all triangles listed in the cells visited, and
    /// the walk goes on until the current cell's exit lies at or beyond that hit (or `t_max`):
    /// a triangle spanning several cells may be hit beyond the cell it was tested in, and a
    /// closer one may still wait in the next cell.
    #[inline(always)]
    pub(crate) fn traverse<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        let d = self.domain.as_ref()?;
        if !walkable(ray) {
            return None;
        }
        counter.boxes(1);
        let slab = SlabRay::new(ray);
        let (t0, _) = slab.interval(&d.planes(), t_max)?;
        let pre = RayPrecomp::new(ray);
        let (o, dir) = (ray.origin, ray.dir);
        let inv = dir.recip();
        let entry = ray.at(t0);
        let mut cell = [0u32; 3];
        let mut t_next = [f32::INFINITY; 3];
        for a in 0..3 {
            // An axis-parallel direction (either zero) never crosses a face on that axis; the
            // entry coordinate is then the origin's exactly, as `0 * t0` is zero.
            let c = d.coord(a, entry[a]);
            cell[a] = c;
            if dir[a] > 0.0 {
                t_next[a] = (d.plane(a, c + 1) - o[a]) * inv[a];
            } else if dir[a] < 0.0 {
                t_next[a] = (d.plane(a, c) - o[a]) * inv[a];
            }
        }
        let mut closest = Closest::new(t_max);
        loop {
            counter.boxes(1);
            let range = self.lists.range(d.index(cell));
            if !range.is_empty() {
                counter.leaf();
                for &id in &self.lists.indices[range] {
                    counter.triangle();
                    let Some(h) = intersect_triangle(&pre, &self.triangles[id as usize], t_max)
                    else {
                        continue;
                    };
                    if closest.offer::<ANY_HIT>(h.t, id, h.b1, h.b2) {
                        return closest.hit;
                    }
                }
            }
            let axis = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            let t_exit = t_next[axis];
            // `cull_t` is the closest hit's distance, or `t_max` without one.
            if closest.cull_t <= t_exit || t_exit == f32::INFINITY {
                break;
            }
            let c = cell[axis];
            if dir[axis] > 0.0 {
                if c + 1 >= d.res[axis] {
                    break;
                }
                cell[axis] = c + 1;
                t_next[axis] = (d.plane(axis, c + 2) - o[axis]) * inv[axis];
            } else {
                if c == 0 {
                    break;
                }
                cell[axis] = c - 1;
                t_next[axis] = (d.plane(axis, c - 1) - o[axis]) * inv[axis];
            }
        }
        closest.hit
    }
}
