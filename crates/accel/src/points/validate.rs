//! Structural self-check of a built tree.

use super::build::PointKdTree;
use super::MAX_DEPTH;

impl PointKdTree {
    /// Checks the invariants the searches rely on: the parallel arrays have one entry per
    /// item, axes are 0, 1 or 2, every item of a node's left subtree lies at or below the
    /// node's coordinate on its axis and every item of its right subtree at or above it, each
    /// node's subtree radius is the largest radius in its subtree, and the depth fits the
    /// search stack. Returns the first violation found. Takes `O(n log n)`.
    pub fn validate(&self) -> Result<(), crate::ValidationError> {
        self.find_problem()
            .map_err(|problem| crate::ValidationError {
                structure: "point kd-tree".into(),
                problem,
            })
    }

    fn find_problem(&self) -> Result<(), String> {
        let n = self.nodes.len();
        if self.axes.len() != n || self.radii.len() != n {
            return Err(format!(
                "{n} nodes but {} axes and {} radii",
                self.axes.len(),
                self.radii.len()
            ));
        }
        if n > 0 && n.ilog2() as usize >= MAX_DEPTH {
            return Err(format!("{n} items are deeper than the search stack"));
        }
        for h in 1..=n {
            let axis = self.axes[h - 1] as usize;
            if axis > 2 {
                return Err(format!("node {h} has axis {axis}"));
            }
            let split = self.nodes[h - 1].point[axis];
            let mut largest = self.radii[h - 1].own;
            for (child, left) in [(2 * h, true), (2 * h + 1, false)] {
                if child > n {
                    continue;
                }
                largest = largest.max(self.radii[child - 1].subtree);
                // Walk the child's subtree level by level: heap numbers c·2^d .. c·2^d + 2^d - 1.
                let (mut first, mut width) = (child, 1usize);
                while first <= n {
                    for d in first..(first + width).min(n + 1) {
                        let c = self.nodes[d - 1].point[axis];
                        let ok = if left { c <= split } else { c >= split };
                        if !ok {
                            let side = if left { "left" } else { "right" };
                            return Err(format!(
                                "node {d} in the {side} subtree of node {h} has coordinate {c} \
                                 on axis {axis}, split {split}"
                            ));
                        }
                    }
                    first *= 2;
                    width *= 2;
                }
            }
            if self.radii[h - 1].subtree != largest {
                return Err(format!(
                    "node {h} records subtree radius {} but its subtree's largest is {largest}",
                    self.radii[h - 1].subtree
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::PointItem;
    use super::*;
    use glam::Vec3;

    fn tree() -> PointKdTree {
        let items: Vec<PointItem> = (0..20u32)
            .map(|i| {
                let p = Vec3::new((i * 7 % 20) as f32, (i * 3 % 5) as f32, 0.0);
                PointItem::with_radius(p, i, i as f32 * 0.1)
            })
            .collect();
        PointKdTree::build(&items).unwrap()
    }

    #[test]
    fn a_built_tree_is_valid() {
        tree().validate().unwrap();
    }

    #[test]
    fn each_broken_invariant_is_found() {
        let mut t = tree();
        t.nodes.swap(1, 2); // the root's children: their subtrees now straddle the split
        assert!(t
            .validate()
            .unwrap_err()
            .problem
            .contains("subtree of node 1"));

        let mut t = tree();
        t.axes[3] = 3;
        assert!(t.validate().unwrap_err().problem.contains("axis 3"));

        let mut t = tree();
        t.radii[10].own = 5.0; // larger than the subtree maxima recorded above it
        assert!(t.validate().unwrap_err().problem.contains("subtree radius"));

        let mut t = tree();
        t.axes.pop();
        assert!(t.validate().is_err());
    }
}
