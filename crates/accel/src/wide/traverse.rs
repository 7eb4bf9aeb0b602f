//! Stack traversal of a wide BVH with a robust four- or eight-wide slab test, in three child
//! orders, with or without entry distances on the stack.

use super::bvh::{slot_of, Isa, WideNode};
use super::qbvh_node::{leaf_parts, EMPTY, LEAF_BIT};
#[cfg(target_arch = "x86_64")]
use super::tri4::intersect8_avx2;
use super::tri4::{intersect4, RayPrecomp4};
use super::{TriangleTest, WideBvh};
use crate::crack_free::{intersect_hybrid, intersect_subdivision, SubdivRay};
use crate::traversal::{Closest, Counter, Stack, FAR_SCALE};
use rt_core::{Aabb, Hit, Ray};

/// Deepest node the traversal stack supports: the binary tree's depth bound (64) plus the
/// levels that split over-long leaves (at most 12 for 2^27 triangles).
pub(crate) const MAX_DEPTH: usize = 80;
/// Traversal pushes at most seven entries (eight-wide nodes) per inner node on the current path.
pub(crate) const STACK_SIZE: usize = 7 * MAX_DEPTH + 1;

/// Key of a missed or empty slot; sorts after every hit.
const MISS: u64 = u64::MAX;

/// Per-ray constants of the slab test. (`pub` only so that [`WideNode`] may name it; the module
/// is private.)
#[derive(Clone, Copy, Debug)]
pub struct Slab {
    org: [f32; 3],
    /// `1 / dir`; a zero component of either sign becomes an infinity of that sign.
    inv: [f32; 3],
    /// Plane index (into [`QNode`]'s `bounds`) of the near and far plane per axis, chosen by the
    /// sign bit of `inv` so that `-0.0` goes with `-inf`.
    near: [usize; 3],
    far: [usize; 3],
    /// `near` and `far` as float offsets into an eight-wide node's `bounds` (`8 * row`): the
    /// AVX2 test's loads then scale a register instead of shifting a reloaded index.
    near8: [usize; 3],
    far8: [usize; 3],
}

