//! Collapsing a binary BVH into a wide one, and packing its leaves four triangles wide.

use super::bvh::{order_word, WideNode};
use super::node::{leaf_code, MAX_LEAF_TRIANGLES, NO_AXES, NO_AXIS, NO_PARENT};
use super::tri4::Tri4;
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

/// Most children of a node, and so most binary levels above one of its slots (a node of
/// eight slots made by expanding one chain).
const MAX_WIDTH: usize = 8;

/// The binary splits above one slot of a node: level `i` split along `axes[i]`, and the slot
/// lies on its high side when bit `i` of `high` is set.
#[derive(Clone, Copy, Default)]
struct Path {
    axes: [u32; MAX_WIDTH - 1],
    high: u8,
    len: u8,
}

impl Path {
    fn child(self, axis: u32, high: bool) -> Self {
        let mut p = self;
        p.axes[p.len as usize] = axis;
        p.high |= u8::from(high) << p.len;
        p.len += 1;
        p
    }

    /// Sort key for a direction in `octant`: at each level, 0 for the side the ray reaches
    /// first. Paths of one node form a binary tree, so they never are prefixes of each other and
    /// the keys of two slots first differ at the split that separates them.
    fn key(&self, octant: usize) -> u8 {
        (0..self.len as usize).fold(0, |k, i| {
            let negative = (octant >> self.axes[i]) & 1 == 1;
            let near_is_high = negative;
            let high = (self.high >> i) & 1 == 1;
            k | (u8::from(high != near_is_high) << (MAX_WIDTH - 2 - i))
        })
    }
}

/// The order words ([`WideNode::order`]) of a node of `width` slots whose first slots have
/// the given paths (the remaining slots are empty and come last).
fn orders(paths: &[Path], width: usize, bits: u32) -> [u32; 8] {
    std::array::from_fn(|octant| {
        let mut slots: [usize; MAX_WIDTH] = std::array::from_fn(|s| s);
        slots[..paths.len()].sort_by_key(|&s| paths[s].key(octant));
        order_word(&slots[..width], bits)
    })
}

/// The output of [`collapse`].
pub(crate) struct Collapsed<N> {
    pub nodes: Vec<N>,
    pub packets: Vec<Tri4>,
    pub packet_ids: Vec<[u32; 4]>,
}

struct Collapser<'a, N> {
    bin: &'a [Node],
    triangles: &'a [[Vec3; 3]],
    ids: &'a [u32],
    out: Collapsed<N>,
}

/// Collapses the binary `nodes` (root first) over the leaf-ordered `triangles` with caller
/// indices `ids`. Every binary leaf becomes one leaf code; a leaf of more than
/// [`MAX_LEAF_TRIANGLES`] triangles becomes a small subtree of leaf codes over consecutive runs.
/// Empty input gives no nodes.
pub(crate) fn collapse<N: WideNode>(
    nodes: &[Node],
    triangles: &[[Vec3; 3]],
    ids: &[u32],
) -> Collapsed<N> {
    let mut c = Collapser {
        bin: nodes,
        triangles,
        ids,
        out: Collapsed {
            nodes: Vec::with_capacity(nodes.len() / (N::WIDTH - 1) + 1),
            packets: Vec::with_capacity(triangles.len() / 3 + 1),
            packet_ids: Vec::with_capacity(triangles.len() / 3 + 1),
        },
    };
    if nodes.is_empty() {
        return c.out;
    }
    if nodes[0].is_leaf() {
        c.emit(&[Src::Bin(0)], NO_AXES, NO_PARENT, None);
    } else {
        c.collapse_inner(0, NO_PARENT);
    }
    c.out
}

/// Axis along which the centres of `a` and `b` are farthest apart, and whether `a`'s centre is
/// the higher one along it. The binary BVH does not store its split axes; this recovers them.
fn split_axis(a: &Aabb, b: &Aabb) -> (u32, bool) {
    let (ca, cb) = (a.center(), b.center());
    let d = (ca - cb).abs();
    let axis = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    (axis as u32, ca[axis] > cb[axis])
}

