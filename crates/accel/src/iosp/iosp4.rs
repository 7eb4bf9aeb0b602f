//! IOSP-4: the implicit bounding-plane BVH with one 4-byte word per node (thesis §7.2).

use super::iosp4_build::{self, SAH_DEPTH};
use super::{bounds_of, slab_of, IospError, TriBox};
use crate::traversal::{Closest, Counter, SlabRay, FAR_SCALE};
use crate::ValidationError;
use glam::Vec3;
use rt_core::triangle::{intersect_triangle, RayPrecomp};
use rt_core::{Aabb, Accel, Hit, Ray};

/// The node word. Bits `[1:0]`: the children's bounding axis (`0..=2`, which is also the axis
/// this node's triangles were partitioned on) or `3` for a leaf. Inner node: bits `[31:2]` are
/// the index of the left child; the right child follows it. Leaf: bits `[4:2]` count its extra
/// triangles (0–7) and bits `[31:5]` give their offset into the extras region, which follows
/// all bounding triangles in the triangle array.
pub(crate) mod word {
    /// Tag of a leaf in bits `[1:0]`.
    pub const LEAF: u32 = 3;

    pub fn inner(child_axis: u32, left: u32) -> u32 {
        debug_assert!(child_axis < 3 && left < 1 << 30);
        left << 2 | child_axis
    }

    pub fn leaf(count: u32, offset: u32) -> u32 {
        debug_assert!(count < 8 && offset < 1 << 27);
        offset << 5 | count << 2 | LEAF
    }

    /// `(count, offset)` of a leaf word.
    #[inline(always)]
    pub fn extras(w: u32) -> (usize, usize) {
        (((w >> 2) & 7) as usize, (w >> 5) as usize)
    }
}

/// Triangle limit: the extras offset has 27 bits, and node indices (fewer than `n / 2`) fit 30.
pub(crate) const MAX_TRIANGLES: usize = 1 << 27;

/// Traversal stack entries: one per inner ancestor at most (see [`SAH_DEPTH`]).
const STACK: usize = SAH_DEPTH as usize + 32;

/// The IOSP-4 hierarchy: every node's slab along one axis is spanned by its two bounding
/// triangles, stored at positions `2i` and `2i + 1` of the triangle array; a node costs one
/// `u32` ([`Iosp4::structure_bytes`] is `4 ·` nodes). Built with a binned SAH that accounts for
/// the one-axis clipping; leaves add up to 7 triangles from a region after all bounding
/// triangles. See the [module](super) doc for the permutation contract.
#[derive(Clone, Debug)]
pub struct Iosp4 {
    words: Vec<u32>,
    triangles: Vec<[Vec3; 3]>,
    bound_slots: usize,
    root_axis: u8,
    bounds: Aabb,
}

impl Iosp4 {
    /// Builds over `triangles`; returns the structure and the permutation applied (`perm[i]` is
    /// the index in `triangles` of position `i` of [`Iosp4::triangles`], which [`Hit::prim`]
    /// reports). Any geometry is accepted.
    ///
    /// # Errors
    ///
    /// [`IospError::TooManyTriangles`] beyond `2^27` triangles (the 27-bit leaf offset).
    pub fn build(triangles: &[[Vec3; 3]]) -> Result<(Self, Vec<u32>), IospError> {
        if triangles.len() > MAX_TRIANGLES {
            return Err(IospError::TooManyTriangles {
                structure: "iosp4",
                count: triangles.len(),
                limit: MAX_TRIANGLES,
            });
        }
        let boxes: Vec<TriBox> = triangles.iter().map(TriBox::of).collect();
        let bounds = bounds_of(triangles);
        let built = iosp4_build::build(&boxes, bounds);
        let permuted = built.order.iter().map(|&i| triangles[i as usize]).collect();
        Ok((
            Self {
                words: built.words,
                triangles: permuted,
                bound_slots: built.bound_slots,
                root_axis: built.root_axis,
                bounds,
            },
            built.order,
        ))
    }

    /// The triangles: the bounding pairs of all nodes, node order, then the leaves' extras.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The node words, root first.
    pub fn words(&self) -> &[u32] {
        &self.words
    }

    /// Bytes of the structure beyond the triangles: 4 per node.
    pub fn structure_bytes(&self) -> usize {
        std::mem::size_of_val(self.words.as_slice())
    }

    /// Checks the words (children and extras in range, every triangle in exactly one node, the
    /// depth within the stack) and that every node's slab contains its subtree's triangles.
    ///
    /// # Errors
    ///
    /// The first broken invariant.
    pub fn validate(&self) -> Result<(), ValidationError> {
        self.check().map_err(|problem| ValidationError {
            structure: "iosp4".into(),
            problem,
        })
    }

