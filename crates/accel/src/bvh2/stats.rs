//! Size and quality figures of a built tree.

use super::{Bvh2, Node};
use rt_core::Accel;
use std::fmt;

/// Shape, quality and size of a [`Bvh2`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BvhStats {
    /// Number of triangles.
    pub triangles: usize,
    /// Number of leaf slots: the triangles, plus the extra references that splitting added and
    /// leaf compaction kept.
    pub references: usize,
    /// Inner nodes plus leaves.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Edges from the root to the deepest leaf (0 for a lone leaf or an empty tree).
    pub max_depth: usize,
    /// Most references in any leaf.
    pub largest_leaf: usize,
    /// Expected cost of a random ray that hits the root under the surface area heuristic, with
    /// the build's traversal and intersection costs: the sum over nodes of their cost weighted
    /// by their area relative to the root's. When the root has no area (all triangles on a line
    /// or a point) every node is weighted 1.
    pub sah_cost: f64,
    /// Bytes held, as [`Accel::memory_bytes`].
    pub memory_bytes: usize,
}

impl Bvh2 {
    /// Computes the statistics by walking the tree.
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats {
            triangles: self.n_triangles,
            references: self.triangles.len(),
            nodes: self.nodes.len(),
            memory_bytes: self.memory_bytes(),
            ..BvhStats::default()
        };
        let Some(root) = self.nodes.first() else {
            return s;
        };
        let area = |n: &Node| n.aabb().surface_area() as f64;
        let root_area = area(root);
        let weight = |n: &Node| {
            if root_area > 0.0 && root_area.is_finite() {
                area(n) / root_area
            } else {
                1.0
            }
        };
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            let n = &self.nodes[i];
            s.max_depth = s.max_depth.max(depth);
            match n.children() {
                Some([l, r]) => {
                    s.sah_cost += self.config.traversal_cost * weight(n);
                    stack.push((l, depth + 1));
                    stack.push((r, depth + 1));
                }
                None => {
                    s.leaves += 1;
                    s.largest_leaf = s.largest_leaf.max(n.count as usize);
                    s.sah_cost += self.config.intersection_cost * n.count as f64 * weight(n);
                }
            }
        }
        s
    }
}

impl fmt::Display for BvhStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} triangles ({} references), {} nodes ({} leaves, largest {}), depth {}, SAH {:.2}, \
             {:.1} KiB",
            self.triangles,
            self.references,
            self.nodes,
            self.leaves,
            self.largest_leaf,
            self.max_depth,
            self.sah_cost,
            self.memory_bytes as f64 / 1024.0
        )
    }
}