impl<N: WideNode> Collapser<'_, N> {
    /// Makes the node for the inner binary node `b`: starting from its two children, replaces
    /// the inner one of largest surface area by its two children, in place, until there are
    /// `N::WIDTH` or only leaves are left. Returns the new node's index.
    fn collapse_inner(&mut self, b: usize, parent: u32) -> u32 {
        let bx = |i: usize| self.bin[i].aabb();
        let [l, r] = self.bin[b].children().expect("inner node");
        let (axis, l_high) = split_axis(&bx(l), &bx(r));
        let mut list = [0; MAX_WIDTH];
        let mut paths = [Path::default(); MAX_WIDTH];
        (list[0], list[1]) = (l, r);
        paths[0] = Path::default().child(axis, l_high);
        paths[1] = Path::default().child(axis, !l_high);
        let mut len = 2;
        while len < N::WIDTH {
            let best = (0..len)
                .filter(|&k| !self.bin[list[k]].is_leaf())
                .max_by(|&x, &y| {
                    let sa = |k: usize| bx(list[k]).surface_area();
                    sa(x).total_cmp(&sa(y))
                });
            let Some(k) = best else { break };
            let [cl, cr] = self.bin[list[k]].children().expect("inner node");
            let (axis, cl_high) = split_axis(&bx(cl), &bx(cr));
            let path = paths[k];
            list.copy_within(k + 1..len, k + 2);
            paths.copy_within(k + 1..len, k + 2);
            list[k] = cl;
            list[k + 1] = cr;
            paths[k] = path.child(axis, cl_high);
            paths[k + 1] = path.child(axis, !cl_high);
            len += 1;
        }
        let mut axes = paths[0].axes[0] | (NO_AXIS << 2) | (NO_AXIS << 4);
        if let (Some([ll, lr]), Some([rl, rr])) = (self.bin[l].children(), self.bin[r].children()) {
            if len == 4 && list[..4] == [ll, lr, rl, rr] {
                axes = (axes & 3) | (paths[0].axes[1] << 2) | (paths[2].axes[1] << 4);
            }
        }
        let srcs: Vec<Src> = list[..len].iter().map(|&i| Src::Bin(i)).collect();
        let orders = orders(&paths[..len], N::WIDTH, N::ORDER_BITS);
        self.emit(&srcs, axes, parent, Some(orders))
    }

    /// Appends a node with one slot per entry of `srcs` (at most `N::WIDTH`), making the nodes
    /// below it depth first. Returns its index.
    fn emit(&mut self, srcs: &[Src], axes: u32, parent: u32, orders: Option<[u32; 8]>) -> u32 {
        debug_assert!(srcs.len() <= N::WIDTH);
        let index = self.out.nodes.len() as u32;
        let mut node = N::empty(parent);
        node.set_axes(axes);
        if let Some(o) = orders {
            node.set_orders(o);
        }
        self.out.nodes.push(node);
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
            self.out.nodes[index as usize].set(slot, bounds, code);
        }
        index
    }

    /// The child code for triangle slots `first..first + count`: a leaf code over newly packed
    /// packets, or a node over `N::WIDTH` runs if they do not fit in one.
    fn leaf(&mut self, first: usize, count: usize, parent: u32) -> u32 {
        if count <= MAX_LEAF_TRIANGLES {
            let packet = self.out.packets.len();
            for start in (first..first + count).step_by(4) {
                let end = (start + 4).min(first + count);
                self.out
                    .packets
                    .push(Tri4::pack(&self.triangles[start..end]));
                self.out.packet_ids.push(std::array::from_fn(|lane| {
                    self.ids[(start + lane).min(end - 1)]
                }));
            }
            return leaf_code(packet, count);
        }
        let step = count.div_ceil(N::WIDTH);
        let runs: Vec<Src> = (first..first + count)
            .step_by(step)
            .map(|s| Src::Run(s, step.min(first + count - s)))
            .collect();
        self.emit(&runs, NO_AXES, parent, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_follow_the_splits() {
        // Root split along x (slots 0, 1 low; 2, 3 high); the low pair split along y with slot 0
        // high, the high pair along z with slot 2 low.
        let root_lo = Path::default().child(0, false);
        let root_hi = Path::default().child(0, true);
        let paths = [
            root_lo.child(1, true),
            root_lo.child(1, false),
            root_hi.child(2, false),
            root_hi.child(2, true),
        ];
        let o = orders(&paths, 4, 2);
        let decode = |b: u32| [0, 2, 4, 6].map(|s| (b >> s) & 3);
        // All positive: low x first; within it low y (slot 1) first; then low z (slot 2).
        assert_eq!(decode(o[0]), [1, 0, 2, 3]);
        // Negative x: the high pair first.
        assert_eq!(decode(o[1]), [2, 3, 1, 0]);
        // Negative y and z.
        assert_eq!(decode(o[0b110]), [0, 1, 3, 2]);
        // Three slots: the unused slot 3 comes last.
        let o = orders(&paths[..2], 4, 2);
        assert_eq!(decode(o[0]), [1, 0, 2, 3]);
    }
}
