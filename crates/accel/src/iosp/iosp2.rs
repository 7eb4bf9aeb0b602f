//! 2-Lvl IOSP: the top levels of a binned-SAH BVH whose leaves are IOSP-0 heaps (thesis §7.4,
//! "2-Lvl IOSP (15)"), the binary top collapsed into four-wide nodes tested with SSE (a
//! deviation, see the module doc).

use super::heap::{self, MAX_TRIANGLES};
use super::lanes::SlotTest;
use super::{IospError, TriBox};
use crate::traversal::{insert_by_distance, Closest, Counter, SlabRay, Stack};
use crate::wide::tri4::RayPrecomp4;
use crate::wide::Slab;
use crate::{BuildParams, Bvh2, Node, ValidationError};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray};
use std::ops::Range;

/// Levels of the SAH top in the thesis' measurements.
pub const DEFAULT_TOP_LEVELS: u32 = 15;

/// Bytes [`Iosp2::build`]'s top may take: the thesis' "at most about 1 MB", in decimal
/// megabytes.
pub const DEFAULT_TOP_BYTES: usize = 1_000_000;

/// Binary levels of the top at most, whatever the budget: bounds the traversal stack.
const MAX_LEVELS: u32 = 48;

/// How deep the binary SAH tree is cut.
#[derive(Clone, Copy)]
enum Cut {
    /// After this many levels.
    Levels(u32),
    /// Where the four-wide top reaches this many bytes, opening the subtrees of largest
    /// surface area times triangle count (the SAH cost of leaving them one heap) first.
    Bytes(usize),
}

/// The top tree's traversal stack: at most three entries per level, and at most 48 levels
/// (the clamp of `top_levels`).
const STACK: usize = 3 * 48 + 1;

/// A four-wide node of the top: the children's boxes as structure of arrays (rows min x, y,
/// z, max x, y, z, as the QBVH's), and per child either a node index (`count` 0) or a heap's
/// first triangle and triangle count. Empty slots have inverted boxes, which no ray enters.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    bounds: [[f32; 4]; 6],
    child: [u32; 4],
    count: [u32; 4],
}

const _: () = assert!(std::mem::size_of::<Node4>() == 128);

impl Node4 {
    const EMPTY: Self = Self {
        bounds: [
            [f32::INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::NEG_INFINITY; 4],
        ],
        child: [0; 4],
        count: [0; 4],
    };

    fn set_box(&mut self, lane: usize, b: &Aabb) {
        for axis in 0..3 {
            self.bounds[axis][lane] = b.min[axis];
            self.bounds[axis + 3][lane] = b.max[axis];
        }
    }

    fn aabb(&self, lane: usize) -> Aabb {
        let p = |row: usize| {
            Vec3::new(
                self.bounds[row][lane],
                self.bounds[row + 1][lane],
                self.bounds[row + 2][lane],
            )
        };
        Aabb {
            min: p(0),
            max: p(3),
        }
    }

    fn planes(&self, lane: usize) -> [f32; 6] {
        std::array::from_fn(|row| self.bounds[row][lane])
    }
}

/// The two-level IOSP: a SAH BVH of at most `top_levels` binary levels, collapsed into
/// four-wide nodes (128 bytes each, the only memory beyond the triangles:
/// [`Iosp2::structure_bytes`]), each leaf an IOSP-0 heap over a contiguous range of the
/// triangle array. See the [module](super) doc for the permutation contract.
#[derive(Clone, Debug)]
pub struct Iosp2 {
    nodes: Vec<Node4>,
    bounds: Aabb,
    triangles: Vec<[Vec3; 3]>,
    lanes: SlotTest,
}

impl Iosp2 {
    /// Builds as [`Iosp2::build_with`] but cuts the binary tree where the four-wide top reaches
    /// [`DEFAULT_TOP_BYTES`], opening the subtrees of largest surface area times triangle count
    /// first (down to at most 48 levels), instead of after a fixed number of levels.
    ///
    /// # Errors
    ///
    /// As [`Iosp2::build_with`].
    pub fn build(triangles: &[[Vec3; 3]]) -> Result<(Self, Vec<u32>), IospError> {
        Self::build_top(triangles, Cut::Bytes(DEFAULT_TOP_BYTES))
    }

