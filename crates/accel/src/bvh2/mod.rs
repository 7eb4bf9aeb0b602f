//! Binary BVH: binned-SAH build, ordered robust traversal.
//!
//! The tree is stored depth-first in one array of 32-byte [`Node`]s with the two children of
//! every inner node side by side. The triangles are copied in leaf order, so a leaf's triangles
//! are contiguous in memory, and [`Bvh2::prim_ids`] maps each copy back to the caller's index,
//! which is what [`Hit::prim`](rt_core::Hit::prim) reports.
//!
//! With [`BuildParams::split`] the builder partitions pieces of triangles rather than triangles
//! (see [`split_references`]), so a triangle can fill several leaf slots; each slot still holds
//! the whole triangle and its caller's index.

pub(crate) mod build;
mod compact;
mod evh_split;
mod node;
mod stats;
mod traverse;
mod validate;

pub use build::MAX_BINS;
pub use evh_split::{split_pieces, split_references};
pub use node::Node;
pub use stats::BvhStats;

use build::Config;
use glam::Vec3;
use rt_core::{Aabb, Accel};

/// Knobs of [`Bvh2::build`]. Out-of-range values are clamped rather than rejected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildParams {
    /// Largest number of triangles in a leaf (at least 1). Smaller leaves are made when the SAH
    /// says splitting does not pay.
    pub max_leaf_size: usize,
    /// Number of SAH bins per axis, between 2 and [`MAX_BINS`].
    pub bins: usize,
    /// SAH cost of visiting an inner node, relative to `intersection_cost`.
    pub traversal_cost: f32,
    /// SAH cost of one ray–triangle test.
    pub intersection_cost: f32,
    /// Build large subtrees in parallel on the rayon pool. The tree is the same either way.
    pub parallel: bool,
    /// Triangle splitting before the build (Dammertz §4.3): extra references with tighter
    /// boxes, never new triangles; leaves still intersect the original triangles.
    pub split: Split,
    /// Remove duplicate references of one triangle within a leaf after the build (only
    /// matters with [`BuildParams::split`]).
    pub compact_leaves: bool,
}

/// Triangle splitting heuristics of Dammertz §4.3. Both split a triangle at the midpoint of an
/// edge, recursively, and hand the builder one reference (box, original index) per piece.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Split {
    /// One reference per triangle.
    #[default]
    None,
    /// Edge Volume Heuristic: split at the midpoint of the edge whose edge box has the largest
    /// volume while that volume exceeds `V_scene / 2^t` (t = 14 in the thesis). Shared edges
    /// split identically, so closed meshes stay closed.
    Evh {
        /// Threshold exponent.
        t: u32,
    },
    /// Bounding Box Area Heuristic: split while the piece's box area exceeds `A_scene / 2^t`.
    Bbah {
        /// Threshold exponent.
        t: u32,
    },
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            max_leaf_size: 4,
            bins: 32,
            traversal_cost: 1.0,
            intersection_cost: 1.0,
            parallel: true,
            split: Split::None,
            compact_leaves: false,
        }
    }
}

/// A binary bounding volume hierarchy over triangles.
#[derive(Clone, Debug)]
pub struct Bvh2 {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
    prim_ids: Vec<u32>,
    /// The caller's triangle count; with splitting there are more slots.
    n_triangles: usize,
    config: Config,
}

impl Bvh2 {
    /// Builds the hierarchy over `triangles`, whose indices become [`Hit::prim`](rt_core::Hit::prim). Any input is
    /// accepted: empty, degenerate, duplicated or huge triangles. Infinite coordinates build
    /// without panicking but are of course never hit sensibly.
    ///
    /// # Panics
    ///
    /// If there are 2^31 or more triangles, or references when splitting.
    pub fn build(triangles: &[[Vec3; 3]], params: &BuildParams) -> Self {
        let config = Config::from(params);
        let built = build::build(triangles, &config);
        let n_triangles = triangles.len();
        let triangles = built.order.iter().map(|&i| triangles[i as usize]).collect();
        Self {
            nodes: built.nodes,
            triangles,
            prim_ids: built.order,
            n_triangles,
            config,
        }
    }

    /// The nodes, root first; empty for an empty scene.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The triangles in leaf order, one per leaf slot: with splitting, a triangle appears once
    /// for every leaf that references it (or more often without leaf compaction).
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// True if the build split triangles ([`BuildParams::split`]), so leaf boxes may bound only
    /// a piece of their triangles.
    pub fn is_split(&self) -> bool {
        self.config.split != Split::None
    }

    /// The caller's index of each triangle in [`Bvh2::triangles`].
    pub fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }
}

impl Accel for Bvh2 {
    fn name(&self) -> &str {
        "bvh"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, Node::aabb)
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.prim_ids.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(self.memory_bytes() - std::mem::size_of_val(self.triangles.as_slice()))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
