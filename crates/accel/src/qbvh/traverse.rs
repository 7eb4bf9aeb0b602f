//! Stack traversal with a four-wide robust slab test, in three child orders, with or without
//! entry distances on the stack.

use super::node::{leaf_parts, QNode, EMPTY, IDENTITY_ORDER, LEAF_BIT};
use super::tri4::{intersect4, RayPrecomp4};
use super::{Qbvh, TriangleTest};
use crate::crack_free::{intersect_hybrid, intersect_subdivision, SubdivRay};
use crate::traversal::{Closest, Counter, FAR_SCALE};
use rt_core::{Aabb, Hit, Ray};
use std::mem::MaybeUninit;

/// Deepest node the traversal stack supports: the binary tree's depth bound (64) plus the
/// levels that split over-long leaves (at most 12 for 2^27 triangles).
pub(crate) const MAX_DEPTH: usize = 80;
/// Traversal pushes at most three entries per inner node on the current path.
pub(crate) const STACK_SIZE: usize = 3 * MAX_DEPTH + 1;

/// Key of a missed or empty slot; sorts after every hit.
const MISS: u64 = u64::MAX;

/// Per-ray constants of the slab test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slab4 {
    org: [f32; 3],
    /// `1 / dir`; a zero component of either sign becomes an infinity of that sign.
    inv: [f32; 3],
    /// Plane index (into [`QNode`]'s `bounds`) of the near and far plane per axis, chosen by the
    /// sign bit of `inv` so that `-0.0` goes with `-inf`.
    near: [usize; 3],
    far: [usize; 3],
}

impl Slab4 {
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        let inv = ray.dir.recip().to_array();
        let neg = inv.map(|x| x.is_sign_negative() as usize);
        Self {
            org: ray.origin.to_array(),
            inv,
            near: [0, 1, 2].map(|a| a + 3 * neg[a]),
            far: [0, 1, 2].map(|a| a + 3 - 3 * neg[a]),
        }
    }

    /// Entry distance into `b` within `[0, t_max]`, conservatively, exactly as `Bvh2` tests.
    #[inline(always)]
    pub(crate) fn hit_box(&self, b: &Aabb, t_max: f32) -> Option<f32> {
        let planes = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for axis in 0..3 {
            let near = (planes[self.near[axis]] - self.org[axis]) * self.inv[axis];
            let far = (planes[self.far[axis]] - self.org[axis]) * self.inv[axis];
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        (t0 <= t1 * FAR_SCALE).then_some(t0)
    }

    /// Entry distances into the four boxes of `node` and the mask of boxes hit, one lane at a
    /// time. A NaN slab distance (0 * inf: the ray lies in a face plane) leaves the interval
    /// alone, because `f32::max`/`min` return the non-NaN operand.
    #[cfg_attr(
        all(target_arch = "x86_64", target_feature = "sse2"),
        allow(dead_code) // used by the tests only
    )]
    #[inline(always)]
    pub(crate) fn hit4_scalar(&self, node: &QNode, t_max: f32) -> (u32, [f32; 4]) {
        let mut mask = 0;
        let mut t = [0.0f32; 4];
        for (lane, t_lane) in t.iter_mut().enumerate() {
            let mut t0 = 0.0f32;
            let mut t1 = t_max;
            for axis in 0..3 {
                let o = self.org[axis];
                let near = (node.bounds[self.near[axis]][lane] - o) * self.inv[axis];
                let far = (node.bounds[self.far[axis]][lane] - o) * self.inv[axis];
                t0 = t0.max(near);
                t1 = t1.min(far);
            }
            *t_lane = t0;
            mask |= u32::from(t0 <= t1 * FAR_SCALE) << lane;
        }
        (mask, t)
    }

    /// [`Slab4::hit4_scalar`] with SSE2. `maxps`/`minps` return their second operand when the
    /// comparison is unordered, so the slab distance goes first and a NaN leaves the running
    /// interval alone, exactly like the scalar code.
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    #[allow(unsafe_code)]
    #[inline(always)]
    pub(crate) fn hit4_sse(&self, node: &QNode, t_max: f32) -> (u32, [f32; 4]) {
        use std::arch::x86_64::*;
        let mut t = [0.0f32; 4];
        // SAFETY: the `cfg` guarantees SSE and SSE2 are enabled for the whole build, which is
        // all these intrinsics require. `_mm_load_ps` reads 16 bytes from a `[f32; 4]` of
        // `node.bounds`, which starts at a multiple of 16 bytes from the 64-byte-aligned node,
        // so the pointer is valid and 16-byte aligned; `_mm_storeu_ps` writes 16 bytes to the
        // local `[f32; 4]` `t`, which needs no alignment.
        let mask = unsafe {
            let mut t0 = _mm_setzero_ps();
            let mut t1 = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let o = _mm_set1_ps(self.org[axis]);
                let inv = _mm_set1_ps(self.inv[axis]);
                let lo = _mm_load_ps(node.bounds[self.near[axis]].as_ptr());
                let hi = _mm_load_ps(node.bounds[self.far[axis]].as_ptr());
                let near = _mm_mul_ps(_mm_sub_ps(lo, o), inv);
                let far = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
                t0 = _mm_max_ps(near, t0);
                t1 = _mm_min_ps(far, t1);
            }
            let hit = _mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(FAR_SCALE)));
            _mm_storeu_ps(t.as_mut_ptr(), t0);
            _mm_movemask_ps(hit) as u32
        };
        (mask, t)
    }

    /// The four-wide test used by traversal: SSE2 on x86_64 (part of its baseline, so no runtime
    /// detection), the scalar loop elsewhere.
    #[inline(always)]
    pub(crate) fn hit4(&self, node: &QNode, t_max: f32) -> (u32, [f32; 4]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
        {
            self.hit4_sse(node, t_max)
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
        {
            self.hit4_scalar(node, t_max)
        }
    }
}

