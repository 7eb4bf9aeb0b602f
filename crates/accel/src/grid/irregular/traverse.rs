//! The walk through the virtual grid: look up the cell at the current point, test its
//! triangles, jump to the exit of its expanded box.

use super::IrregularGrid;
use crate::grid::walkable;
use crate::traversal::{Closest, Counter, SlabRay};
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Hit, Ray};

impl IrregularGrid {
    /// The one walk behind both queries; `ANY_HIT` returns the first hit in range. Hits are
    /// accepted as in the uniform grid's walk: once the current cell's exit lies at or beyond
    /// the closest so far.
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
        let (t0, _) = SlabRay::new(ray).interval(&d.planes(), t_max)?;
        let pre = RayPrecomp::new(ray);
        let (o, dir) = (ray.origin, ray.dir);
        let inv = dir.recip();
        let entry = ray.at(t0);
        let mut v = [0, 1, 2].map(|a| d.coord(a, entry[a]));
        let mut t = t0;
        let mut closest = Closest::new(t_max);
        loop {
            counter.boxes(1);
            let ci = self.map[d.index(v)] as usize;
            let r = &self.records[ci];
            let range = r.start as usize..r.end as usize;
            if !range.is_empty() {
                counter.leaf();
                for &id in &self.indices[range] {
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
            let b = &r.expanded;
            // Exit face of the expanded box: the nearest crossing among the axes the ray moves on.
            let (mut axis, mut t_exit) = (3, f32::INFINITY);
            for a in 0..3 {
                let face = if dir[a] > 0.0 {
                    b[a + 3]
                } else if dir[a] < 0.0 {
                    b[a]
                } else {
                    continue;
                };
                let ta = (d.plane(a, face as u32) - o[a]) * inv[a];
                if ta < t_exit {
                    (axis, t_exit) = (a, ta);
                }
            }
            if axis == 3 || closest.cull_t <= t_exit {
                break;
            }
            // Next virtual cell: exactly across the exit face on `axis`; on the other axes the
            // point at the exit, clamped into the box left and never behind the current cell
            // along the ray, so every step advances.
            let next = if dir[axis] > 0.0 {
                let hi = b[axis + 3] as u32;
                if hi >= d.res[axis] {
                    break;
                }
                hi
            } else {
                let lo = b[axis] as u32;
                if lo == 0 {
                    break;
                }
                lo - 1
            };
            t = t.max(t_exit);
            let p = ray.at(t);
            for a in 0..3 {
                if a == axis || dir[a] == 0.0 {
                    continue;
                }
                let c = d.coord(a, p[a]).clamp(b[a] as u32, b[a + 3] as u32 - 1);
                v[a] = if dir[a] > 0.0 {
                    c.max(v[a])
                } else {
                    c.min(v[a])
                };
            }
            v[axis] = next;
        }
        closest.hit
    }
}
