//! Construction: the two-level grid at virtual resolution, then merging, expansion and the flat
//! layout.

use super::{expand, merge, IrregularGrid, IrregularGridParams, Record, VBox};
use crate::grid::domain::{cleary, padded_bounds, Domain};
use crate::grid::lists::{bin, Lists};
use crate::grid::overlap::Binner;
use crate::grid::{check_count, check_positive, GridError};
use glam::Vec3;

/// Largest virtual resolution per axis: the seed's six 10-bit indices.
pub(crate) const MAX_VIRTUAL_AXIS: u32 = 1024;
/// Largest number of virtual cells (a 64 MiB map).
const MAX_VIRTUAL_CELLS: u64 = 1 << 24;

/// A cell during the build: its box of virtual cells and its sorted triangles.
#[derive(Clone, Debug)]
pub(crate) struct BuildCell {
    pub lo: [u32; 3],
    pub hi: [u32; 3],
    pub tris: Vec<u32>,
}

pub(super) fn build(
    triangles: &[[Vec3; 3]],
    params: &IrregularGridParams,
) -> Result<IrregularGrid, GridError> {
    check_count(triangles.len())?;
    check_positive("lambda_top", params.lambda_top)?;
    check_positive("lambda_sub", params.lambda_sub)?;
    if !(params.traversal_cost.is_finite() && params.traversal_cost >= 0.0) {
        return Err(GridError::BadParameter {
            name: "traversal_cost",
            value: params.traversal_cost as f64,
            expected: "finite and non-negative",
        });
    }
    check_positive("intersection_cost", params.intersection_cost)?;
    let empty = IrregularGrid {
        domain: None,
        map: Vec::new(),
        records: Vec::new(),
        boxes: Vec::new(),
        indices: Vec::new(),
        triangles: triangles.to_vec(),
    };
    let bounds = padded_bounds(triangles);
    if bounds.is_empty() {
        return Ok(empty);
    }
    let top_res = cleary(
        bounds.extent().as_dvec3(),
        triangles.len(),
        params.lambda_top as f64,
        MAX_VIRTUAL_AXIS,
    );
    let top = Domain::new(bounds, top_res);
    let diagonal = top.diagonal();
    let top_pairs = bin(
        triangles,
        0..triangles.len() as u32,
        &top,
        diagonal,
        params.binning,
    );
    let top_lists = Lists::from_pairs(top.cell_count(), &top_pairs)?;
    drop(top_pairs);

    // Depth per top cell: 2^d cells per axis with 2^d the power of two nearest (in log scale)
    // to cbrt(lambda_sub * n), so that a top cell gets about lambda_sub * n cells; rounding up
    // instead gave up to eight times as many on the bunny.
    let max_depth = params.max_depth.min(10);
    let mut depths: Vec<u32> = (0..top.cell_count())
        .map(|c| {
            let n = top_lists.get(c).len();
            if n == 0 {
                return 0;
            }
            let s = (params.lambda_sub as f64 * n as f64).cbrt();
            (s.log2().round().max(0.0) as u32).min(max_depth)
        })
        .collect();
    let mut depth = depths.iter().copied().max().unwrap_or(0);
    let fits = |d: u32| {
        let r = top_res.map(|r| (r as u64) << d);
        r.iter().all(|&x| x <= MAX_VIRTUAL_AXIS as u64)
            && r.iter().product::<u64>() <= MAX_VIRTUAL_CELLS
    };
    while depth > 0 && !fits(depth) {
        depth -= 1;
    }
    for d in &mut depths {
        *d = (*d).min(depth);
    }
    let vd = Domain::new(bounds, top_res.map(|r| r << depth));

    // The second level: each top cell's triangles binned into its 2^d sub-cells, against the
    // virtual grid's faces so that builder and traversal agree on every face.
    let margin = vd.margin();
    let mut cells = Vec::new();
    let mut map = vec![0u32; vd.cell_count()];
    for tz in 0..top_res[2] {
        for ty in 0..top_res[1] {
            for tx in 0..top_res[0] {
                let t = [tx, ty, tz];
                let ti = top.index(t);
                let d = depths[ti];
                let (sub, span) = (1u32 << d, 1u32 << (depth - d));
                let base = t.map(|x| x << depth);
                let first = cells.len();
                for sz in 0..sub {
                    for sy in 0..sub {
                        for sx in 0..sub {
                            let lo = [0, 1, 2].map(|a| base[a] + [sx, sy, sz][a] * span);
                            cells.push(BuildCell {
                                lo,
                                hi: lo.map(|x| x + span),
                                tris: Vec::new(),
                            });
                        }
                    }
                }
                for &id in top_lists.get(ti) {
                    let tri = &triangles[id as usize];
                    let b = Binner::new(tri, diagonal, params.binning);
                    let (vlo, vhi) = vd.cell_range(b.lo, b.hi, margin);
                    let s_lo = [0, 1, 2].map(|a| (vlo[a].max(base[a]) - base[a]) / span);
                    let s_hi =
                        [0, 1, 2].map(|a| ((vhi[a].max(base[a]) - base[a]) / span).min(sub - 1));
                    for sz in s_lo[2]..=s_hi[2] {
                        for sy in s_lo[1]..=s_hi[1] {
                            for sx in s_lo[0]..=s_hi[0] {
                                let k = first + ((sz * sub + sy) * sub + sx) as usize;
                                let c = &mut cells[k];
                                let (clo, chi) = vd.cell_box(c.lo, c.hi);
                                if b.overlaps(clo, chi, margin) {
                                    c.tris.push(id);
                                }
                            }
                        }
                    }
                }
                for (k, c) in cells.iter().enumerate().skip(first) {
                    fill(&mut map, &vd, c.lo, c.hi, k as u32);
                }
            }
        }
    }
    drop(top_lists);
    if cells.len() > u32::MAX as usize {
        return Err(GridError::TooManyReferences);
    }

    if params.merge {
        merge::merge(&mut cells, &mut map, &vd, params);
    }
    let expanded = expand::expand(&cells, &map, &vd, params.expansion_passes);

    let pack = |lo: [u32; 3], hi: [u32; 3]| -> VBox {
        [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(|x| x as u16)
    };
    let boxes = cells.iter().map(|c| pack(c.lo, c.hi)).collect();
    let mut indices = Vec::new();
    let mut records = Vec::with_capacity(cells.len());
    for (c, &(lo, hi)) in cells.iter().zip(&expanded) {
        let start = indices.len();
        indices.extend_from_slice(&c.tris);
        if indices.len() > u32::MAX as usize {
            return Err(GridError::TooManyReferences);
        }
        records.push(Record {
            expanded: pack(lo, hi),
            start: start as u32,
            end: indices.len() as u32,
        });
    }
    Ok(IrregularGrid {
        domain: Some(vd),
        map,
        records,
        boxes,
        indices,
        ..empty
    })
}

/// Points the virtual cells `lo..hi` at cell `c`.
pub(crate) fn fill(map: &mut [u32], vd: &Domain, lo: [u32; 3], hi: [u32; 3], c: u32) {
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            let row = vd.index([lo[0], y, z]);
            map[row..row + (hi[0] - lo[0]) as usize].fill(c);
        }
    }
}
