//! Cell expansion (Pérard-Gayot et al. 2017, §3.3): a cell's box grows over neighbours whose
//! triangles it already holds, so a ray leaving the cell skips them.

use super::build::BuildCell;
use super::is_subset;
use crate::grid::domain::Domain;

/// The expanded box `(lo, hi)` of every cell after `passes` rounds over x, y, z and both
/// directions. `map` still names each virtual cell's own cell.
pub(super) fn expand(
    cells: &[BuildCell],
    map: &[u32],
    vd: &Domain,
    passes: u32,
) -> Vec<([u32; 3], [u32; 3])> {
    let mut boxes: Vec<_> = cells.iter().map(|c| (c.lo, c.hi)).collect();
    // `seen[j] == token`: neighbour j already checked for the current face.
    let mut seen = vec![0u32; cells.len()];
    let mut token = 0u32;
    for _ in 0..passes {
        let mut grown = false;
        for axis in 0..3 {
            for positive in [true, false] {
                for i in 0..cells.len() {
                    let (lo, hi) = boxes[i];
                    let layer = if positive {
                        if hi[axis] >= vd.res[axis] {
                            continue;
                        }
                        hi[axis]
                    } else {
                        if lo[axis] == 0 {
                            continue;
                        }
                        lo[axis] - 1
                    };
                    token = token.wrapping_add(1);
                    if token == 0 {
                        seen.fill(0);
                        token = 1;
                    }
                    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
                    let mut far = if positive { u32::MAX } else { 0 };
                    let mut all_subsets = true;
                    'face: for y in lo[c]..hi[c] {
                        for x in lo[b]..hi[b] {
                            let mut v = [0; 3];
                            (v[axis], v[b], v[c]) = (layer, x, y);
                            let j = map[vd.index(v)] as usize;
                            if seen[j] == token {
                                continue;
                            }
                            seen[j] = token;
                            if !is_subset(&cells[j].tris, &cells[i].tris) {
                                all_subsets = false;
                                break 'face;
                            }
                            // The neighbours' own boxes: every virtual cell up to the nearest
                            // far face belongs to the neighbour whose face cell it lies behind.
                            far = if positive {
                                far.min(cells[j].hi[axis])
                            } else {
                                far.max(cells[j].lo[axis])
                            };
                        }
                    }
                    if all_subsets {
                        if positive {
                            boxes[i].1[axis] = far;
                        } else {
                            boxes[i].0[axis] = far;
                        }
                        grown = true;
                    }
                }
            }
        }
        if !grown {
            break;
        }
    }
    boxes
}
