//! The top level of [`super::TwoLevel`]: a binary SAH BVH over the entries' world boxes,
//! collapsed eight wide, rebuilt or refitted per frame.

use crate::bvh2::build::{build_over_boxes, MAX_DEPTH};
use crate::bvh2::Node;
use crate::traversal::{insert_by_distance, Stack};
use crate::wide::{Avx2, Slab};
use crate::BuildParams;
use glam::Vec3;
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

/// Lanes of a top-level node: eight, tested in one AVX2 register where the CPU has it (two
/// SSE halves otherwise), so a ray visits fewer, shallower nodes than four wide.
const WIDTH: usize = 8;
/// A child code naming an entry (the top level's leaf) rather than a node.
const ENTRY: u32 = 1 << 31;
/// A slot with no child; its box is inverted, so no ray enters it.
const NONE: u32 = u32::MAX;
/// Pending subtrees at most: each level below the root pushes at most three.
const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A node of the eight-wide top level: its children's boxes as structure of arrays (rows min
/// x, y, z, max x, y, z, as [`Slab::hit8`] reads them, 32-byte aligned) and their codes: a
/// node index, `ENTRY | entry`, or `NONE`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node4 {
    bounds: [[f32; WIDTH]; 6],
    children: [u32; WIDTH],
}

impl Node4 {
    fn empty() -> Self {
        let (lo, hi) = ([f32::INFINITY; WIDTH], [f32::NEG_INFINITY; WIDTH]);
        Self {
            bounds: [lo, lo, lo, hi, hi, hi],
            children: [NONE; WIDTH],
        }
    }

    fn set(&mut self, slot: usize, b: Aabb) {
        let v = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
        for (row, value) in self.bounds.iter_mut().zip(v) {
            row[slot] = value;
        }
    }

    /// The union of the occupied slots' boxes.
    fn aabb(&self) -> Aabb {
        let b = &self.bounds;
        (0..WIDTH)
            .filter(|&i| self.children[i] != NONE)
            .map(|i| {
                Aabb::new(
                    Vec3::new(b[0][i], b[1][i], b[2][i]),
                    Vec3::new(b[3][i], b[4][i], b[5][i]),
                )
            })
            .fold(Aabb::EMPTY, Aabb::union)
    }
}

/// The binary SAH tree over the entries (one entry per leaf, as the thesis builds it)
/// collapsed wide for traversal, as the thesis makes its QBVHs: one SIMD test of eight boxes
/// replaces three levels of scalar pairs, which dominated the clustered trace.
#[derive(Default)]
pub(super) struct Top {
    nodes: Vec<Node4>,
    /// Set when the CPU has AVX2: the walk then runs a copy compiled for it.
    avx2: Option<Avx2>,
}

impl Top {
    /// One entry per leaf: entering an object costs a transform and a second traversal,
    /// so a leaf of two overlapping objects would enter both for every ray reaching it.
    pub fn build(boxes: &[Aabb]) -> Self {
        let params = BuildParams {
            max_leaf_size: 1,
            parallel: false,
            ..BuildParams::default()
        };
        let built = build_over_boxes(boxes, &params);
        let mut top = Self {
            nodes: Vec::with_capacity(built.nodes.len() / (WIDTH - 1) + 1),
            avx2: Avx2::detect(),
        };
        if !built.nodes.is_empty() {
            top.collapse(&built.nodes, &built.order, 0);
        }
        top
    }

    /// Emits binary node `b` as a wide node (its index returned), its children after
    /// it: the binary inner child of largest surface area is opened until every slot is
    /// filled or only leaves remain.
    fn collapse(&mut self, bin: &[Node], order: &[u32], b: usize) -> u32 {
        let index = self.nodes.len();
        self.nodes.push(Node4::empty());
        let mut slots = [0usize; WIDTH];
        let mut n = 1;
        slots[0] = b;
        loop {
            let open = (0..n)
                .filter(|&i| !bin[slots[i]].is_leaf())
                .max_by(|&i, &j| {
                    let area = |k: usize| bin[slots[k]].aabb().surface_area();
                    area(i).total_cmp(&area(j))
                });
            let Some(i) = open else { break };
            if n == WIDTH {
                break;
            }
            let [l, r] = bin[slots[i]].children().expect("an inner node");
            slots[i] = l;
            slots[n] = r;
            n += 1;
        }
        for (lane, &s) in slots[..n].iter().enumerate() {
            let node = &bin[s];
            let code = match node.prims() {
                // One entry per leaf (`max_leaf_size: 1`).
                Some(range) => {
                    debug_assert_eq!(range.len(), 1);
                    ENTRY | order[range.start]
                }
                None => self.collapse(bin, order, s),
            };
            self.nodes[index].set(lane, node.aabb());
            self.nodes[index].children[lane] = code;
        }
        index as u32
    }

