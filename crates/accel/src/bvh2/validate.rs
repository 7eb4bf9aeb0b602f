//! Structural self-check of a built tree, for tests and debugging.

use super::build::MAX_DEPTH;
use super::Bvh2;
use crate::traversal::inside;
use rt_core::Aabb;

impl Bvh2 {
    /// Checks the invariants traversal relies on: every node is reachable exactly once, children
    /// lie after their parent and inside its bounds, leaves are non-empty, no larger than the
    /// build allowed and contain their triangles' bounds, the leaves' triangle ranges cover every
    /// triangle exactly once, [`Bvh2::prim_ids`] is a permutation, and the depth fits the
    /// traversal stack. Returns the first violation found.
    pub fn validate(&self) -> Result<(), String> {
        let n_tris = self.triangles.len();
        if self.prim_ids.len() != n_tris {
            return Err(format!(
                "{} prim ids for {} triangles",
                self.prim_ids.len(),
                n_tris
            ));
        }
        let mut seen_id = vec![false; n_tris];
        for &id in &self.prim_ids {
            match seen_id.get_mut(id as usize) {
                Some(seen @ false) => *seen = true,
                Some(true) => return Err(format!("prim id {id} appears twice")),
                None => return Err(format!("prim id {id} out of range")),
            }
        }
        if self.nodes.is_empty() {
            return if n_tris == 0 {
                Ok(())
            } else {
                Err(format!("no nodes for {n_tris} triangles"))
            };
        }

        let mut reached = vec![false; self.nodes.len()];
        let mut covered = vec![false; n_tris];
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            if std::mem::replace(&mut reached[i], true) {
                return Err(format!("node {i} reached twice"));
            }
            if depth >= MAX_DEPTH {
                return Err(format!(
                    "node {i} at depth {depth} overflows the traversal stack"
                ));
            }
            let node = &self.nodes[i];
            let bounds = node.aabb();
            if let Some(children) = node.children() {
                for c in children {
                    if c <= i || c >= self.nodes.len() {
                        return Err(format!(
                            "node {i} has child index {c} out of order or range"
                        ));
                    }
                    if !inside(&self.nodes[c].aabb(), &bounds) {
                        return Err(format!("child {c} sticks out of its parent {i}"));
                    }
                    stack.push((c, depth + 1));
                }
            } else {
                let prims = node.prims().unwrap_or_default();
                if prims.len() > self.config.max_leaf {
                    return Err(format!(
                        "leaf {i} holds {} triangles, more than {}",
                        prims.len(),
                        self.config.max_leaf
                    ));
                }
                if prims.end > n_tris {
                    return Err(format!("leaf {i} range {prims:?} out of range"));
                }
                for p in prims {
                    if std::mem::replace(&mut covered[p], true) {
                        return Err(format!("triangle slot {p} is in two leaves"));
                    }
                    if !inside(&Aabb::from_points(&self.triangles[p]), &bounds) {
                        return Err(format!("triangle slot {p} sticks out of leaf {i}"));
                    }
                }
            }
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return Err(format!("node {i} is unreachable"));
        }
        if let Some(p) = covered.iter().position(|c| !c) {
            return Err(format!("triangle slot {p} is in no leaf"));
        }
        Ok(())
    }
}
