//! Per-cell triangle lists in one flat array: cell `i` owns `indices[offsets[i]..offsets[i + 1]]`.

use super::domain::{finite, Domain};
use super::overlap::Binner;
use super::{Binning, GridError};
use glam::Vec3;

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct Lists {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
}

impl Lists {
    /// From `(cell, triangle)` pairs in increasing triangle order, by a counting sort, so each
    /// list is sorted by triangle.
    pub fn from_pairs(cells: usize, pairs: &[(u32, u32)]) -> Result<Self, GridError> {
        if pairs.len() > u32::MAX as usize {
            return Err(GridError::TooManyReferences);
        }
        let mut offsets = vec![0u32; cells + 1];
        for &(c, _) in pairs {
            offsets[c as usize + 1] += 1;
        }
        for i in 0..cells {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut indices = vec![0u32; pairs.len()];
        for &(c, t) in pairs {
            let slot = &mut fill[c as usize];
            indices[*slot as usize] = t;
            *slot += 1;
        }
        Ok(Self { offsets, indices })
    }

    #[inline(always)]
    pub fn range(&self, cell: usize) -> std::ops::Range<usize> {
        self.offsets[cell] as usize..self.offsets[cell + 1] as usize
    }

    pub fn get(&self, cell: usize) -> &[u32] {
        &self.indices[self.range(cell)]
    }

    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.offsets.as_slice())
            + std::mem::size_of_val(self.indices.as_slice())
    }
}

/// `(cell, triangle)` pairs of the triangles `ids` (increasing) binned into the cells of
/// `domain`, with the margins of the module documentation. `diagonal` is the whole grid's.
pub(crate) fn bin(
    triangles: &[[Vec3; 3]],
    ids: impl Iterator<Item = u32>,
    domain: &Domain,
    diagonal: f64,
    binning: Binning,
) -> Vec<(u32, u32)> {
    let margin = domain.margin();
    let mut pairs = Vec::new();
    for id in ids {
        let tri = &triangles[id as usize];
        if !finite(tri) {
            continue;
        }
        let b = Binner::new(tri, diagonal, binning);
        let (lo, hi) = domain.cell_range(b.lo, b.hi, margin);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let (clo, chi) = domain.cell_box([x, y, z], [x + 1, y + 1, z + 1]);
                    if b.overlaps(clo, chi, margin) {
                        pairs.push((domain.index([x, y, z]) as u32, id));
                    }
                }
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counting_sort_keeps_triangle_order() {
        let l = Lists::from_pairs(3, &[(2, 0), (0, 1), (2, 1), (2, 5)]).unwrap();
        assert_eq!(l.get(0), &[1]);
        assert_eq!(l.get(1), &[] as &[u32]);
        assert_eq!(l.get(2), &[0, 1, 5]);
    }
}