    /// Builds a [`Bvh2`] (default parameters) over `triangles`, cuts it after `top_levels`
    /// levels (clamped to `1..=48`; a subtree cut off becomes one leaf over its triangles) and
    /// orders each leaf's triangles into an IOSP-0 heap. Returns the structure and the
    /// permutation applied (`perm[i]` is the index in `triangles` of position `i`, which
    /// [`Hit::prim`] reports).
    ///
    /// # Errors
    ///
    /// [`IospError::TooManyTriangles`] for `2^31` triangles or more.
    pub fn build_with(
        triangles: &[[Vec3; 3]],
        top_levels: u32,
    ) -> Result<(Self, Vec<u32>), IospError> {
        Self::build_top(triangles, Cut::Levels(top_levels))
    }

    fn build_top(triangles: &[[Vec3; 3]], how: Cut) -> Result<(Self, Vec<u32>), IospError> {
        if triangles.len() >= MAX_TRIANGLES {
            return Err(IospError::TooManyTriangles {
                structure: "iosp2",
                count: triangles.len(),
                limit: MAX_TRIANGLES - 1,
            });
        }
        let bvh = Bvh2::build(triangles, &BuildParams::default());
        let src = bvh.nodes();
        let nodes = match how {
            Cut::Levels(levels) => {
                let levels = levels.clamp(1, MAX_LEVELS);
                binary_top(src, &|_, depth| depth + 1 < levels)
            }
            Cut::Bytes(budget) => {
                // The most expansions whose four-wide top fits: bytes grow with the count.
                let order = expansion_order(src);
                let top = |k: usize| {
                    let mut open = vec![false; src.len()];
                    order[..k].iter().for_each(|&i| open[i] = true);
                    binary_top(src, &|at, _| open[at])
                };
                let fits = |k: usize| 128 * wide_count(&top(k)) <= budget;
                let (mut lo, mut hi) = (0, order.len());
                while lo < hi {
                    let mid = (lo + hi).div_ceil(2);
                    if fits(mid) {
                        lo = mid;
                    } else {
                        hi = mid - 1;
                    }
                }
                top(lo)
            }
        };
        // Bvh2 without splitting stores each triangle once, in leaf order, so every cut
        // subtree owns a contiguous range; order each range as a heap.
        let mut perm: Vec<u32> = bvh.prim_ids().to_vec();
        for node in &nodes {
            if let Some(range) = node.prims() {
                let ids = &mut perm[range];
                let boxes: Vec<TriBox> = ids
                    .iter()
                    .map(|&i| TriBox::of(&triangles[i as usize]))
                    .collect();
                let order = heap::build(&boxes);
                let heaped: Vec<u32> = order.iter().map(|&k| ids[k as usize]).collect();
                ids.copy_from_slice(&heaped);
            }
        }
        let permuted = perm.iter().map(|&i| triangles[i as usize]).collect();
        let mut wide = Vec::new();
        if let Some(root) = nodes.first() {
            wide.push(Node4::EMPTY);
            match root.prims() {
                // A scene of one leaf: a root with one child.
                Some(r) => {
                    wide[0].set_box(0, &root.aabb());
                    wide[0].child[0] = r.start as u32;
                    wide[0].count[0] = r.len() as u32;
                }
                None => collapse(&nodes, 0, 0, &mut wide),
            }
        }
        Ok((
            Self {
                nodes: wide,
                bounds: bvh.bounds(),
                triangles: permuted,
                lanes: SlotTest::detect(),
            },
            perm,
        ))
    }

