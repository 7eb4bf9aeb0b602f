//! A balanced point kd-tree for photon-map-style queries: the photons of a photon map, and the
//! bins of the caustic histogram in the path-space-partitioned renderer.
//!
//! # What it is for
//!
//! Photon mapping (Jensen 1996; Dammertz's thesis, seed 004, §6.1.3) stores millions of points
//! and asks for the `k` nearest to a shading point, whose distance sets the density estimate's
//! radius. The caustic histogram (§6.3.3) stores the eye vertices of one pass as *bins*, each
//! with its own radius (half the pixel footprint), "the same way as the photons in a photon
//! map", and adds every caustic photon to the closest bin whose radius covers it. Both use
//! this one tree:
//!
//! - [`PointKdTree::nearest_k`] and [`PointKdTree::nearest_k_bounded_first`]: the `k` nearest
//!   items, optionally within a maximum radius;
//! - [`PointKdTree::for_each_within`] and [`PointKdTree::within`]: every item within a radius;
//! - [`PointKdTree::nearest_covering`]: the closest item whose own radius covers the query (the
//!   caustic histogram's bin lookup).
//!
//! # Sources
//!
//! - J. L. Bentley, "Multidimensional binary search trees used for associative searching",
//!   CACM 18(9), 1975: the point kd-tree.
//! - H. W. Jensen, *Realistic Image Synthesis Using Photon Mapping*, A K Peters 2001, ch. 6 and
//!   appendix B: the balanced tree in heap order, median split on the widest axis, the
//!   max-heap k-NN search pruned by its largest distance.
//! - H. Dammertz, PhD thesis, Ulm 2011, §6.1.3 ("Algorithmic Details": heap layout, root 1,
//!   children `2i` and `2i + 1`; start with a bounded radius and restart unbounded only when
//!   fewer than `n` photons were found) and §6.3.3 (bins in the same tree, the closest covering
//!   bin per photon).
//!
//! # Layout
//!
//! Item number `h` of the heap order (root `h = 1`, children `2h` and `2h + 1`, no pointers) is
//! stored at index `h - 1` of three parallel arrays: the point and payload (16 bytes, all the
//! k-NN and radius searches read besides the axis), the split axis (1 byte), and the item's
//! radius beside the largest radius in its subtree (8 bytes, read only by the covering
//! search), 25 bytes per item in all. A
//! node's split value is its own point's coordinate on its axis: its left subtree lies at or
//! below it, its right subtree at or above it.
//!
//! The build splits the current items' bounding box on its widest axis (the lowest axis on a
//! tie) at the position that keeps the heap *complete* (left-balanced, Jensen appendix B):
//! the left subtree gets exactly the items a complete binary tree of that size puts there, so
//! the heap is the array `1..=n` without holes for every `n`, not only `2^k - 1`. The item
//! there is found by `select_nth_unstable_by` (linear time), so the build is `O(n log n)`.
//!
//! # Queries
//!
//! All searches are depth first with a stack of at most [`MAX_DEPTH`] entries on the program
//! stack: near child first, then the node's own item, then the far child if the distance to
//! its cell can still beat the bound. The lower bound carried down is the largest squared plane
//! distance met on the way (a cell's distance to the query is at least each of them), which
//! prunes near children too once the bound shrinks. Every distance is
//! [`distance_squared`] in `f32`; that rounding is monotonic, so a point beyond a split plane
//! never computes a smaller squared distance than the plane's, and pruning never drops an
//! item the brute-force definition ([`BruteForcePoints`]) would return. Results are ordered by
//! squared distance and then payload ([`Neighbour`]'s `Ord`), so they do not depend on the
//! tree's shape. No query allocates: the k-NN max-heap lives in a reusable [`PointQuery`].
//!
//! # Deviations
//!
//! - Items keep their own radius and each node the largest radius of its subtree, which the
//!   thesis does not describe: the covering search prunes a subtree as soon as the query is
//!   farther from its cell than that radius, instead of searching up to the largest radius of
//!   all bins ([`CoverBound::Global`], kept for comparison; `examples/points_bench.rs`
//!   measures both).
//! - Jensen's search recurses and checks a node's own photon after both children; ours is
//!   iterative and checks it between them, so the bound shrinks before the far child is tried.
//! - The lower bound is the largest plane distance on the path, not the exact
//!   distance to the cell (Arya and Mount's incremental distance), which would prune more but
//!   needs three more floats per stack entry.
//! - Ties in distance are broken by payload, so which of several equally distant items are
//!   among the `k` nearest is defined (Jensen leaves it to the traversal order).
//! - Wald et al.'s deliberately unbalanced trees (VVH, §6.1.3's [Wald 04b]) are not built.
//! - Points must be finite and within [`MAX_COORDINATE`], so that no squared distance between
//!   two of them overflows; radii must be finite and non-negative.