    /// Recomputes every node's boxes from `boxes` (indexed like the build's), keeping the tree.
    pub fn refit(&mut self, boxes: &[Aabb]) {
        // Children follow their parent in `nodes`, so a reverse sweep sees children first.
        for i in (0..self.nodes.len()).rev() {
            for lane in 0..WIDTH {
                let code = self.nodes[i].children[lane];
                let b = match code {
                    NONE => continue,
                    c if c & ENTRY != 0 => boxes[(c & !ENTRY) as usize],
                    c => self.nodes[c as usize].aabb(),
                };
                self.nodes[i].set(lane, b);
            }
        }
    }

    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
    }

    /// Front-to-back walk: `leaf(entry, t_cull, counters)` returns the distance of a hit
    /// found in it; with `any` the first hit ends the walk. Nodes are counted only with
    /// `COUNT`: counting the occupied slots of every node cost a few per cent uncounted.
    #[inline]
    pub fn walk<const COUNT: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
        any: bool,
        leaf: impl FnMut(u32, f32, &mut TraversalCounters) -> Option<f32>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2.is_some() {
            // SAFETY: `Avx2::detect` found AVX2 when this top level was made.
            #[allow(unsafe_code)]
            return unsafe { self.walk_avx2::<COUNT>(ray, t_max, counters, any, leaf) };
        }
        self.walk_with::<COUNT, false>(ray, t_max, counters, any, leaf)
    }

    /// [`Top::walk`] compiled with AVX2: the eight boxes in one register.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn walk_avx2<const COUNT: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
        any: bool,
        leaf: impl FnMut(u32, f32, &mut TraversalCounters) -> Option<f32>,
    ) {
        self.walk_with::<COUNT, true>(ray, t_max, counters, any, leaf)
    }

    #[inline(always)]
    fn walk_with<const COUNT: bool, const AVX2: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
        any: bool,
        mut leaf: impl FnMut(u32, f32, &mut TraversalCounters) -> Option<f32>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let slab = Slab::new(ray);
        let mut t_cull = t_max;
        let mut stack = Stack::<STACK, true>::new();
        let mut cur = 0u32;
        loop {
            if cur & ENTRY != 0 {
                if let Some(t) = leaf(cur & !ENTRY, t_cull, counters) {
                    t_cull = t_cull.min(t);
                    if any {
                        return;
                    }
                }
            } else {
                let node = &self.nodes[cur as usize];
                if COUNT {
                    counters.nodes_visited +=
                        node.children.iter().filter(|&&c| c != NONE).count() as u64;
                }
                #[cfg(target_arch = "x86_64")]
                let (mask, t) = if AVX2 {
                    // SAFETY: `AVX2` is true only in `walk_avx2`, called after detection.
                    #[allow(unsafe_code)]
                    unsafe {
                        slab.hit8_avx2(&node.bounds, t_cull)
                    }
                } else {
                    slab.hit8(&node.bounds, t_cull)
                };
                #[cfg(not(target_arch = "x86_64"))]
                let (mask, t) = slab.hit8(&node.bounds, t_cull);
                // The hit slots by entry distance, nearest first.
                let (mut hits, mut n) = ([(0.0f32, 0u32); WIDTH], 0);
                let mut rest = mask;
                while rest != 0 {
                    let lane = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    n = insert_by_distance(&mut hits, n, t[lane], node.children[lane]);
                }
                if let Some(nearest) = stack.push_all_but_nearest(&hits[..n]) {
                    cur = nearest;
                    continue;
                }
            }
            // The nearest pending subtree that can still hold something closer.
            match stack.pop(t_cull) {
                Some(code) => cur = code,
                None => return,
            }
        }
    }
}