    /// The triangles: each top-level leaf's range is an IOSP-0 heap.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// Number of four-wide top-level nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes of the structure beyond the triangles: the top level's nodes.
    pub fn structure_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
    }

    /// Checks that every top-level node's box contains its children's (or its triangles') and
    /// that the leaves' ranges tile the triangle array and are valid heaps.
    ///
    /// # Errors
    ///
    /// The first broken invariant.
    pub fn validate(&self) -> Result<(), ValidationError> {
        self.check().map_err(|problem| ValidationError {
            structure: "iosp2".into(),
            problem,
        })
    }

    fn check(&self) -> Result<(), String> {
        let mut covered = vec![0u8; self.triangles.len()];
        for (i, node) in self.nodes.iter().enumerate() {
            for lane in 0..4 {
                let b = node.aabb(lane);
                if b.min.x > b.max.x {
                    continue; // an empty slot
                }
                let (child, count) = (node.child[lane] as usize, node.count[lane] as usize);
                let inner: Vec<Aabb> = if count == 0 {
                    let Some(c) = self.nodes.get(child).filter(|_| child > i) else {
                        return Err(format!("node {i} slot {lane} points out of range"));
                    };
                    (0..4)
                        .map(|l| c.aabb(l))
                        .filter(|b| b.min.x <= b.max.x)
                        .collect()
                } else {
                    let Some(tris) = self.triangles.get(child..child + count) else {
                        return Err(format!("node {i} slot {lane} points out of range"));
                    };
                    heap::check(tris).map_err(|e| format!("node {i} slot {lane}: {e}"))?;
                    (child..child + count).for_each(|s| covered[s] += 1);
                    tris.iter().map(Aabb::from_points).collect()
                };
                if let Some(c) = inner.iter().find(|c| !crate::traversal::inside(c, &b)) {
                    return Err(format!(
                        "node {i} slot {lane}'s box {b:?} does not contain {c:?}"
                    ));
                }
            }
        }
        match covered.iter().position(|&c| c != 1) {
            Some(s) => Err(format!("slot {s} in {} leaves", covered[s])),
            None => Ok(()),
        }
    }

    #[inline(always)]
    fn traverse<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        if self.nodes.is_empty() || !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let slab4 = Slab::new(ray);
        let slab = SlabRay::new(ray);
        let pre = RayPrecomp4::new(ray);
        let mut closest = Closest::new(t_max);
        let tris = &self.triangles[..];
        // (node << 2 | lane) of a heap, or a node index, with the HEAP bit; entry distance.
        const HEAP: u32 = 1 << 31;
        let mut stack = Stack::<STACK, true>::new();
        let mut cur = 0u32;
        loop {
            if cur & HEAP != 0 {
                let (node, lane) = (&self.nodes[(cur & !HEAP) as usize >> 2], cur as usize & 3);
                let (start, count) = (node.child[lane] as usize, node.count[lane] as usize);
                // The box clips the heap's interval on all three axes (its root slab has one).
                if let Some(interval) = slab.interval(&node.planes(lane), closest.cull_t) {
                    if heap::traverse::<ANY_HIT, C>(
                        &tris[start..start + count],
                        start as u32,
                        &slab,
                        &pre,
                        self.lanes,
                        interval,
                        t_max,
                        &mut closest,
                        counter,
                    ) {
                        return closest.hit;
                    }
                }
            } else {
                let node = &self.nodes[cur as usize];
                counter.boxes(4);
                let (mask, t) = slab4.hit4(&node.bounds, closest.cull_t);
                // The hit slots by entry distance, nearest first.
                let (mut hits, mut n) = ([(0.0f32, 0u32); 4], 0);
                let mut rest = mask;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let code = if node.count[lane] == 0 {
                        node.child[lane]
                    } else {
                        // The heap's root pair (or all of a small heap) will be read when it is
                        // popped: start loading it now, as the QBVH does for its leaves.
                        let start = node.child[lane] as usize;
                        heap::prefetch_slots(tris, start, node.count[lane].min(2) as usize);
                        HEAP | (cur << 2) | lane as u32
                    };
                    n = insert_by_distance(&mut hits, n, t[lane], code);
                }
                if let Some(nearest) = stack.push_all_but_nearest(&hits[..n]) {
                    cur = nearest;
                    continue;
                }
            }
            match stack.pop(closest.cull_t) {
                Some(code) => cur = code,
                None => return closest.hit,
            }
        }
    }
}

/// Collapses the binary node `at` of `src` (an inner node) into `dst[to]`: starting from its
/// two children, the inner child of largest surface area is replaced by its own two until
/// there are four or only leaves (Dammertz et al.'s greedy QBVH collapse); inner children
/// become nodes of their own, leaves become heap slots.
fn collapse(src: &[Node], at: usize, to: usize, dst: &mut Vec<Node4>) {
    let mut kids: Vec<usize> = src[at].children().expect("an inner node").to_vec();
    while kids.len() < 4 {
        let widest = kids
            .iter()
            .enumerate()
            .filter(|(_, &k)| src[k].children().is_some())
            .max_by(|a, b| {
                let area = |k: usize| src[k].aabb().surface_area();
                area(*a.1).total_cmp(&area(*b.1))
            })
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let k = kids.swap_remove(i);
        kids.extend(src[k].children().expect("inner"));
    }
    for (lane, &k) in kids.iter().enumerate() {
        dst[to].set_box(lane, &src[k].aabb());
        match src[k].prims() {
            Some(r) => {
                dst[to].child[lane] = r.start as u32;
                dst[to].count[lane] = r.len() as u32;
            }
            None => {
                let index = dst.len();
                dst.push(Node4::EMPTY);
                dst[to].child[lane] = index as u32;
                collapse(src, k, index, dst);
            }
        }
    }
}

