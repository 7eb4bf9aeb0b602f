//! The top level of [`super::TwoLevel`]: a binary SAH BVH over the placements' world boxes,
//! rebuilt or refitted per frame.

use crate::bvh2::build::{build_over_boxes, MAX_DEPTH};
use crate::bvh2::Node;
use crate::traversal::{walk_binary, Step};
use crate::BuildParams;
use rt_core::{Aabb, Ray, TraversalCounters};

/// How the top level follows the placements from frame to frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TopLevel {
    /// A new binned-SAH build over the world boxes (the tree fits the new positions).
    #[default]
    Rebuild,
    /// The boxes recomputed bottom-up in the old tree (cheaper; the tree degrades as objects
    /// move apart).
    Refit,
}

impl TopLevel {
    /// The name in specs.
    pub fn name(self) -> &'static str {
        match self {
            TopLevel::Rebuild => "rebuild",
            TopLevel::Refit => "refit",
        }
    }
}

/// Nodes (root first) and the placement of every leaf slot.
#[derive(Default)]
pub(super) struct Top {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl Top {
    /// One placement per leaf: entering an object costs a transform and a second traversal,
    /// so a leaf of two overlapping objects would enter both for every ray reaching it.
    pub fn build(boxes: &[Aabb]) -> Self {
        let params = BuildParams {
            max_leaf_size: 1,
            parallel: false,
            ..BuildParams::default()
        };
        let built = build_over_boxes(boxes, &params);
        Self {
            nodes: built.nodes,
            order: built.order,
        }
    }

    /// Recomputes every node's box from `boxes` (indexed like the build's), keeping the tree.
    pub fn refit(&mut self, boxes: &[Aabb]) {
        // Children follow their parent in `nodes`, so a reverse sweep sees children first.
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            let b = match (n.prims(), n.children()) {
                (Some(slots), _) => slots
                    .map(|s| boxes[self.order[s] as usize])
                    .fold(Aabb::EMPTY, Aabb::union),
                (None, Some([a, c])) => self.nodes[a].aabb().union(self.nodes[c].aabb()),
                (None, None) => unreachable!("a node is a leaf or has children"),
            };
            self.nodes[i] = if n.is_leaf() {
                Node::leaf(b, n.index, n.count)
            } else {
                Node::inner(b, n.index)
            };
        }
    }

    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice()) + std::mem::size_of_val(self.order.as_slice())
    }

    /// Front-to-back walk: `leaf(placement, t_cull, counters)` returns the distance of a hit
    /// found in it; with `any` the first hit ends the walk.
    pub fn walk(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
        any: bool,
        mut leaf: impl FnMut(u32, f32, &mut TraversalCounters) -> Option<f32>,
    ) {
        let mut t_cull = t_max;
        walk_binary::<_, _, MAX_DEPTH>(&self.nodes, ray, t_max, counters, |node, _, c| {
            let mut found = None;
            for s in node.prims().expect("a leaf") {
                if let Some(t) = leaf(self.order[s], t_cull, c) {
                    t_cull = t_cull.min(t);
                    found = Some(t_cull);
                    if any {
                        return Step::Done;
                    }
                }
            }
            match found {
                Some(t) => Step::Closer(t),
                None => Step::Miss,
            }
        });
    }
}
