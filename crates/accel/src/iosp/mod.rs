//! Implicit Object Space Partitioning (IOSP): bounding volume hierarchies whose planes are not
//! stored but rebuilt during traversal from triangles placed at known positions in the
//! triangle array.
//!
//! Implements chapters 6–7 of P. Bauszat's PhD thesis (TU Braunschweig), which is
//! M. Eisemann, P. Bauszat, S. Guthe and M. Magnor, "Geometry Presorting for Implicit Object
//! Space Partitioning", Computer Graphics Forum 31(4) (EGSR 2012),
//! doi:10.1111/j.1467-8659.2012.03140.x. Every bounding plane of a BVH touches a vertex, so a
//! node can be described by the two triangles that span it along one axis; those "bounding
//! triangles" sit in the node, are tested when it is entered, and leave the partitioning.
//!
//! Three structures, each an [`rt_core::Accel`]:
//!
//! - [`Iosp0`] (the thesis' IOSP-0): a complete, left-balanced binary tree stored as a heap
//!   *inside the triangle array*. Node `i` owns triangles `2i` and `2i + 1`, its children are
//!   nodes `2i + 1` and `2i + 2`, its bounding axis is `depth % 3`. Nothing else is stored:
//!   [`Iosp0::structure_bytes`] is 0.
//! - [`Iosp4`] (IOSP-4): one 4-byte word per node (children's axis, left-child index, or a
//!   leaf's extra-triangle count and offset), built with the surface area heuristic.
//! - [`Iosp2`] (the thesis' "2-Lvl IOSP"): the top levels of a binned-SAH [`crate::Bvh2`], each
//!   of whose leaves is its own IOSP-0 over a contiguous range of triangles.
//!
//! # The permutation contract
//!
//! A structure that stores nothing can keep no index map either, so each build returns, next
//! to the structure, the permutation it applied to the triangles: `perm[i]` is the caller's
//! index of the triangle now at position `i`. [`Hit::prim`](rt_core::Hit::prim) is a position
//! in the **permuted** order. The renderer is expected to reorder the scene's triangles and all
//! their per-triangle attributes (normals, UVs, materials) with `perm`, so that `Hit::prim`
//! indexes them directly: `permuted_attr[i] = attr[perm[i]]`. `perm` is a true permutation of
//! `0..n` (no triangle is duplicated, see the deviations). The structures keep their own copy
//! of the permuted triangles, available from `triangles()`, and `memory_bytes` counts it.
//!
//! ```
//! use rt_accel::Iosp0;
//! use rt_core::{glam::Vec3, Accel, Ray};
//!
//! let at = |z: f32| [Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(0.0, 1.0, z)];
//! let triangles = [at(3.0), at(1.0), at(2.0)];
//! let materials = ["far", "near", "middle"];
//! let (iosp, perm) = Iosp0::build(&triangles).unwrap();
//! assert_eq!(iosp.structure_bytes(), 0);
//! // The renderer reorders every per-triangle attribute with the permutation...
//! let materials: Vec<&str> = perm.iter().map(|&i| materials[i as usize]).collect();
//! // ...so that `Hit::prim` indexes it directly.
//! let hit = iosp.intersect(&Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::Z), f32::INFINITY);
//! assert_eq!(materials[hit.unwrap().prim as usize], "near");
//! ```
//!
//! # Deviations from the thesis
//!
//! - **Odd triangle counts.** The thesis duplicates the last triangle. Here the heap's last
//!   node holds one triangle instead (nodes = `ceil(n / 2)`), so the triangle array is exactly
//!   the caller's triangles and `perm` stays a permutation; the same lets every IOSP-0 leaf of
//!   [`Iosp2`] hold any count.
//! - **IOSP-4 leaf count.** The thesis keeps every leaf's extra-triangle count even and stores
//!   half of it in 3 bits (0–14). Here the 3 bits hold the count itself (0–7), so odd totals
//!   need no duplicate; with the thesis' setting of leaves of about 4 triangles the smaller
//!   maximum does not bind. A one-triangle scene is a single node with one bounding triangle.
//! - **Symmetric slabs.** A node's slab is the min and max over all six vertex coordinates of
//!   its two triangles, not "min plane from the first, max plane from the second": the thesis'
//!   builder scrambles the order within a pair, and even a careful one loses hits when the min
//!   triangle reaches past the max triangle (the digest's §1.7, erratum 1).
//! - **Slab distances ordered by the sign of `1 / dir`**, not by comparison, so a `-0.0`
//!   component with the origin on a plane does not cull (erratum 3). The far side is padded
//!   by `1 + 2 γ(3)` as in the crate's other traversals (Ize 2013).
//! - **Eq. 7.1 as printed is wrong** (about 41 % of subtree sizes, including the thesis' own
//!   12-triangle example); [`split::eq_7_1_corrected`] is used, and [`split::eq_7_1_printed`]
//!   is kept only so the tests can show the difference.
//! - **Builder.** A level-by-level CPU builder (the nodes of a level in parallel with rayon,
//!   each splitting its remaining triangles at the object median with `select_nth_unstable`)
//!   instead of the thesis' GPU builder of lexicographic sorts (Fig. 7.3). The partition key is
//!   the centroid rather than the min vertex: the bounding triangles are found by a scan, so
//!   the sort order need not put them first.
//! - **Traversal** is a short stack of (node, axis, interval) entries with ordered descent;
//!   the thesis leaves stack versus stackless open. The thesis' per-triangle AABB pre-test
//!   (which it found no faster) is not implemented.
//! - **Clipped start.** IOSP-0 clips the ray to the scene box (kept for `Accel::bounds`, not
//!   per node) and 2-Lvl IOSP to the top-level leaf's box before the heap's root, whose slab
//!   bounds one axis only; the thesis starts the root with the ray's whole interval.
//! - **Batched triangle tests** (CPU only, not in the thesis). An entered node's triangles
//!   are not tested at once but queued, and the queue is tested eight at a time, gathered
//!   from the triangle array with AVX2 where the CPU has it (one at a time otherwise), when
//!   it is full and before every pop from the stack; a popped node is therefore culled against
//!   every triangle entered before it, as in the thesis. A node whose two children are leaves
//!   queues their four triangles instead of testing their slabs, and a heap of at most eight
//!   triangles (small 2-Lvl leaves) is tested whole. Hits are those of the thesis' traversal
//!   bit for bit; only the counters move (fewer slab tests, more triangle tests). Batching a
//!   second level (grandchildren, 14 triangles) measured no faster on the bunny.
//! - **Prefetches** (CPU only). Entering a heap node asks for its children's four triangles,
//!   and the 2-Lvl top asks for a heap's root pair when it queues the heap: in a heap the
//!   children sit far from their parent, but their slots are known before the parent's slab
//!   is tested (about 1.2 times the uniform-ray speed on the bunny and the dragon).
//! - **Counters.** `nodes_visited` counts slab tests (one per node reached), `leaves_visited`
//!   counts nodes entered (their triangles are then tested), `prims_tested` triangle tests.
//! - **IOSP-4 root axis.** The node word gives its children's bounding axis; the root's is the
//!   scene's largest axis, kept in the structure (one byte, not per node).
//! - **2-Lvl top.** The top is the crate's binned-SAH [`crate::Bvh2`] (32 bins, leaves of at
//!   most 4 triangles) cut at `top_levels` (15 in the thesis) rather than a separate builder,
//!   and then collapsed into four-wide nodes (Dammertz et al.'s greedy collapse, 128 bytes a
//!   node, the four boxes tested at once with SSE) rather than traversed as a binary tree of
//!   32-byte nodes: on the bunny's uniform rays this made 2-Lvl IOSP about 1.45 times faster
//!   and its top 26 % smaller (759,040 against 1,030,496 bytes), since a 15-level binary top
//!   has about three times as many nodes as its four-wide collapse.
//! - **2-Lvl budget.** [`Iosp2::build`] cuts the binary tree not after 15 levels but where the
//!   four-wide top reaches [`DEFAULT_TOP_BYTES`] (10^6), opening the subtrees of largest
//!   surface area times triangle count first; [`Iosp2::build_with`] keeps the thesis' level
//!   cut. Same run, uniform rays, share of `bvh8`'s rays/s (`iosp_speed`): bunny 57 % to
//!   66 %, conference 58 % to 64 %, dragon 45 % to 59 %.

