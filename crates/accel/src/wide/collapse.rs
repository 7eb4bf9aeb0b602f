//! Collapsing a binary BVH into a wide one, and packing its leaves four triangles wide: greedily
//! by surface area (Dammertz et al. 2008, the QBVH), or by the SAH-optimal plan of Ylitie et
//! al. 2017 (the BVH8, see [`Plan`]).

use super::bvh::{order_word, WideNode};
use super::qbvh_node::{leaf_code, MAX_LEAF_TRIANGLES, NO_AXES, NO_AXIS, NO_PARENT};
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
    sah: Option<CollapseCosts>,
) -> Collapsed<N> {
    let mut c = Collapser {
        bin: nodes,
        triangles,
        ids,
        out: Collapsed {
            nodes: huge_vec(nodes.len() / (N::WIDTH - 1) + 1),
            packets: huge_vec(triangles.len() / 3 + 1),
            packet_ids: huge_vec(triangles.len() / 3 + 1),
        },
    };
    if nodes.is_empty() {
        return c.out;
    }
    if nodes[0].is_leaf() {
        c.emit(&[Src::Bin(0)], NO_AXES, NO_PARENT, None);
    } else if let Some(costs) = sah {
        let plan = Plan::new(nodes, N::WIDTH, costs);
        c.emit_planned(&plan, 0, NO_PARENT);
    } else {
        c.collapse_inner(0, NO_PARENT);
    }
    c.out
}

/// SAH costs of the planned collapse ([`Plan`]), relative to each other: visiting one wide
/// node, and testing one four-triangle packet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CollapseCosts {
    pub node: f32,
    pub packet: f32,
}

/// The costs of a [`Bvh8`](super::Bvh8)'s collapse: a node visit (an eight-wide box test and
/// the sort of the hit slots) and a packet test (four watertight triangle tests) cost about the
/// same. On the dragon, packet costs of 0.5 and 2 were within noise of 1: the binary tree's
/// leaves (up to 16 triangles) bound what the plan can do. Smaller binary leaves (`leaf=4` or
/// `icost=0.5`) cut instructions by 8 to 13 % on the bunny but were 5 to 15 % slower on the
/// dragon, whose extra nodes and emptier packets no longer fit the caches.
pub(crate) const PLAN_COSTS: CollapseCosts = CollapseCosts {
    node: 1.0,
    packet: 1.0,
};

/// The SAH-optimal collapse of a binary tree into a wide one, after Ylitie, Karras and Laine,
/// "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs" (HPG 2017), §4.1:
/// bottom up, `cost[n][i - 1]` is the least SAH cost of representing binary subtree `n` by at
/// most `i` slots of its parent's wide node, each slot a leaf or a wide node of its own. Top
/// down, every wide node then takes the distribution of slots that cost says is cheapest.
///
/// Deviations: a leaf costs per four-triangle packet (`ceil(count / 4)`, Embree's SAH block
/// size), not per triangle, and holds up to [`MAX_LEAF_TRIANGLES`] triangles; a leaf may be
/// any binary subtree (its triangles are contiguous in leaf order), not only a binary leaf.
struct Plan {
    /// Per binary node, `cost[i - 1]` for `i` slots at most (`width` entries used).
    cost: Vec<[f32; MAX_WIDTH]>,
    /// Cost of the subtree as one leaf (infinite when it has too many triangles).
    leaf: Vec<f32>,
    /// Triangle slots of the subtree: first, count.
    range: Vec<(u32, u32)>,
    width: usize,
}

impl Plan {
    fn new(bin: &[Node], width: usize, c: CollapseCosts) -> Self {
        let n = bin.len();
        let mut p = Plan {
            cost: vec![[0.0; MAX_WIDTH]; n],
            leaf: vec![0.0; n],
            range: vec![(0, 0); n],
            width,
        };
        // Children always follow their parent in `bin`, so a reverse sweep is bottom up.
        for i in (0..n).rev() {
            let node = &bin[i];
            let area = node.aabb().surface_area();
            let packets = |count: u32| count.div_ceil(4) as f32;
            match node.children() {
                None => {
                    let r = node.prims().expect("leaf");
                    p.range[i] = (r.start as u32, r.len() as u32);
                    p.leaf[i] = area * c.packet * packets(r.len() as u32);
                    p.cost[i] = [p.leaf[i]; MAX_WIDTH];
                }
                Some([l, r]) => {
                    let count = p.range[l].1 + p.range[r].1;
                    p.range[i] = (p.range[l].0, count);
                    p.leaf[i] = if count as usize <= MAX_LEAF_TRIANGLES {
                        area * c.packet * packets(count)
                    } else {
                        f32::INFINITY
                    };
                    let inner = area * c.node + p.split(l, r, width).0;
                    let one = p.leaf[i].min(inner);
                    let mut cost = [one; MAX_WIDTH];
                    for (k, slot) in cost.iter_mut().enumerate().take(width).skip(1) {
                        *slot = one.min(p.split(l, r, k + 1).0);
                    }
                    p.cost[i] = cost;
                }
            }
        }
        p
    }