/// Sort key of a hit slot: entry distance in the high word, child code in the low one. Entry
/// distances are never NaN and at least zero (possibly `-0.0`, hence clearing the sign bit), so
/// their bits order like the values.
#[inline(always)]
fn key(t: f32, code: u32) -> u64 {
    (u64::from(t.to_bits() & 0x7FFF_FFFF) << 32) | u64::from(code)
}

#[inline(always)]
fn key_t(k: u64) -> f32 {
    f32::from_bits((k >> 32) as u32)
}

/// Sorting network for four keys, ascending.
#[inline(always)]
fn sort4(k: &mut [u64; 4]) {
    #[inline(always)]
    fn cswap(k: &mut [u64; 4], i: usize, j: usize) {
        let (a, b) = (k[i], k[j]);
        k[i] = a.min(b);
        k[j] = a.max(b);
    }
    cswap(k, 0, 1);
    cswap(k, 2, 3);
    cswap(k, 0, 2);
    cswap(k, 1, 3);
    cswap(k, 1, 2);
}

/// [`Order`](super::Order) as a const generic parameter.
pub(crate) const UNSORTED: u8 = 0;
pub(crate) const DISTANCE: u8 = 1;
pub(crate) const SPLIT_PLANE: u8 = 2;

/// Direction octant: bit `a` set when the direction is negative along axis `a` (`-0.0` counts
/// as negative, matching the slab test's choice of planes).
#[inline(always)]
pub(crate) fn octant(ray: &Ray) -> usize {
    usize::from(ray.dir.x.is_sign_negative())
        | usize::from(ray.dir.y.is_sign_negative()) << 1
        | usize::from(ray.dir.z.is_sign_negative()) << 2
}

/// Slots still to visit: child codes and, with the t-stack, their entry distances.
///
/// The arrays are left uninitialised: zeroing 2 KB per ray cost more than a short traversal.
struct Stack<const TSTACK: bool> {
    codes: [MaybeUninit<u32>; STACK_SIZE],
    ts: [MaybeUninit<f32>; STACK_SIZE],
    len: usize,
}

