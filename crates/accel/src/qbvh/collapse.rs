//! Collapsing a binary BVH into a four-wide one.

use super::node::{leaf_code, QNode, MAX_LEAF_TRIANGLES, NO_AXES, NO_AXIS, NO_PARENT};
use crate::bvh2::Node;
use glam::Vec3;
use rt_core::Aabb;

/// What fills one slot of a node being made.
#[derive(Clone, Copy)]
enum Src {
    /// A node of the binary tree.
    Bin(usize),
    /// A run of triangle slots too long for one leaf code, split further.
    Run(usize, usize),
}

struct Collapser<'a> {
    bin: &'a [Node],
    triangles: &'a [[Vec3; 3]],
    out: Vec<QNode>,
}

/// Collapses the binary `nodes` (root first) over the leaf-ordered `triangles`. Every binary
/// leaf becomes one leaf code; a leaf of more than [`MAX_LEAF_TRIANGLES`] triangles becomes a
/// small subtree of leaf codes over consecutive runs. Empty input gives no nodes.
pub(crate) fn collapse(nodes: &[Node], triangles: &[[Vec3; 3]]) -> Vec<QNode> {
    if nodes.is_empty() {
        return Vec::new();
    }
    let mut c = Collapser {
        bin: nodes,
        triangles,
        out: Vec::with_capacity(nodes.len() / 3 + 1),
    };
    if nodes[0].is_leaf() {
        c.emit(&[Src::Bin(0)], NO_AXES, NO_PARENT);
    } else {
        c.collapse_inner(0, NO_PARENT);
    }
    c.out
}

/// Axis along which the centres of `a` and `b` are farthest apart.
fn split_axis(a: &Aabb, b: &Aabb) -> u32 {
    let d = (a.center() - b.center()).abs();
    if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    }
}

impl Collapser<'_> {
    /// Makes the node for the inner binary node `b`: starting from its two children, replaces
    /// the inner one of largest surface area by its two children, in place, until there are four
    /// or only leaves are left. Returns the new node's index.
    fn collapse_inner(&mut self, b: usize, parent: u32) -> u32 {
        let [l, r] = self.bin[b].children().expect("inner node");
        let mut list = [l, r, 0, 0];
        let mut len = 2;
        while len < 4 {
            let best = (0..len)
                .filter(|&k| !self.bin[list[k]].is_leaf())
                .max_by(|&x, &y| {
                    let sa = |k: usize| self.bin[list[k]].aabb().surface_area();
                    sa(x).total_cmp(&sa(y))
                });
            let Some(k) = best else { break };
            let [cl, cr] = self.bin[list[k]].children().expect("inner node");
            list.copy_within(k + 1..len, k + 2);
            list[k] = cl;
            list[k + 1] = cr;
            len += 1;
        }
        let bx = |i: usize| self.bin[i].aabb();
        let mut axes = split_axis(&bx(l), &bx(r)) | (NO_AXIS << 2) | (NO_AXIS << 4);
        if let (Some([ll, lr]), Some([rl, rr])) = (self.bin[l].children(), self.bin[r].children()) {
            if list == [ll, lr, rl, rr] {
                axes = (axes & 3)
                    | (split_axis(&bx(ll), &bx(lr)) << 2)
                    | (split_axis(&bx(rl), &bx(rr)) << 4);
            }
        }
        let srcs: Vec<Src> = list[..len].iter().map(|&i| Src::Bin(i)).collect();
        self.emit(&srcs, axes, parent)
    }

    /// Appends a node with one slot per entry of `srcs` (at most four), making the nodes below
    /// it depth first. Returns its index.
    fn emit(&mut self, srcs: &[Src], axes: u32, parent: u32) -> u32 {
        debug_assert!(srcs.len() <= 4);
        let index = self.out.len() as u32;
        self.out.push(QNode::new(parent, axes));
        for (slot, &src) in srcs.iter().enumerate() {
            let (bounds, code) = match src {
                Src::Bin(b) => {
                    let node = self.bin[b];
                    let code = match node.prims() {
                        None => self.collapse_inner(b, index),
                        Some(p) => self.leaf(p.start, p.len(), index),
                    };
                    (node.aabb(), code)
                }
                Src::Run(first, count) => {
                    let bounds = self.triangles[first..first + count]
                        .iter()
                        .fold(Aabb::EMPTY, |b, t| b.union(Aabb::from_points(t)));
                    (bounds, self.leaf(first, count, index))
                }
            };
            self.out[index as usize].set(slot, bounds, code);
        }
        index
    }

    /// The child code for triangle slots `first..first + count`: a leaf code, or a node over
    /// four runs if they do not fit in one.
    fn leaf(&mut self, first: usize, count: usize, parent: u32) -> u32 {
        if count <= MAX_LEAF_TRIANGLES {
            return leaf_code(first, count);
        }
        let step = count.div_ceil(4);
        let runs: Vec<Src> = (first..first + count)
            .step_by(step)
            .map(|s| Src::Run(s, step.min(first + count - s)))
            .collect();
        self.emit(&runs, NO_AXES, parent)
    }
}