    /// The cheapest way to give `slots` slots (at least 2) to binary siblings `l` and `r`:
    /// its cost and the slots that go to `l`.
    fn split(&self, l: usize, r: usize, slots: usize) -> (f32, usize) {
        let mut best = (f32::INFINITY, 1);
        for k in 1..slots {
            let c = self.cost[l][k - 1] + self.cost[r][slots - k - 1];
            if c < best.0 {
                best = (c, k);
            }
        }
        best
    }
}

/// An empty vector with room for `capacity` elements whose memory the kernel is asked to back
/// with transparent huge pages (2 MiB) where they are enabled only on request, as Embree's
/// allocator does. Rays that wander through the whole scene touch more 4 KiB pages than the
/// TLB holds; with huge pages the dragon's 47 MB need two dozen entries.
fn huge_vec<T>(capacity: usize) -> Vec<T> {
    let v = Vec::with_capacity(capacity);
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = v.as_ptr() as usize;
        let end = start + capacity * std::mem::size_of::<T>();
        let (lo, hi) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if hi > lo {
            // SAFETY: `madvise` only advises on the whole pages `lo..hi`, which lie inside the
            // vector's allocation; it changes no memory contents and its failure is harmless.
            #[allow(unsafe_code)]
            unsafe {
                libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
            }
        }
    }
    v
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

    /// Makes the wide node of binary inner node `b` as `plan` distributes its slots; returns
    /// its index.
    fn emit_planned(&mut self, plan: &Plan, b: usize, parent: u32) -> u32 {
        let [l, r] = self.bin[b].children().expect("inner node");
        let (axis, l_high) = split_axis(&self.bin[l].aabb(), &self.bin[r].aabb());
        let k = plan.split(l, r, plan.width).1;
        let mut slots = Vec::with_capacity(MAX_WIDTH);
        self.distribute(plan, l, k, Path::default().child(axis, l_high), &mut slots);
        let right = Path::default().child(axis, !l_high);
        self.distribute(plan, r, plan.width - k, right, &mut slots);
        let paths: Vec<Path> = slots.iter().map(|s: &(usize, Path)| s.1).collect();
        let orders = orders(&paths, N::WIDTH, N::ORDER_BITS);
        let index = self.out.nodes.len() as u32;
        let mut node = N::empty(parent);
        node.set_axes(axis | (NO_AXIS << 2) | (NO_AXIS << 4));
        node.set_orders(orders);
        self.out.nodes.push(node);
        for (slot, &(s, _)) in slots.iter().enumerate() {
            let code = match self.bin[s].prims() {
                Some(p) => self.leaf(p.start, p.len(), index),
                None if plan.leaf[s] <= plan.cost[s][0] => {
                    let (first, count) = plan.range[s];
                    self.leaf(first as usize, count as usize, index)
                }
                None => self.emit_planned(plan, s, index),
            };
            self.out.nodes[index as usize].set(slot, self.bin[s].aabb(), code);
        }
        index
    }

    /// Appends to `out` the binary subtrees that fill at most `slots` slots for binary node
    /// `b` (on `path`), as `plan` says is cheapest.
    fn distribute(
        &self,
        plan: &Plan,
        b: usize,
        slots: usize,
        path: Path,
        out: &mut Vec<(usize, Path)>,
    ) {
        if let (Some([l, r]), true) = (self.bin[b].children(), slots > 1) {
            let (cost, k) = plan.split(l, r, slots);
            if cost < plan.cost[b][0] {
                let (axis, l_high) = split_axis(&self.bin[l].aabb(), &self.bin[r].aabb());
                self.distribute(plan, l, k, path.child(axis, l_high), out);
                self.distribute(plan, r, slots - k, path.child(axis, !l_high), out);
                return;
            }
        }
        out.push((b, path));
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
    use crate::wide::Node8;
    use crate::{BuildParams, Bvh2};

    #[test]
    fn the_plan_fills_nodes_and_keeps_every_triangle() {
        let mut s = 0x2545_F491u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as f32 / (1 << 24) as f32
        };
        let tris: Vec<[Vec3; 3]> = (0..5000)
            .map(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
                [
                    c,
                    c + Vec3::new(rnd(), 0.0, 0.1),
                    c + Vec3::new(0.0, rnd(), 0.2),
                ]
            })
            .collect();
        let params = BuildParams {
            max_leaf_size: 16,
            intersection_cost: 0.2,
            ..BuildParams::default()
        };
        let bvh = Bvh2::build(&tris, &params);
        let (n, t, ids) = (bvh.nodes(), bvh.triangles(), bvh.prim_ids());
        let greedy = collapse::<Node8>(n, t, ids, None);
        let planned = collapse::<Node8>(n, t, ids, Some(PLAN_COSTS));
        assert!(planned.nodes.len() < greedy.nodes.len());
        let mut seen: Vec<u32> = Vec::new();
        for node in &planned.nodes {
            assert!(node.occupied() >= 2 || planned.nodes.len() == 1);
            for slot in 0..8 {
                if let crate::wide::QChild::Leaf(r) = node.child(slot) {
                    seen.extend(r.map(|s| planned.packet_ids[s / 4][s % 4]));
                }
            }
        }
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..5000));
    }

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