impl<const TSTACK: bool> Stack<TSTACK> {
    #[inline(always)]
    fn new() -> Self {
        Self {
            codes: [const { MaybeUninit::uninit() }; STACK_SIZE],
            ts: [const { MaybeUninit::uninit() }; STACK_SIZE],
            len: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, code: u32, t: f32) {
        self.codes[self.len].write(code);
        if TSTACK {
            self.ts[self.len].write(t);
        }
        self.len += 1;
    }

    /// The most recently pushed slot that may still hold something within `cull_t`.
    #[inline(always)]
    #[allow(unsafe_code)]
    fn pop(&mut self, cull_t: f32) -> Option<u32> {
        while self.len > 0 {
            self.len -= 1;
            // SAFETY: `push` wrote `codes[i]` (and `ts[i]` when `TSTACK`) for every `i < len`
            // before incrementing `len`, and nothing else changes `len` or the arrays.
            let (code, keep) = unsafe {
                (
                    self.codes[self.len].assume_init(),
                    !TSTACK || self.ts[self.len].assume_init() <= cull_t * FAR_SCALE,
                )
            };
            if keep {
                return Some(code);
            }
        }
        None
    }
}

impl Qbvh {
    /// The one traversal loop behind every query; `ANY_HIT` returns the first hit found,
    /// `ORDER` is one of [`UNSORTED`], [`DISTANCE`], [`SPLIT_PLANE`].
    ///
    /// Leaves are tested with [`Qbvh::test_leaf`], which keeps the rule of [`Closest`]: hits are
    /// tested against the caller's `t_max` and the closest kept with an exact `<`, so the
    /// answer does not depend on the order; boxes are culled against the closest hit so far.
    #[inline(always)]
    pub(crate) fn traverse<const ANY_HIT: bool, const ORDER: u8, const TSTACK: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        counter: &mut C,
    ) -> Option<Hit> {
        let nodes = &self.nodes[..];
        if nodes.is_empty() {
            return None;
        }
        let slab = Slab4::new(ray);
        counter.boxes(1);
        slab.hit_box(&self.bounds, t_max)?;
        let pre = RayPrecomp4::new(ray);
        let oct = octant(ray);

        let mut closest = Closest::new(t_max);
        let mut stack = Stack::<TSTACK>::new();
        let mut cur: u32 = 0;
        loop {
            if cur & LEAF_BIT != 0 {
                if self.test_leaf::<ANY_HIT, C>(&pre, cur, t_max, &mut closest, counter) {
                    return closest.hit;
                }
            } else {
                let node = &nodes[cur as usize];
                counter.boxes(node.occupied() as u64);
                let (mask, t) = slab.hit4(node, closest.cull_t);
                if mask != 0 {
                    if ORDER == DISTANCE {
                        let mut keys = [MISS; 4];
                        for lane in 0..4 {
                            if mask & (1 << lane) != 0 {
                                keys[lane] = key(t[lane], node.children[lane]);
                            }
                        }
                        sort4(&mut keys);
                        for &k in [keys[3], keys[2], keys[1]].iter() {
                            if k != MISS {
                                stack.push(k as u32, key_t(k));
                            }
                        }
                        cur = keys[0] as u32;
                    } else {
                        let order = if ORDER == SPLIT_PLANE {
                            node.orders[oct]
                        } else {
                            IDENTITY_ORDER
                        };
                        // Hit slots by rank (bit r: the r-th nearest slot was hit). The
                        // nearest is visited next, the others pushed far to near.
                        let slot = |rank: u32| usize::from((order >> (2 * rank)) & 3);
                        let ranks =
                            (0..4).fold(0u32, |r, rank| r | (((mask >> slot(rank)) & 1) << rank));
                        let nearest = slot(ranks.trailing_zeros());
                        let mut rest = ranks & (ranks - 1);
                        while rest != 0 {
                            let rank = 31 - rest.leading_zeros();
                            rest &= !(1 << rank);
                            let s = slot(rank);
                            stack.push(node.children[s], t[s]);
                        }
                        cur = node.children[nearest];
                    }
                    // Empty slots have inverted boxes and never hit, so `cur` is a real child.
                    debug_assert_ne!(cur, EMPTY);
                    continue;
                }
            }
            match stack.pop(closest.cull_t) {
                Some(code) => cur = code,
                None => return closest.hit,
            }
        }
    }