impl Slab {
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        let inv = ray.dir.recip().to_array();
        let neg = inv.map(|x| x.is_sign_negative() as usize);
        let near = [0, 1, 2].map(|a| a + 3 * neg[a]);
        let far = [0, 1, 2].map(|a| a + 3 - 3 * neg[a]);
        Self {
            org: ray.origin.to_array(),
            inv,
            near,
            far,
            near8: near.map(|r| 8 * r),
            far8: far.map(|r| 8 * r),
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

    /// Entry distances into the `W` boxes of `bounds` (structure of arrays, as in
    /// [`QNode`](super::QNode)) and the mask of boxes hit, one lane at a time. A NaN slab distance (0 * inf: the ray lies in a face plane) leaves the interval
    /// alone, because `f32::max`/`min` return the non-NaN operand.
    #[cfg_attr(
        all(target_arch = "x86_64", target_feature = "sse2"),
        allow(dead_code) // used by the tests only
    )]
    #[inline(always)]
    pub(crate) fn hit_scalar<const W: usize>(
        &self,
        bounds: &[[f32; W]; 6],
        t_max: f32,
    ) -> (u32, [f32; W]) {
        let mut mask = 0;
        let mut t = [0.0f32; W];
        for (lane, t_lane) in t.iter_mut().enumerate() {
            let mut t0 = 0.0f32;
            let mut t1 = t_max;
            for axis in 0..3 {
                let o = self.org[axis];
                let near = (bounds[self.near[axis]][lane] - o) * self.inv[axis];
                let far = (bounds[self.far[axis]][lane] - o) * self.inv[axis];
                t0 = t0.max(near);
                t1 = t1.min(far);
            }
            *t_lane = t0;
            mask |= u32::from(t0 <= t1 * FAR_SCALE) << lane;
        }
        (mask, t)
    }

    /// [`Slab::hit_scalar`] over four lanes with SSE2: lanes `lane0..lane0 + 4` of the
    /// `W`-wide `bounds`. `maxps`/`minps` return their second operand when the comparison is
    /// unordered, so the slab distance goes first and a NaN leaves the running interval alone,
    /// exactly like the scalar code.
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    #[allow(unsafe_code)]
    #[inline(always)]
    fn hit4_sse<const W: usize>(
        &self,
        bounds: &[[f32; W]; 6],
        lane0: usize,
        t_max: f32,
    ) -> (u32, [f32; 4]) {
        use std::arch::x86_64::*;
        assert!(lane0 + 4 <= W && lane0.is_multiple_of(4));
        let mut t = [0.0f32; 4];
        // SAFETY: the `cfg` guarantees SSE and SSE2 are enabled for the whole build, which is
        // all these intrinsics require. `_mm_load_ps` reads lanes `lane0..lane0 + 4` (in range
        // by the assertion) of a row of `bounds`; node rows are arrays of 4 or 8 `f32` starting
        // at multiples of 16 bytes in a 64-byte-aligned node, and `lane0` is a multiple of 4, so
        // the pointer is 16-byte aligned; `_mm_storeu_ps` writes 16 bytes to the local `t`.
        let mask = unsafe {
            let mut t0 = _mm_setzero_ps();
            let mut t1 = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let o = _mm_set1_ps(self.org[axis]);
                let inv = _mm_set1_ps(self.inv[axis]);
                // `near`/`far` indices are below 6 (see `Slab::new`), so the rows exist.
                let lo = _mm_load_ps(bounds.get_unchecked(self.near[axis]).as_ptr().add(lane0));
                let hi = _mm_load_ps(bounds.get_unchecked(self.far[axis]).as_ptr().add(lane0));
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
    pub(crate) fn hit4(&self, bounds: &[[f32; 4]; 6], t_max: f32) -> (u32, [f32; 4]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
        {
            self.hit4_sse(bounds, 0, t_max)
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
        {
            self.hit_scalar(bounds, t_max)
        }
    }

    /// The eight-wide test without AVX2: two SSE2 halves on x86_64, the scalar loop elsewhere.
    #[inline(always)]
    pub(crate) fn hit8(&self, bounds: &[[f32; 8]; 6], t_max: f32) -> (u32, [f32; 8]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
        {
            let (m0, t0) = self.hit4_sse(bounds, 0, t_max);
            let (m1, t1) = self.hit4_sse(bounds, 4, t_max);
            let mut t = [0.0; 8];
            t[..4].copy_from_slice(&t0);
            t[4..].copy_from_slice(&t1);
            (m0 | (m1 << 4), t)
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
        {
            self.hit_scalar(bounds, t_max)
        }
    }

    /// [`Slab::hit_scalar`] over eight lanes with one AVX2 register per plane, with the same
    /// operand order (and so the same NaN handling) as the SSE2 test.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    #[inline]
    pub(crate) unsafe fn hit8_avx2(&self, bounds: &[[f32; 8]; 6], t_max: f32) -> (u32, [f32; 8]) {
        use std::arch::x86_64::*;
        let mut t = [0.0f32; 8];
        let mut t0 = _mm256_setzero_ps();
        let mut t1 = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let o = _mm256_set1_ps(self.org[axis]);
            let inv = _mm256_set1_ps(self.inv[axis]);
            // SAFETY: `Slab::new` makes every `near`/`far` index `a` or `a + 3` with `a < 3`, and
            // `near8`/`far8` eight times those, so both rows exist; each row is an `[f32; 8]`,
            // 32 bytes, read whole without alignment needs. (Unchecked: the bounds checks cost
            // a dozen instructions a node.)
            let (lo, hi) = unsafe {
                let b = bounds.as_ptr().cast::<f32>();
                (
                    _mm256_loadu_ps(b.add(self.near8[axis])),
                    _mm256_loadu_ps(b.add(self.far8[axis])),
                )
            };
            let near = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
            let far = _mm256_mul_ps(_mm256_sub_ps(hi, o), inv);
            t0 = _mm256_max_ps(near, t0);
            t1 = _mm256_min_ps(far, t1);
        }
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t0, _mm256_mul_ps(t1, _mm256_set1_ps(FAR_SCALE)));
        // SAFETY: writes 32 bytes to the local `[f32; 8]`, which needs no alignment.
        unsafe { _mm256_storeu_ps(t.as_mut_ptr(), t0) };
        (_mm256_movemask_ps(hit) as u32, t)
    }
}

/// A ray set up for traversal: the slab test's constants, the direction octant and, once a
/// leaf is reached, the triangle test's. A two-level structure keeps one per object-space ray,
/// so that consecutive entry points of one placement do not redo the setup (it showed up as
/// a store-forwarding stall per entry, ~5 % of a clustered trace).
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    ray: Ray,
    slab: Slab,
    oct: usize,
    /// Made at the first leaf: many rays (most camera rays past the silhouette) never reach
    /// one, and the shear costs a division and a dozen data-dependent selections.
    pre: Option<RayPrecomp4>,
}

