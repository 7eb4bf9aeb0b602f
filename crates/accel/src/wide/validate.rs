//! Structural self-check of a collapsed tree.

use super::bvh::WideNode;
use super::qbvh_node::{QChild, EMPTY, NO_PARENT};
use super::traverse::MAX_DEPTH;
use super::WideBvh;
use crate::traversal::inside;
use rt_core::Aabb;

impl<N: WideNode> WideBvh<N> {
    /// Checks the invariants traversal relies on: every node is reachable exactly once, inner
    /// children lie after their parent and record it as their parent, every slot box contains
    /// the boxes below it (or, for a leaf, its triangles), empty slots have inverted boxes,
    /// every node's split-plane orders are permutations of its slots, leaves are non-empty and
    /// (unless the build split triangles, when they need only overlap it) lie inside their box,
    /// cover every packet exactly once, lanes a leaf does not fill repeat its last triangle,
    /// the leaves hold [`WideBvh::reference_count`] references, the root's children lie inside
    /// [`Accel::bounds`](rt_core::Accel::bounds), and the depth fits the traversal stack.
    /// Returns the first violation found.
    pub fn validate(&self) -> Result<(), crate::ValidationError> {
        self.find_problem()
            .map_err(|problem| crate::ValidationError {
                structure: rt_core::Accel::name(self).to_string(),
                problem,
            })
    }

    fn find_problem(&self) -> Result<(), String> {
        let n_packets = self.packets.len();
        if self.packet_ids.len() != n_packets {
            return Err(format!(
                "{} id rows for {n_packets} packets",
                self.packet_ids.len()
            ));
        }
        if self.nodes.is_empty() {
            return if n_packets == 0 && self.references == 0 {
                Ok(())
            } else {
                Err(format!("no nodes for {n_packets} packets"))
            };
        }
        if self.nodes[0].parent_code() != NO_PARENT {
            return Err("root has a parent".into());
        }

        let mut reached = vec![false; self.nodes.len()];
        let mut covered = vec![false; n_packets];
        let mut references = 0;
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
            for octant in 0..8 {
                let mut seen = 0u32;
                for rank in 0..N::WIDTH {
                    seen |= 1 << node.slot_at(octant, rank);
                }
                if seen != (1 << N::WIDTH) - 1 {
                    return Err(format!(
                        "node {i}: order of octant {octant} is no permutation"
                    ));
                }
            }
            if node.occupied() == 0 {
                return Err(format!("node {i} has no children"));
            }
            for slot in 0..N::WIDTH {
                let b = node.child_aabb(slot);
                if node.code(slot) == EMPTY {
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
                        if self.nodes[c].parent_code() != i as u32 {
                            return Err(format!("node {c} does not name {i} as parent"));
                        }
                        stack.push((c, depth + 1, b));
                    }
                    QChild::Leaf(slots) => {
                        let packets = slots.start / 4..slots.end.div_ceil(4);
                        if packets.end > n_packets {
                            return Err(format!("leaf {slots:?} of node {i} out of range"));
                        }
                        for p in packets {
                            if std::mem::replace(&mut covered[p], true) {
                                return Err(format!("packet {p} is in two leaves"));
                            }
                        }
                        references += slots.len();
                        for s in slots.clone() {
                            let tri = Aabb::from_points(&self.reference(s).0);
                            // A split reference's box bounds a piece of its triangle only.
                            let ok = if self.split {
                                tri.min.cmple(b.max).all() && tri.max.cmpge(b.min).all()
                            } else {
                                inside(&tri, &b)
                            };
                            if !ok {
                                return Err(format!("triangle slot {s} sticks out of its leaf"));
                            }
                        }
                        let last = self.reference(slots.end - 1);
                        for pad in slots.end..slots.end.next_multiple_of(4) {
                            if self.reference(pad) != last {
                                return Err(format!("padding lane {pad} differs"));
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
            return Err(format!("packet {p} is in no leaf"));
        }
        if references != self.references {
            return Err(format!(
                "{references} references in leaves, {} expected",
                self.references
            ));
        }
        Ok(())
    }
}
