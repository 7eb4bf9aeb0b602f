//! The left-balanced median build (Jensen 2001, appendix B; Dammertz §6.1.3).

use super::{check_items, PointError, PointItem};
use glam::Vec3;

/// The stored part of an item that every search reads: 16 bytes, four to a cache line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub(super) struct Node {
    pub(super) point: [f32; 3],
    pub(super) payload: u32,
}

/// A balanced point kd-tree in implicit heap order (module docs: layout, queries,
/// deviations).
///
/// ```
/// use rt_accel::points::{PointItem, PointKdTree, PointQuery};
/// use rt_core::glam::Vec3;
///
/// let photons: Vec<PointItem> = (0..100u32)
///     .map(|i| PointItem::new(Vec3::new(i as f32, 0.0, 0.0), i))
///     .collect();
/// let tree = PointKdTree::build(&photons).unwrap();
/// let mut query = PointQuery::new(3);
/// let near = tree.nearest_k(Vec3::new(41.4, 0.0, 0.0), 3, None, &mut query);
/// let ids: Vec<u32> = near.iter().map(|n| n.payload).collect();
/// assert_eq!(ids, [41, 42, 40]);
/// ```
#[derive(Clone, Debug, Default)]
pub struct PointKdTree {
    /// Heap item `h` at index `h - 1`.
    pub(super) nodes: Vec<Node>,
    /// Split axis (0, 1 or 2) of each node.
    pub(super) axes: Vec<u8>,
    /// Each item's radius and its subtree's largest, side by side because the covering
    /// search reads both.
    pub(super) radii: Vec<Radii>,
}

/// The radii of one node.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(super) struct Radii {
    /// The item's own.
    pub(super) own: f32,
    /// The largest in the node's subtree, its own included.
    pub(super) subtree: f32,
}

impl PointKdTree {
    /// Builds the tree over copies of `items`.
    ///
    /// # Errors
    ///
    /// The first item whose point is not finite or exceeds
    /// [`MAX_COORDINATE`](super::MAX_COORDINATE), or whose radius is NaN, infinite or negative.
    pub fn build(items: &[PointItem]) -> Result<Self, PointError> {
        let mut tree = Self::default();
        tree.rebuild(&mut items.to_vec())?;
        Ok(tree)
    }

    /// Replaces the contents with `items`, reusing this tree's memory (the caustic histogram
    /// rebuilds its bins every pass) and `items` as the work array: on success `items` is left
    /// permuted.
    ///
    /// # Errors
    ///
    /// As [`PointKdTree::build`]; the tree and `items` are then unchanged.
    pub fn rebuild(&mut self, items: &mut [PointItem]) -> Result<(), PointError> {
        check_items(items)?;
        let n = items.len();
        self.nodes.clear();
        self.nodes.resize(n, Node::default());
        self.axes.clear();
        self.axes.resize(n, 0);
        self.radii.clear();
        self.radii.resize(n, Radii::default());
        self.place(items, 1);
        // Children come after their parent in heap order, so one backward pass sees every
        // subtree's maximum before its parent needs it.
        for h in (1..=n).rev() {
            let mut r = self.radii[h - 1].own;
            for child in [2 * h, 2 * h + 1] {
                if child <= n {
                    r = r.max(self.radii[child - 1].subtree);
                }
            }
            self.radii[h - 1].subtree = r;
        }
        Ok(())
    }

    /// Stores `items` as the subtree rooted at heap number `h`. The recursion is as deep as the
    /// tree, at most [`MAX_DEPTH`](super::MAX_DEPTH).
    fn place(&mut self, items: &mut [PointItem], h: usize) {
        if items.is_empty() {
            return;
        }
        let axis = widest_axis(items);
        let m = left_subtree_size(items.len());
        items.select_nth_unstable_by(m, |a, b| a.point[axis].total_cmp(&b.point[axis]));
        let median = items[m];
        self.nodes[h - 1] = Node {
            point: median.point.to_array(),
            payload: median.payload,
        };
        self.axes[h - 1] = axis as u8;
        self.radii[h - 1].own = median.radius;
        let (left, rest) = items.split_at_mut(m);
        self.place(left, 2 * h);
        self.place(&mut rest[1..], 2 * h + 1);
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the tree holds no items.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The largest item radius (0 for an empty tree).
    pub fn max_radius(&self) -> f32 {
        self.radii.first().map_or(0.0, |r| r.subtree)
    }

    /// The item at heap number `heap_index` (root 1, children of `h` at `2h` and `2h + 1`) and
    /// its split axis (0 = x, 1 = y, 2 = z), or `None` outside `1..=len`. For tests and
    /// tools that inspect the layout.
    pub fn node(&self, heap_index: usize) -> Option<(PointItem, usize)> {
        let i = heap_index.checked_sub(1)?;
        let node = self.nodes.get(i)?;
        let item = PointItem::with_radius(Vec3::from(node.point), node.payload, self.radii[i].own);
        Some((item, self.axes[i] as usize))
    }

    /// Bytes held by the tree's arrays (their capacity, which [`PointKdTree::rebuild`] keeps).
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.axes.capacity()
            + self.radii.capacity() * std::mem::size_of::<Radii>()
    }
}

/// The axis of the largest extent of the items' bounding box, the lowest on a tie.
fn widest_axis(items: &[PointItem]) -> usize {
    let (lo, hi) = items.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), it| (lo.min(it.point), hi.max(it.point)),
    );
    let e = hi - lo;
    if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    }
}

/// How many of `n` items the left subtree of a complete (left-balanced) binary tree holds:
/// all levels but the last are full, and the last fills from the left.
pub(super) fn left_subtree_size(n: usize) -> usize {
    if n <= 1 {
        return 0;
    }
    // The last level is level `depth` (the root is level 0); the levels above hold
    // `2^depth - 1` items, the root and two full halves of `2^(depth-1) - 1` each.
    let depth = n.ilog2();
    let above = (1usize << depth) - 1;
    let last = n - above;
    let half_of_last = 1usize << (depth - 1);
    (above - 1) / 2 + last.min(half_of_last)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The complete tree's left subtree size, counted from its heap numbers.
    fn left_size_by_counting(n: usize) -> usize {
        // Heap numbers in the left subtree of the root are those whose path starts at 2.
        (2..=n).filter(|&h| h >> (h.ilog2() - 1) == 2).count()
    }

    #[test]
    fn left_subtree_size_matches_the_complete_tree() {
        for n in 0..2000 {
            assert_eq!(left_subtree_size(n), left_size_by_counting(n), "n = {n}");
        }
        assert_eq!(left_subtree_size(usize::MAX), usize::MAX / 2);
    }

    #[test]
    fn widest_axis_prefers_the_lowest_on_ties() {
        let items =
            |ps: &[Vec3]| -> Vec<PointItem> { ps.iter().map(|&p| PointItem::new(p, 0)).collect() };
        assert_eq!(widest_axis(&items(&[Vec3::ZERO, Vec3::ONE])), 0);
        assert_eq!(
            widest_axis(&items(&[Vec3::ZERO, Vec3::new(1.0, 2.0, 2.0)])),
            1
        );
        assert_eq!(
            widest_axis(&items(&[Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)])),
            2
        );
        assert_eq!(widest_axis(&items(&[Vec3::ONE])), 0);
    }
}