    /// Tests the triangles of leaf `code`; returns true when an any-hit query has its answer.
    #[inline(always)]
    pub(crate) fn test_leaf<const ANY_HIT: bool, C: Counter>(
        &self,
        pre: &RayPrecomp4,
        code: u32,
        t_max: f32,
        closest: &mut Closest,
        counter: &mut C,
    ) -> bool {
        let (first, count) = leaf_parts(code);
        counter.leaf();
        counter.triangles(count as u64);
        if self.options.intersection != TriangleTest::Watertight {
            return self.test_leaf_crack_free::<ANY_HIT>(pre, first, count, t_max, closest);
        }
        for p in first..first + count.div_ceil(4) {
            let h = intersect4(pre, &self.packets[p], t_max);
            if h.mask == 0 {
                continue;
            }
            let ids = &self.packet_ids[p];
            for (lane, &id) in ids.iter().enumerate() {
                if h.mask & (1 << lane) != 0
                    && closest.offer::<ANY_HIT>(h.t[lane], id, h.b1[lane], h.b2[lane])
                {
                    return true;
                }
            }
        }
        false
    }

    /// The leaf test with the thesis' crack-free triangle tests, one triangle at a time (they
    /// exist for comparison, not speed).
    #[inline(never)]
    fn test_leaf_crack_free<const ANY_HIT: bool>(
        &self,
        pre: &RayPrecomp4,
        first: usize,
        count: usize,
        t_max: f32,
        closest: &mut Closest,
    ) -> bool {
        let sub = SubdivRay::new(&pre.ray);
        for slot in 4 * first..4 * first + count {
            let (tri, id) = self.reference(slot);
            let hit = match self.options.intersection {
                TriangleTest::Hybrid => intersect_hybrid(&sub, &tri, t_max),
                _ => intersect_subdivision(&sub, &tri, t_max),
            };
            if let Some(h) = hit {
                if closest.offer::<ANY_HIT>(h.t, id, h.b1, h.b2) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qbvh::node::{leaf_code, NO_AXES, NO_PARENT};
    use glam::Vec3;

    #[test]
    fn sort4_sorts() {
        let mut k = [5, MISS, 1, 3];
        sort4(&mut k);
        assert_eq!(k, [1, 3, 5, MISS]);
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // slots index several arrays
    fn sse_and_scalar_agree() {
        let mut s = 0x1234_5678u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            // Few distinct values so that rays often lie in face planes.
            (s % 9) as f32 * 0.25 - 1.0
        };
        for _ in 0..20_000 {
            let mut node = QNode::new(NO_PARENT, NO_AXES);
            for slot in 0..3 {
                let a = Vec3::new(rnd(), rnd(), rnd());
                let b = Vec3::new(rnd(), rnd(), rnd());
                node.set(slot, Aabb::new(a.min(b), a.max(b)), leaf_code(slot, 1));
            }
            let mut d = Vec3::new(rnd(), rnd(), rnd());
            for c in 0..3 {
                if d[c] == 0.0 && rnd() < 0.0 {
                    d[c] = -0.0;
                }
            }
            if d == Vec3::ZERO {
                d = Vec3::X;
            }
            let ray = Ray::new(Vec3::new(rnd(), rnd(), rnd()) * 2.0, d);
            let slab = Slab4::new(&ray);
            for t_max in [f32::INFINITY, 1.0] {
                let (m, t) = slab.hit4_scalar(&node, t_max);
                assert_eq!(m & 8, 0, "empty slot hit");
                for slot in 0..3 {
                    let want = slab.hit_box(&node.child_aabb(slot), t_max);
                    assert_eq!(want.is_some(), m & (1 << slot) != 0);
                    if let Some(w) = want {
                        assert_eq!(w, t[slot]);
                    }
                }
                #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
                {
                    let (ms, ts) = slab.hit4_sse(&node, t_max);
                    assert_eq!(ms, m);
                    for slot in 0..4 {
                        if m & (1 << slot) != 0 {
                            assert_eq!(ts[slot], t[slot]);
                        }
                    }
                }
            }
        }
    }
}
