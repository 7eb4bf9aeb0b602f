//! SAH merging of neighbouring cells (Pérard-Gayot et al. 2017, §3.2).

use super::build::{fill, BuildCell};
use super::IrregularGridParams;
use crate::grid::domain::Domain;
use glam::DVec3;

/// Merges neighbours whose union is a box and costs no more, by the SAH, than the two apart;
/// passes along x, y, z until a round merges nothing. Removes the merged-away cells and
/// renumbers `map`.
pub(super) fn merge(
    cells: &mut Vec<BuildCell>,
    map: &mut [u32],
    vd: &Domain,
    params: &IrregularGridParams,
) {
    let vcell = (vd.max - vd.min).as_dvec3()
        / DVec3::new(vd.res[0] as f64, vd.res[1] as f64, vd.res[2] as f64);
    let (ct, ci) = (
        params.traversal_cost as f64,
        params.intersection_cost as f64,
    );
    let area = |lo: [u32; 3], hi: [u32; 3]| {
        let e = DVec3::new(
            (hi[0] - lo[0]) as f64,
            (hi[1] - lo[1]) as f64,
            (hi[2] - lo[2]) as f64,
        ) * vcell;
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    };
    let cost = |lo, hi, n: usize| area(lo, hi) * (ct + ci * n as f64);
    let mut alive = vec![true; cells.len()];
    let mut touched = vec![false; cells.len()];
    let mut union = Vec::new();
    loop {
        let mut merged_any = false;
        for axis in 0..3 {
            touched.fill(false);
            for i in 0..cells.len() {
                if !alive[i] || touched[i] || cells[i].hi[axis] >= vd.res[axis] {
                    continue;
                }
                let mut probe = cells[i].lo;
                probe[axis] = cells[i].hi[axis];
                let j = map[vd.index(probe)] as usize;
                if touched[j] {
                    continue;
                }
                let (a, b) = (&cells[i], &cells[j]);
                // The neighbour holds the virtual cell just past `a`'s face at `a`'s low corner,
                // so the union is a box exactly when the cross-sections agree.
                let same_section =
                    (0..3).all(|k| k == axis || (a.lo[k] == b.lo[k] && a.hi[k] == b.hi[k]));
                if !same_section {
                    continue;
                }
                sorted_union(&a.tris, &b.tris, &mut union);
                let mut hi = a.hi;
                hi[axis] = b.hi[axis];
                let apart = cost(a.lo, a.hi, a.tris.len()) + cost(b.lo, b.hi, b.tris.len());
                if cost(a.lo, hi, union.len()) > apart {
                    continue;
                }
                let (blo, bhi) = (b.lo, b.hi);
                let a = &mut cells[i];
                a.hi = hi;
                std::mem::swap(&mut a.tris, &mut union);
                cells[j].tris = Vec::new();
                alive[j] = false;
                fill(map, vd, blo, bhi, i as u32);
                touched[i] = true;
                touched[j] = true;
                merged_any = true;
            }
        }
        if !merged_any {
            break;
        }
    }
    // Renumber the survivors in order.
    let mut new_index = vec![u32::MAX; cells.len()];
    let mut next = 0u32;
    for (i, &a) in alive.iter().enumerate() {
        if a {
            new_index[i] = next;
            next += 1;
        }
    }
    for m in map.iter_mut() {
        *m = new_index[*m as usize];
    }
    let mut i = 0;
    cells.retain(|_| {
        i += 1;
        alive[i - 1]
    });
}

/// `out` = the sorted union of the sorted `a` and `b`, without duplicates.
fn sorted_union(a: &[u32], b: &[u32], out: &mut Vec<u32>) {
    out.clear();
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (x, y) = (a[i], b[j]);
        out.push(x.min(y));
        i += usize::from(x <= y);
        j += usize::from(y <= x);
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_is_sorted_without_duplicates() {
        let mut out = Vec::new();
        sorted_union(&[1, 3, 5], &[2, 3, 6, 7], &mut out);
        assert_eq!(out, [1, 2, 3, 5, 6, 7]);
        sorted_union(&[], &[4], &mut out);
        assert_eq!(out, [4]);
    }
}
