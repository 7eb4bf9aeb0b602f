//! Structural self-check of a built tree, for tests and debugging.

use super::build::MAX_DEPTH;
use super::{evh_split, Bvh2, Split};
use crate::traversal::inside;
use glam::Vec3;

/// Marks a slot no leaf has claimed yet.
const NO_LEAF: u32 = u32::MAX;

impl Bvh2 {
    /// Checks the invariants traversal relies on: every node is reachable exactly once, children
    /// lie after their parent and inside its bounds, leaves are non-empty and no larger than the
    /// build allowed, the leaves' slot ranges cover every slot exactly once, every slot holds the
    /// triangle its [`Bvh2::prim_ids`] entry names, every caller triangle is referenced
    /// (exactly once without splitting, at most once per leaf with leaf compaction), the box of
    /// every reference the build started from (the triangle's, or each piece's when splitting)
    /// lies in a leaf that references the triangle, and the depth fits the traversal stack.
    /// Returns the first violation found.
    pub fn validate(&self) -> Result<(), crate::ValidationError> {
        self.find_problem()
            .map_err(|problem| crate::ValidationError {
                structure: rt_core::Accel::name(self).to_string(),
                problem,
            })
    }

    fn find_problem(&self) -> Result<(), String> {
        let originals = self.check_ids()?;
        let n_slots = self.triangles.len();
        if self.nodes.is_empty() {
            return if n_slots == 0 {
                Ok(())
            } else {
                Err(format!("no nodes for {n_slots} triangle slots"))
            };
        }

        let mut reached = vec![false; self.nodes.len()];
        let mut leaf_of_slot = vec![NO_LEAF; n_slots];
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
                continue;
            }
            let prims = node.prims().unwrap_or_default();
            if prims.len() > self.config.max_leaf {
                return Err(format!(
                    "leaf {i} holds {} triangles, more than {}",
                    prims.len(),
                    self.config.max_leaf
                ));
            }
            if prims.end > n_slots {
                return Err(format!("leaf {i} range {prims:?} out of range"));
            }
            let ids = &self.prim_ids[prims.clone()];
            if self.config.compact_leaves {
                for (k, id) in ids.iter().enumerate() {
                    if ids[..k].contains(id) {
                        return Err(format!("compacted leaf {i} references {id} twice"));
                    }
                }
            }
            for p in prims {
                if leaf_of_slot[p] != NO_LEAF {
                    return Err(format!("triangle slot {p} is in two leaves"));
                }
                leaf_of_slot[p] = i as u32;
            }
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return Err(format!("node {i} is unreachable"));
        }
        if let Some(p) = leaf_of_slot.iter().position(|&l| l == NO_LEAF) {
            return Err(format!("triangle slot {p} is in no leaf"));
        }
        self.check_coverage(&originals, &leaf_of_slot)
    }

    /// Checks the prim ids against the slots and returns the caller's triangles by index.
    fn check_ids(&self) -> Result<Vec<[Vec3; 3]>, String> {
        let n_slots = self.triangles.len();
        if self.prim_ids.len() != n_slots {
            return Err(format!(
                "{} prim ids for {n_slots} triangle slots",
                self.prim_ids.len()
            ));
        }
        let mut originals: Vec<Option<[Vec3; 3]>> = vec![None; self.n_triangles];
        let bits = |t: &[Vec3; 3]| t.map(|v| v.to_array().map(f32::to_bits));
        for (slot, (&id, tri)) in self.prim_ids.iter().zip(&self.triangles).enumerate() {
            match originals.get_mut(id as usize) {
                Some(o @ None) => *o = Some(*tri),
                Some(Some(_)) if self.config.split == Split::None => {
                    return Err(format!("prim id {id} appears twice without splitting"));
                }
                Some(Some(first)) if bits(first) != bits(tri) => {
                    return Err(format!("slot {slot} holds another triangle than id {id}"));
                }
                Some(Some(_)) => {}
                None => return Err(format!("prim id {id} out of range")),
            }
        }
        originals
            .into_iter()
            .enumerate()
            .map(|(id, t)| t.ok_or_else(|| format!("triangle {id} is in no leaf")))
            .collect()
    }

    /// Every reference box the build partitioned must lie inside one of the leaves referencing
    /// its triangle: that is what makes a ray through any point of the triangle reach a leaf
    /// that tests it. The references are recomputed; splitting is deterministic.
    fn check_coverage(&self, originals: &[[Vec3; 3]], leaf_of_slot: &[u32]) -> Result<(), String> {
        // The leaves referencing each triangle, grouped by triangle: `leaves[start[i]..fill[i]]`.
        let mut start = vec![0usize; originals.len() + 1];
        for &id in &self.prim_ids {
            start[id as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        // Slots are visited in order and a leaf's slots are contiguous, so a leaf holding a
        // triangle several times is listed once.
        let mut fill = start.clone();
        let mut leaves = vec![0u32; self.prim_ids.len()];
        for (&id, &leaf) in self.prim_ids.iter().zip(leaf_of_slot) {
            let id = id as usize;
            if fill[id] == start[id] || leaves[fill[id] - 1] != leaf {
                leaves[fill[id]] = leaf;
                fill[id] += 1;
            }
        }
        // Time is the pieces of a triangle times its leaves, which is small at sensible
        // thresholds (a few references per triangle) and fine for tests at extreme ones.
        for r in evh_split::references(originals, self.config.split, false) {
            let id = r.index as usize;
            let covered = leaves[start[id]..fill[id]]
                .iter()
                .any(|&l| inside(&r.bounds, &self.nodes[l as usize].aabb()));
            if !covered {
                return Err(format!(
                    "reference box {:?} of triangle {id} lies in no leaf referencing it",
                    r.bounds
                ));
            }
        }
        Ok(())
    }
}