mod brute;
mod build;
mod search;
mod validate;

pub use brute::BruteForcePoints;
pub use build::PointKdTree;
pub use search::{CoverBound, PointQuery, QueryStats};

use glam::Vec3;
use std::cmp::Ordering;

/// Largest magnitude of a point coordinate: the squared distance between two points within it
/// (at most `3 (2 · 10^18)^2 ≈ 1.2 · 10^37`) stays below `f32::MAX`.
pub const MAX_COORDINATE: f32 = 1e18;

/// Depth of the deepest tree any `usize` item count can make (a complete tree of `n` items is
/// `floor(log2 n) + 1` deep); the search stacks have this many entries.
pub const MAX_DEPTH: usize = usize::BITS as usize;

/// One item to store: a point, the caller's index for it and, for the covering search, its
/// radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointItem {
    /// Where it is.
    pub point: Vec3,
    /// The caller's index (photon number, bin number, ...), reported as [`Neighbour::payload`]
    /// and used to break ties in distance.
    pub payload: u32,
    /// How far it reaches, for [`PointKdTree::nearest_covering`] (finite and at least 0);
    /// the other queries ignore it.
    pub radius: f32,
}

impl PointItem {
    /// An item without a radius (a photon).
    pub fn new(point: Vec3, payload: u32) -> Self {
        Self::with_radius(point, payload, 0.0)
    }

    /// An item that covers the ball of `radius` around `point` (a bin).
    pub fn with_radius(point: Vec3, payload: u32, radius: f32) -> Self {
        Self {
            point,
            payload,
            radius,
        }
    }
}

/// One result: an item's payload and its squared distance to the query.
///
/// Ordered by squared distance, then payload: the order every query reports in. (Items with
/// equal distance and payload are indistinguishable in a result.)
#[derive(Clone, Copy, Debug)]
pub struct Neighbour {
    /// [`distance_squared`] from the query point.
    pub dist2: f32,
    /// The item's [`PointItem::payload`].
    pub payload: u32,
}

impl Neighbour {
    /// The order as one integer: squared distances are never NaN (queries reject non-finite
    /// points) and never -0 (a sum of squares), and the bits of non-negative floats sort like
    /// the floats, so one `u64` comparison replaces two on the searches' hot path.
    #[inline(always)]
    pub(crate) fn key(&self) -> u64 {
        (u64::from(self.dist2.to_bits()) << 32) | u64::from(self.payload)
    }
}

impl Ord for Neighbour {
    #[inline(always)]
    fn cmp(&self, other: &Self) -> Ordering {
        self.key().cmp(&other.key())
    }
}

impl PartialOrd for Neighbour {
    #[inline(always)]
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Neighbour {
    #[inline(always)]
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Neighbour {}

/// The one distance every query and [`BruteForcePoints`] uses: `|a - b|^2` in `f32`,
/// `(dx·dx + dy·dy) + dz·dz`.
#[inline(always)]
pub fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    (a - b).length_squared()
}

/// Why a set of items cannot be stored.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PointError {
    /// A coordinate is NaN or infinite.
    #[error("item {index}: point {point} is not finite")]
    NonFinitePoint {
        /// Position of the item in the input.
        index: usize,
        /// Its point.
        point: Vec3,
    },
    /// A coordinate exceeds [`MAX_COORDINATE`] in magnitude.
    #[error("item {index}: point {point} lies beyond ±{MAX_COORDINATE:e}, where squared distances overflow")]
    OutOfRange {
        /// Position of the item in the input.
        index: usize,
        /// Its point.
        point: Vec3,
    },
    /// A radius is NaN, infinite or negative.
    #[error("item {index}: radius {radius} is not a finite non-negative number")]
    BadRadius {
        /// Position of the item in the input.
        index: usize,
        /// Its radius.
        radius: f32,
    },
}

/// Checks every item, returning the first bad one.
pub(crate) fn check_items(items: &[PointItem]) -> Result<(), PointError> {
    for (index, item) in items.iter().enumerate() {
        let point = item.point;
        if !point.is_finite() {
            return Err(PointError::NonFinitePoint { index, point });
        }
        if point.abs().max_element() > MAX_COORDINATE {
            return Err(PointError::OutOfRange { index, point });
        }
        if !(item.radius.is_finite() && item.radius >= 0.0) {
            return Err(PointError::BadRadius {
                index,
                radius: item.radius,
            });
        }
    }
    Ok(())
}

/// The squared search bound of an optional query radius (infinite for none), or `Err` for a
/// NaN or negative radius, which matches nothing.
pub(crate) fn radius_bound(radius: Option<f32>) -> Result<f32, ()> {
    match radius {
        None => Ok(f32::INFINITY),
        Some(r) if r >= 0.0 => Ok(r * r),
        Some(_) => Err(()),
    }
}
