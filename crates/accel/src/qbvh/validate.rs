//! Structural self-check of a collapsed tree.

use super::node::{QChild, EMPTY, NO_PARENT};
use super::traverse::MAX_DEPTH;
use super::Qbvh;
use crate::traversal::inside;
use rt_core::Aabb;

impl Qbvh {
    /// Checks the invariants traversal relies on: every node is reachable exactly once, inner
    /// children lie after their parent and record it as their parent, every slot box contains
    /// the boxes below it (or, for a leaf, its triangles), empty slots have inverted boxes,
    /// leaves are non-empty and cover every triangle slot exactly once, [`Qbvh::prim_ids`] is a
    /// permutation, the root's children lie inside [`Accel::bounds`](rt_core::Accel::bounds),
    /// and the depth fits the traversal stack. Returns the first violation found.
    pub fn validate(&self) -> Result<(), String> {
        let n_tris = self.triangles.len();
        if self.prim_ids.len() != n_tris {
            return Err(format!(
                "{} prim ids for {n_tris} triangles",
                self.prim_ids.len()
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
        if self.nodes[0].parent != NO_PARENT {
            return Err("root has a parent".into());
        }

        let mut reached = vec![false; self.nodes.len()];
        let mut covered = vec![false; n_tris];
        // (node, depth, box it must lie in)
        let mut stack = vec![(0usize, 0usize, self.bounds)];
        while let Some((i, depth, outer)) = stack.pop() {
            if std::mem::replace(&mut reached[i], true) {
                return Err(format!("node {i} reached twice"));
            }
            if depth >= MAX_DEPTH {
                return Err(format!("node {i} at depth {depth} overflows the stack"));
            }
            let node = &self.nodes[i];
            if node.reserved != [0; 2] {
                return Err(format!("node {i} has nonzero reserved words"));
            }
            if node.occupied() == 0 {
                return Err(format!("node {i} has no children"));
            }
            for slot in 0..4 {
                let b = node.child_aabb(slot);
                if node.children[slot] == EMPTY {
                    let inverted = b.min.cmpeq(glam::Vec3::INFINITY).all()
                        && b.max.cmpeq(glam::Vec3::NEG_INFINITY).all();
                    if !inverted {
                        return Err(format!("empty slot {slot} of node {i} has a box"));
                    }
                    continue;
                }
                if !inside(&b, &outer) {
                    return Err(format!("slot {slot} of node {i} sticks out of its parent"));
                }
                match node.child(slot) {
                    QChild::Empty => unreachable!(),
                    QChild::Inner(c) => {
                        if c <= i || c >= self.nodes.len() {
                            return Err(format!("node {i} has child {c} out of order or range"));
                        }
                        if self.nodes[c].parent != i as u32 {
                            return Err(format!("node {c} does not name {i} as parent"));
                        }
                        stack.push((c, depth + 1, b));
                    }
                    QChild::Leaf(prims) => {
                        if prims.end > n_tris {
                            return Err(format!("leaf {prims:?} of node {i} out of range"));
                        }
                        for p in prims {
                            if std::mem::replace(&mut covered[p], true) {
                                return Err(format!("triangle slot {p} is in two leaves"));
                            }
                            if !inside(&Aabb::from_points(&self.triangles[p]), &b) {
                                return Err(format!("triangle slot {p} sticks out of its leaf"));
                            }
                        }
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