/// The top of the binary tree `src`: a copy whose node `at` (at depth `depth`) keeps its
/// children where `open(at, depth)` and otherwise becomes a leaf over its subtree's range.
fn binary_top(src: &[Node], open: &dyn Fn(usize, u32) -> bool) -> Vec<Node> {
    let mut dst = Vec::new();
    if let Some(root) = src.first() {
        dst.push(*root);
        cut(src, 0, 0, 0, open, &mut dst);
    }
    dst
}

/// Copies the children of `src`'s node `at` (already copied to `dst[to]`, at depth `depth`)
/// into `dst`, turning nodes not to be opened into leaves over their subtree's range.
fn cut(
    src: &[Node],
    at: usize,
    to: usize,
    depth: u32,
    open: &dyn Fn(usize, u32) -> bool,
    dst: &mut Vec<Node>,
) {
    let Some([l, r]) = src[at].children() else {
        return;
    };
    if !open(at, depth) {
        let range = subtree_range(src, at);
        dst[to] = Node::leaf(src[at].aabb(), range.start as u32, range.len() as u32);
        return;
    }
    let first = dst.len();
    dst[to] = Node::inner(src[at].aabb(), first as u32);
    dst.push(src[l]);
    dst.push(src[r]);
    cut(src, l, first, depth + 1, open, dst);
    cut(src, r, first + 1, depth + 1, open, dst);
}

/// The inner nodes of `src` in the order a budgeted cut opens them: largest surface area
/// times triangle count first (among those whose parent is open), above [`MAX_LEVELS`].
fn expansion_order(src: &[Node]) -> Vec<usize> {
    if src.is_empty() {
        return Vec::new();
    }
    // Triangles under each node, children after their parent in `src`.
    let mut count = vec![0f32; src.len()];
    for i in (0..src.len()).rev() {
        count[i] = match (src[i].children(), src[i].prims()) {
            (Some([l, r]), _) => count[l] + count[r],
            (None, Some(r)) => r.len() as f32,
            (None, None) => 0.0,
        };
    }
    let key = |i: usize| src[i].aabb().surface_area() * count[i];
    let mut order = Vec::new();
    let mut frontier = std::collections::BinaryHeap::new();
    frontier.push((Ordered(key(0)), 0usize, 0u32));
    while let Some((_, i, depth)) = frontier.pop() {
        let Some(children) = src[i].children() else {
            continue;
        };
        if depth + 1 >= MAX_LEVELS {
            continue;
        }
        order.push(i);
        for c in children {
            frontier.push((Ordered(key(c)), c, depth + 1));
        }
    }
    order
}

/// An `f32` ordered by `total_cmp`, for the frontier heap.
#[derive(PartialEq)]
struct Ordered(f32);

impl Eq for Ordered {}

impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Four-wide nodes [`collapse`] makes of the binary top `nodes`.
fn wide_count(nodes: &[Node]) -> usize {
    match nodes.first() {
        None => 0,
        Some(root) if root.prims().is_some() => 1,
        Some(_) => {
            let mut wide = vec![Node4::EMPTY];
            collapse(nodes, 0, 0, &mut wide);
            wide.len()
        }
    }
}

/// The leaf-order range of the subtree of `at`: its leaves are contiguous because the binary
/// BVH stores them depth first.
fn subtree_range(src: &[Node], at: usize) -> Range<usize> {
    let (mut lo, mut hi) = (usize::MAX, 0);
    let mut stack = vec![at];
    while let Some(i) = stack.pop() {
        match (src[i].children(), src[i].prims()) {
            (Some(c), _) => stack.extend(c),
            (None, Some(r)) => {
                lo = lo.min(r.start);
                hi = hi.max(r.end);
            }
            (None, None) => {}
        }
    }
    lo..hi
}

impl Accel for Iosp2 {
    fn name(&self) -> &str {
        "iosp2"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes() + std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(Iosp2::structure_bytes(self))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