    fn check(&self) -> Result<(), String> {
        let n = self.triangles.len();
        let m = self.words.len();
        if n == 0 {
            return if m == 0 {
                Ok(())
            } else {
                Err("nodes without triangles".into())
            };
        }
        let mut seen = vec![0u8; n];
        // (node, axis, depth, slab lo, slab hi) of every ancestor is checked against each
        // triangle by walking down with the list of enclosing slabs.
        let mut stack = vec![(
            0usize,
            self.root_axis as usize,
            Vec::<(usize, f32, f32)>::new(),
        )];
        let mut reached = vec![false; m];
        while let Some((node, axis, mut slabs)) = stack.pop() {
            if node >= m || reached[node] {
                return Err(format!("node {node} out of range or reached twice"));
            }
            reached[node] = true;
            if slabs.len() >= STACK {
                return Err(format!("node {node} deeper than the traversal stack"));
            }
            let (a, b) = self.pair(node);
            let (lo, hi) = slab_of(&self.triangles[a], &self.triangles[b], axis);
            slabs.push((axis, lo, hi));
            let w = self.words[node];
            let mut mine = vec![a, b];
            if w & 3 == word::LEAF {
                let (count, offset) = word::extras(w);
                let first = self.bound_slots + offset;
                if first + count > n {
                    return Err(format!("leaf {node}'s extras {first}+{count} beyond {n}"));
                }
                mine.extend(first..first + count);
            } else {
                let left = (w >> 2) as usize;
                if left + 1 >= m || left <= node {
                    return Err(format!("node {node}'s children {left} out of range"));
                }
                for c in [left, left + 1] {
                    stack.push((c, (w & 3) as usize, slabs.clone()));
                }
            }
            mine.dedup();
            for s in mine {
                seen[s] += 1;
                let t = TriBox::of(&self.triangles[s]);
                for &(ax, lo, hi) in &slabs {
                    if t.lo[ax] < lo || t.hi[ax] > hi {
                        return Err(format!("slot {s} of node {node} leaves an ancestor's slab [{lo}, {hi}] on axis {ax}"));
                    }
                }
            }
        }
        if let Some(s) = seen.iter().position(|&c| c != 1) {
            return Err(format!("slot {s} in {} nodes", seen[s]));
        }
        if let Some(node) = reached.iter().position(|&r| !r) {
            return Err(format!("node {node} unreachable"));
        }
        Ok(())
    }

    /// The bounding slots of `node` (equal for a one-triangle scene).
    #[inline(always)]
    fn pair(&self, node: usize) -> (usize, usize) {
        let a = 2 * node;
        (a, (a + 1).min(self.bound_slots - 1))
    }

    #[inline(always)]
    fn traverse<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        if self.words.is_empty() || !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let pre = RayPrecomp::new(ray);
        let slab = SlabRay::new(ray);
        let mut closest = Closest::new(t_max);
        let tris = &self.triangles[..];
        let mut stack = [(0u32, 0u32, 0f32, 0f32); STACK];
        let mut sp = 0;
        let (mut node, mut axis, mut t0, mut t1) = (0u32, self.root_axis as u32, 0f32, t_max);
        loop {
            let (a, b) = self.pair(node as usize);
            counter.boxes(1);
            let (lo, hi) = slab_of(&tris[a], &tris[b], axis as usize);
            let (near, far) = slab.slab(axis as usize, lo, hi);
            let tn = t0.max(near);
            let tf = t1.min(far).min(closest.cull_t);
            let mut descended = false;
            if tn <= tf * FAR_SCALE {
                counter.leaf();
                let w = self.words[node as usize];
                let extras = if w & 3 == word::LEAF {
                    let (count, offset) = word::extras(w);
                    self.bound_slots + offset..self.bound_slots + offset + count
                } else {
                    0..0
                };
                for s in (a..=b).chain(extras) {
                    counter.triangle();
                    if let Some(h) = intersect_triangle(&pre, &tris[s], t_max) {
                        if closest.offer::<ANY_HIT>(h.t, s as u32, h.b1, h.b2) {
                            return closest.hit;
                        }
                    }
                }
                if w & 3 != word::LEAF {
                    let left = w >> 2;
                    let k = w & 3;
                    let (near, far) = if slab.negative(k as usize) {
                        (left + 1, left)
                    } else {
                        (left, left + 1)
                    };
                    stack[sp] = (far, k, tn, tf);
                    sp += 1;
                    (node, axis, t0, t1) = (near, k, tn, tf);
                    descended = true;
                }
            }
            if !descended {
                loop {
                    if sp == 0 {
                        return closest.hit;
                    }
                    sp -= 1;
                    let e = stack[sp];
                    if e.2 <= closest.cull_t * FAR_SCALE {
                        (node, axis, t0, t1) = e;
                        break;
                    }
                }
            }
        }
    }
}

impl Accel for Iosp4 {
    fn name(&self) -> &str {
        "iosp4"
    }

    crate::traversal::queries_by_traverse!();

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        self.structure_bytes() + std::mem::size_of_val(self.triangles.as_slice())
    }

    fn structure_bytes(&self) -> Option<usize> {
        Some(Iosp4::structure_bytes(self))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