impl PreparedRay {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        Self {
            ray: *ray,
            slab: Slab::new(ray),
            oct: octant(ray),
            pre: None,
        }
    }

    /// The triangle test's set-up, made on first use.
    #[inline(always)]
    pub(crate) fn precomp(&mut self) -> &RayPrecomp4 {
        let ray = &self.ray;
        self.pre.get_or_insert_with(|| RayPrecomp4::new(ray))
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

impl<N: WideNode> WideBvh<N> {
    /// The one traversal loop behind every query; `ANY_HIT` returns the first hit found,
    /// `ORDER` is one of [`UNSORTED`], [`DISTANCE`], [`SPLIT_PLANE`]; `isa` picks the box test.
    ///
    /// Leaves are tested with [`WideBvh::test_leaf`], which keeps the rule of [`Closest`]: hits
    /// are tested against the caller's `t_max` and the closest kept with an exact `<`, so the
    /// answer does not depend on the order; boxes are culled against the closest hit so far.
    #[inline(always)]
    pub(crate) fn traverse<
        const ANY_HIT: bool,
        const ORDER: u8,
        const TSTACK: bool,
        I: Isa,
        C: Counter,
    >(
        &self,
        start: u32,
        prepared: &mut PreparedRay,
        t_max: f32,
        isa: I,
        counter: &mut C,
    ) -> Option<Hit> {
        let PreparedRay {
            ref ray,
            ref slab,
            oct,
            ref mut pre,
        } = *prepared;
        let nodes = &self.nodes[..];
        // A NaN in the ray makes every slab test pass, empty slots included, and the descent
        // then never ends (it overflowed the stack); such a ray hits nothing.
        if nodes.is_empty() || !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        // The eight boxes of the root node are tested next anyway, as cheaply as the scene's
        // box; the four-wide node keeps the test (and its count).
        if N::WIDTH < 8 && start == 0 {
            counter.boxes(1);
            slab.hit_box(&self.bounds, t_max)?;
        }

        let mut closest = Closest::new(t_max);
        let mut stack = Stack::<STACK_SIZE, TSTACK>::new();
        // The root, or an entry point of a clustered top level (a node or a leaf).
        let mut cur: u32 = start;
        loop {
            if cur & LEAF_BIT != 0 {
                if pre.is_none() {
                    *pre = Some(RayPrecomp4::new(ray));
                }
                let Some(pre) = pre else {
                    unreachable!("set above")
                };
                if self.test_leaf::<ANY_HIT, I, C>(pre, cur, t_max, &mut closest, isa, counter) {
                    return closest.hit;
                }
            } else {
                let node = &nodes[cur as usize];
                counter.boxes(node.occupied() as u64);
                let (mask, t) = node.hit(slab, closest.cull_t, isa);
                if mask != 0 {
                    if ORDER == DISTANCE && N::WIDTH == 4 {
                        let mut keys = [MISS; 4];
                        for (lane, k) in keys.iter_mut().enumerate() {
                            if mask & (1 << lane) != 0 {
                                *k = key(t[lane], node.code(lane));
                            }
                        }
                        sort4(&mut keys);
                        for &k in [keys[3], keys[2], keys[1]].iter() {
                            if k != MISS {
                                stack.push(k as u32, key_t(k));
                            }
                        }
                        cur = keys[0] as u32;
                    } else if ORDER == DISTANCE {
                        // Most nodes have one or two hit slots (Embree's traverser has the
                        // same two fast paths); more are insertion-sorted.
                        let first = mask.trailing_zeros() as usize;
                        let rest = mask & (mask - 1);
                        if rest == 0 {
                            cur = node.code(first);
                        } else if ANY_HIT {
                            // Any occluder will do, so the order is not worth sorting for
                            // (Embree's any-hit traverser does not sort either).
                            let mut rest = rest;
                            while rest != 0 {
                                let lane = rest.trailing_zeros() as usize;
                                rest &= rest - 1;
                                self.prefetch(node.code(lane));
                                stack.push(node.code(lane), t[lane]);
                            }
                            cur = node.code(first);
                        } else if rest & (rest - 1) == 0 {
                            let second = rest.trailing_zeros() as usize;
                            let a = key(t[first], node.code(first));
                            let b = key(t[second], node.code(second));
                            let (near, far) = if a < b { (a, b) } else { (b, a) };
                            self.prefetch(far as u32);
                            stack.push(far as u32, key_t(far));
                            cur = near as u32;
                        } else {
                            let mut keys = [MISS; 8];
                            let mut n = 0;
                            let mut rest = mask;
                            while rest != 0 {
                                let lane = rest.trailing_zeros() as usize;
                                rest &= rest - 1;
                                let k = key(t[lane], node.code(lane));
                                let mut i = n;
                                while i > 0 && keys[i - 1] > k {
                                    keys[i] = keys[i - 1];
                                    i -= 1;
                                }
                                keys[i] = k;
                                n += 1;
                            }
                            for &k in keys[1..n].iter().rev() {
                                self.prefetch(k as u32);
                                stack.push(k as u32, key_t(k));
                            }
                            cur = keys[0] as u32;
                        }
                    } else {
                        let order = if ORDER == SPLIT_PLANE {
                            node.order(oct)
                        } else {
                            N::IDENTITY_ORDER
                        };
                        // Hit slots by rank (bit r: the r-th nearest slot was hit). The
                        // nearest is visited next, the others pushed far to near.
                        let slot = |rank: u32| slot_of(order, N::ORDER_BITS, rank as usize);
                        let ranks = (0..N::WIDTH as u32)
                            .fold(0u32, |r, rank| r | (((mask >> slot(rank)) & 1) << rank));
                        let nearest = slot(ranks.trailing_zeros());
                        let mut rest = ranks & (ranks - 1);
                        while rest != 0 {
                            let rank = 31 - rest.leading_zeros();
                            rest &= !(1 << rank);
                            let s = slot(rank);
                            stack.push(node.code(s), t[s]);
                        }
                        cur = node.code(nearest);
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

    /// Starts fetching the memory of child `code` (its node, or its leaf's packets) into the
    /// cache, so that a child pushed now is there when it is popped: the loads of the nodes on
    /// one path depend on each other, the fetches of pushed siblings need not wait (Embree
    /// prefetches hit children likewise).
    #[inline(always)]
    pub(crate) fn prefetch(&self, code: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (ptr, bytes) = if code & LEAF_BIT != 0 {
                let (first, count) = leaf_parts(code);
                let p = self.packets.as_ptr().wrapping_add(first);
                (
                    p.cast::<i8>(),
                    count.div_ceil(4) * std::mem::size_of::<super::Tri4>(),
                )
            } else {
                let p = self.nodes.as_ptr().wrapping_add(code as usize);
                (p.cast::<i8>(), std::mem::size_of::<N>())
            };
            let mut off = 0;
            while off < bytes.min(256) {
                // SAFETY: prefetching has no architectural effect and never faults, whatever
                // the address; SSE is part of the x86_64 baseline.
                #[allow(unsafe_code)]
                unsafe {
                    _mm_prefetch::<_MM_HINT_T0>(ptr.wrapping_add(off))
                };
                off += 64;
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = code;
    }

    /// Tests the triangles of leaf `code`; returns true when an any-hit query has its answer.
    /// With AVX2, packets are tested two at a time, eight lanes wide; hits are offered in the
    /// same order either way.
    #[inline(always)]
    pub(crate) fn test_leaf<const ANY_HIT: bool, I: Isa, C: Counter>(
        &self,
        pre: &RayPrecomp4,
        code: u32,
        t_max: f32,
        closest: &mut Closest,
        _isa: I,
        counter: &mut C,
    ) -> bool {
        let (first, count) = leaf_parts(code);
        counter.leaf();
        counter.triangles(count as u64);
        if self.options.intersection != TriangleTest::Watertight {
            return self.test_leaf_crack_free::<ANY_HIT>(pre, first, count, t_max, closest);
        }
        let (mut p, end) = (first, first + count.div_ceil(4));
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 {
            while p < end {
                // An odd last packet fills both halves and its upper lanes are ignored: one
                // kernel for every pass, not a four-wide one after the eight-wide ones.
                let (q, valid) = if p + 1 < end {
                    (p + 1, 0xFF)
                } else {
                    (p, 0x0F)
                };
                // SAFETY: a value of an `Isa` whose `AVX2` is true is made only by
                // `Avx2::detect`, after run-time detection found AVX2.
                #[allow(unsafe_code)]
                let h = unsafe { intersect8_avx2(pre, &self.packets[p], &self.packets[q], t_max) };
                if let Some(h) = h {
                    let mut mask = h.mask & valid;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let id = self.packet_ids[p + lane / 4][lane % 4];
                        if closest.offer::<ANY_HIT>(h.t[lane], id, h.b1[lane], h.b2[lane]) {
                            return true;
                        }
                    }
                }
                p += 2;
            }
        }
        for p in p..end {
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
    use crate::wide::bvh::WideNode;
    use crate::wide::bvh8_node::Node8;
    use crate::wide::qbvh_node::{leaf_code, QNode, NO_PARENT};
    use glam::Vec3;

    #[test]
    fn sort4_sorts() {
        let mut k = [5, MISS, 1, 3];
        sort4(&mut k);
        assert_eq!(k, [1, 3, 5, MISS]);
    }

    /// Compares a SIMD box test's mask and entry distances with the scalar test's.
    fn same_hits<const W: usize>(want: (u32, [f32; W]), got: (u32, [f32; W])) {
        assert_eq!(got.0, want.0);
        for slot in 0..W {
            if want.0 & (1 << slot) != 0 {
                assert_eq!(got.1[slot], want.1[slot]);
            }
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // slots index several arrays
    fn simd_and_scalar_box_tests_agree() {
        let mut s = 0x1234_5678u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            // Few distinct values so that rays often lie in face planes.
            (s % 9) as f32 * 0.25 - 1.0
        };
        let avx2 = crate::wide::Avx2::detect();
        for _ in 0..20_000 {
            // Slot 3 of the four-wide node and slot 7 of the eight-wide one stay empty.
            let mut node = QNode::empty(NO_PARENT);
            let mut node8 = Node8::empty(NO_PARENT);
            for slot in 0..7 {
                let a = Vec3::new(rnd(), rnd(), rnd());
                let b = Vec3::new(rnd(), rnd(), rnd());
                let bounds = Aabb::new(a.min(b), a.max(b));
                if slot < 3 {
                    node.set(slot, bounds, leaf_code(slot, 1));
                }
                node8.set(slot, bounds, leaf_code(slot, 1));
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
            let slab = Slab::new(&ray);
            for t_max in [f32::INFINITY, 1.0] {
                let (m, t) = slab.hit_scalar(&node.bounds, t_max);
                assert_eq!(m & 8, 0, "empty slot hit");
                for slot in 0..3 {
                    let want = slab.hit_box(&node.child_aabb(slot), t_max);
                    assert_eq!(want.is_some(), m & (1 << slot) != 0);
                    if let Some(w) = want {
                        assert_eq!(w, t[slot]);
                    }
                }
                same_hits((m, t), slab.hit4(&node.bounds, t_max));
                let want8 = slab.hit_scalar(&node8.bounds, t_max);
                assert_eq!(want8.0 & 0x80, 0, "empty slot hit");
                assert_eq!(want8.0 & 7, m & 7);
                same_hits(want8, slab.hit8(&node8.bounds, t_max));
                #[cfg(target_arch = "x86_64")]
                if avx2.is_some() {
                    // SAFETY: `Avx2::detect` found AVX2.
                    #[allow(unsafe_code)]
                    same_hits(want8, unsafe { slab.hit8_avx2(&node8.bounds, t_max) });
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = avx2;
    }
}
