//! 2-Lvl IOSP: the top levels of a binned-SAH BVH whose leaves are IOSP-0 heaps (thesis §7.4,
//! "2-Lvl IOSP (15)").

use super::heap::{self, MAX_TRIANGLES};
use super::lanes::SlotTest;
use super::{IospError, TriBox};
use crate::traversal::{walk_binary, with_counter, BinaryNode, Closest, Counter, SlabRay, Step};
use crate::wide::tri4::RayPrecomp4;
use crate::{BuildParams, Bvh2, Node, ValidationError};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};
use std::ops::Range;

/// Levels of the SAH top in the thesis' measurements.
pub const DEFAULT_TOP_LEVELS: u32 = 15;

/// The top tree's traversal stack: its depth is at most 48 (the clamp of `top_levels`).
const MAX_DEPTH: usize = 64;

/// The two-level IOSP: a binary SAH BVH of at most `top_levels` levels (32-byte nodes, the only
/// memory beyond the triangles: [`Iosp2::structure_bytes`]), each leaf an IOSP-0 heap over a
/// contiguous range of the triangle array. See the [module](super) doc for the permutation
/// contract.
#[derive(Clone, Debug)]
pub struct Iosp2 {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
    lanes: SlotTest,
}

impl Iosp2 {
    /// Builds with [`DEFAULT_TOP_LEVELS`]; see [`Iosp2::build_with`].
    ///
    /// # Errors
    ///
    /// As [`Iosp2::build_with`].
    pub fn build(triangles: &[[Vec3; 3]]) -> Result<(Self, Vec<u32>), IospError> {
        Self::build_with(triangles, DEFAULT_TOP_LEVELS)
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
        if triangles.len() >= MAX_TRIANGLES {
            return Err(IospError::TooManyTriangles {
                structure: "iosp2",
                count: triangles.len(),
                limit: MAX_TRIANGLES - 1,
            });
        }
        let top_levels = top_levels.clamp(1, 48);
        let bvh = Bvh2::build(triangles, &BuildParams::default());
        let mut nodes = Vec::new();
        if let Some(root) = bvh.nodes().first() {
            nodes.push(*root);
            cut(bvh.nodes(), 0, 0, 0, top_levels, &mut nodes);
        }
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
        Ok((
            Self {
                nodes,
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

    /// The top-level nodes, root first.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
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
            let b = node.aabb();
            let inner: Vec<Aabb> = match (node.children(), node.prims()) {
                (Some(c), _) if c[1] < self.nodes.len() && c[0] > i => {
                    c.iter().map(|&k| self.nodes[k].aabb()).collect()
                }
                (None, Some(r)) if r.end <= self.triangles.len() => {
                    heap::check(&self.triangles[r.clone()])
                        .map_err(|e| format!("leaf {i}: {e}"))?;
                    r.clone().for_each(|s| covered[s] += 1);
                    self.triangles[r].iter().map(Aabb::from_points).collect()
                }
                _ => return Err(format!("node {i} points out of range")),
            };
            if let Some(c) = inner.iter().find(|c| !crate::traversal::inside(c, &b)) {
                return Err(format!("node {i}'s box {b:?} does not contain {c:?}"));
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
        if !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let pre = RayPrecomp4::new(ray);
        let slab = SlabRay::new(ray);
        let mut closest = Closest::new(t_max);
        let tris = &self.triangles[..];
        walk_binary::<_, _, MAX_DEPTH>(
            &self.nodes,
            ray,
            t_max,
            counter,
            |node, cull_t, counter| {
                let range: Range<usize> = node.prims().expect("a leaf");
                let offset = range.start as u32;
                // The leaf's box clips the heap's interval on all three axes (its root slab has
                // one); the walk found it entered, so this only misses by rounding.
                let Some(interval) = slab.interval(node.planes(), cull_t) else {
                    return Step::Miss;
                };
                if heap::traverse::<ANY_HIT, C>(
                    &tris[range],
                    offset,
                    &slab,
                    &pre,
                    self.lanes,
                    interval,
                    t_max,
                    &mut closest,
                    counter,
                ) {
                    Step::Done
                } else {
                    Step::Closer(closest.cull_t)
                }
            },
        );
        closest.hit
    }
}

/// Copies the children of `src`'s node `at` (already copied to `dst[to]`, at depth `depth`)
/// into `dst`, turning nodes on the last kept level into leaves over their subtree's range.
fn cut(src: &[Node], at: usize, to: usize, depth: u32, levels: u32, dst: &mut Vec<Node>) {
    let Some([l, r]) = src[at].children() else {
        return;
    };
    if depth + 1 >= levels {
        let range = subtree_range(src, at);
        dst[to] = Node::leaf(src[at].aabb(), range.start as u32, range.len() as u32);
        return;
    }
    let first = dst.len();
    dst[to] = Node::inner(src[at].aabb(), first as u32);
    dst.push(src[l]);
    dst.push(src[r]);
    cut(src, l, first, depth + 1, levels, dst);
    cut(src, r, first + 1, depth + 1, levels, dst);
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

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        with_counter!(counters, |c| self.traverse::<false, _>(ray, t_max, c))
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        _toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        with_counter!(counters, |c| self
            .traverse::<true, _>(ray, t_max, c)
            .is_some())
    }

    fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, Node::aabb)
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