mod heap;
mod iosp0;
mod iosp2;
mod iosp4;
mod iosp4_build;
mod lanes;
mod permuted;
pub mod split;

pub use iosp0::Iosp0;
pub use iosp2::{Iosp2, DEFAULT_TOP_BYTES, DEFAULT_TOP_LEVELS};
pub use iosp4::Iosp4;
pub use permuted::Unpermuted;

use glam::Vec3;

/// Why a build refused its input.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum IospError {
    /// More triangles than the structure's indices can address.
    #[error("{structure}: {count} triangles, at most {limit} supported")]
    TooManyTriangles {
        /// The structure's name.
        structure: &'static str,
        /// Triangles given.
        count: usize,
        /// The largest count supported.
        limit: usize,
    },
}

/// Per-axis bounds of a triangle, as the builders see it. `f32::min`/`max` drop NaN
/// coordinates, as the traversal's slab does, so the builder and traversal agree on them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriBox {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
}

impl TriBox {
    pub(crate) fn of(t: &[Vec3; 3]) -> Self {
        let lo = t[0].min(t[1]).min(t[2]).to_array();
        let hi = t[0].max(t[1]).max(t[2]).to_array();
        Self { lo, hi }
    }

    /// Twice the centroid of the box on `axis`: the partition key.
    #[inline]
    pub(crate) fn key(&self, axis: usize) -> f32 {
        self.lo[axis] + self.hi[axis]
    }
}

/// The slab `[min, max]` on `axis` over all coordinates of the given triangles (one or two):
/// symmetric, so the order of a node's two triangles does not matter.
#[inline(always)]
pub(crate) fn slab_of(a: &[Vec3; 3], b: &[Vec3; 3], axis: usize) -> (f32, f32) {
    let lo = a[0][axis]
        .min(a[1][axis])
        .min(a[2][axis])
        .min(b[0][axis])
        .min(b[1][axis])
        .min(b[2][axis]);
    let hi = a[0][axis]
        .max(a[1][axis])
        .max(a[2][axis])
        .max(b[0][axis])
        .max(b[1][axis])
        .max(b[2][axis]);
    (lo, hi)
}

/// Bounds of all triangles, with `Aabb::union`'s NaN handling.
pub(crate) fn bounds_of(triangles: &[[Vec3; 3]]) -> rt_core::Aabb {
    triangles.iter().fold(rt_core::Aabb::EMPTY, |b, t| {
        b.union(rt_core::Aabb::from_points(t))
    })
}
