//! Packets of eight rays through a [`Bvh8`](super::Bvh8) with AVX2, for coherent ray streams
//! (a camera's rays of neighbouring pixels, shadow rays toward one light).
//!
//! The packet visits a node when any of its rays (a lane mask) entered it, and tests the eight
//! rays against one child box at a time, the rays in the eight lanes of a register: the node's
//! memory and the stack work are shared by the packet, and every lane computes exactly the
//! slab test of [`Slab::hit8_avx2`](super::traverse::Slab) for its own ray (each ray's near
//! plane is picked by the sign of its `1 / dir`, the same operations in the same order), so a
//! ray enters exactly the boxes its single-ray traversal would enter. Leaves are tested ray by
//! ray with the single-ray leaf test. Any-hit answers are thus the single-ray answers; closest
//! hits too, because [`Closest`] keeps the minimum of (distance, triangle index) whatever the
//! order leaves are visited in.

use super::bvh::Avx2;
use super::bvh8_node::Node8;
use super::qbvh_node::{EMPTY, LEAF_BIT};
use super::traverse::{octant, PreparedRay, STACK_SIZE};
use super::WideBvh;
use crate::traversal::{Closest, NoCount, FAR_SCALE};
use rt_core::{Hit, Ray};
use std::arch::x86_64::*;

/// Rays per packet.
pub(crate) const PACKET: usize = 8;

/// One slot of the packet stack: a child code, the lanes that entered its box and (closest
/// hit) the least of their entry distances.
#[derive(Clone, Copy, Default)]
pub(crate) struct Entry {
    code: u32,
    mask: u32,
    t: f32,
}

/// The packet stack, made once per stream.
pub(crate) type PacketStack = [Entry; STACK_SIZE];

/// Smallest lane of `v`.
#[target_feature(enable = "avx2")]
#[inline]
fn hmin(v: __m256) -> f32 {
    let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
    let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    let m = _mm_min_ss(m, _mm_shuffle_ps::<1>(m, m));
    _mm_cvtss_f32(m)
}

/// The eight floats of `a` in a register.
#[target_feature(enable = "avx2")]
#[inline]
#[allow(unsafe_code)]
fn load(a: &[f32; 8]) -> __m256 {
    // SAFETY: reads the 32 bytes of `a`, unaligned.
    unsafe { _mm256_loadu_ps(a.as_ptr()) }
}

/// All bits of the lanes whose bit is set in `mask`.
#[target_feature(enable = "avx2")]
#[inline]
fn lanes(mask: u32) -> __m256 {
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let m = _mm256_and_si256(_mm256_set1_epi32(mask as i32), bits);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(m, bits))
}

/// True if the rays all point into one octant (the sign bits of their directions agree):
/// coherent enough for a packet.
#[inline]
pub(crate) fn same_octant(rays: &[Ray]) -> bool {
    let sign = |r: &Ray| super::traverse::octant(r);
    rays.iter().all(|r| sign(r) == sign(&rays[0]))
}

impl WideBvh<Node8> {
    /// Traces `rays` (one to eight, all in one direction octant: [`same_octant`]) as one
    /// packet: the closest hit of each within its `t_max`, or with `ANY_HIT` any hit (`Some`
    /// with unspecified fields for an occluded ray).
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2 (`_avx2` is the proof).
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    pub(crate) unsafe fn packet8<const ANY_HIT: bool>(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        stack: &mut PacketStack,
        avx2: Avx2,
    ) -> [Option<Hit>; PACKET] {
        let n = rays.len().min(t_max.len()).min(PACKET);
        let nodes = &self.nodes[..];
        let mut closest: [Closest; PACKET] =
            std::array::from_fn(|i| Closest::new(if i < n { t_max[i] } else { 0.0 }));
        if nodes.is_empty() || n == 0 {
            return closest.map(|c| c.hit);
        }
        debug_assert!(same_octant(&rays[..n]));
        // Lanes of rays still looking; the others (missing, or with a NaN or infinity, which
        // hit nothing as in the single-ray traversal) never hit a box: their culling distance
        // is -inf.
        let mut live = 0u32;
        let mut org = [[0.0f32; PACKET]; 3];
        let mut inv = [[0.0f32; PACKET]; 3];
        let mut cull = [f32::NEG_INFINITY; PACKET];
        for (i, r) in rays[..n].iter().enumerate() {
            if !(r.origin.is_finite() && r.dir.is_finite()) {
                continue;
            }
            live |= 1 << i;
            // As `Slab::new`: `1 / dir` per component.
            let rcp = r.dir.recip();
            for a in 0..3 {
                org[a][i] = r.origin[a];
                inv[a][i] = rcp[a];
            }
            cull[i] = closest[i].cull_t;
        }
        let o = org.map(|x| load(&x));
        let d = inv.map(|x| load(&x));
        // The rays share an octant (the caller checked): the near plane of axis `a` is the
        // box's max (row `a + 3`) where the direction is negative (its sign bit, so -0.0 goes
        // with the -inf of `1 / -0.0`), as in `Slab::new`. Rays with a NaN or infinity are
        // inactive, whatever planes they get.
        let oct = octant(&rays[0]);
        let neg = |a: usize| (oct >> a) & 1;
        let near_row: [usize; 3] = std::array::from_fn(|a| (a + 3 * neg(a)).min(5));
        let far_row: [usize; 3] = std::array::from_fn(|a| (a + 3 - 3 * neg(a)).min(5));
        let far_scale = _mm256_set1_ps(FAR_SCALE);
        let inf = _mm256_set1_ps(f32::INFINITY);
        let mut prepared: [Option<PreparedRay>; PACKET] = [None; PACKET];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (0u32, live);
        'trace: loop {
            if cur & LEAF_BIT != 0 {
                let mut m = mask;
                while m != 0 {
                    let r = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let p = prepared[r]
                        .get_or_insert_with(|| PreparedRay::new(&rays[r]))
                        .precomp();
                    let c = &mut closest[r];
                    if self.test_leaf::<ANY_HIT, _, _>(p, cur, t_max[r], c, avx2, &mut NoCount) {
                        live &= !(1 << r);
                        cull[r] = f32::NEG_INFINITY;
                    } else {
                        cull[r] = c.cull_t;
                    }
                }
                if ANY_HIT && live == 0 {
                    break 'trace;
                }
            } else {
                let node = &nodes[cur as usize];
                let entering = lanes(mask);
                let t_cull = load(&cull);
                let mut hit = [0u32; 8];
                let mut near = [0.0f32; 8];
                let mut any = 0u32;
                for slot in 0..8 {
                    if node.children[slot] == EMPTY {
                        continue;
                    }
                    // `Slab::hit8_avx2` for one box and eight rays, whose shared octant picks
                    // the near and far planes as `Slab::new` does for each of them.
                    let mut t0 = _mm256_setzero_ps();
                    let mut t1 = t_cull;
                    for a in 0..3 {
                        let near = _mm256_set1_ps(node.bounds[near_row[a]][slot]);
                        let far = _mm256_set1_ps(node.bounds[far_row[a]][slot]);
                        let t_near = _mm256_mul_ps(_mm256_sub_ps(near, o[a]), d[a]);
                        let t_far = _mm256_mul_ps(_mm256_sub_ps(far, o[a]), d[a]);
                        t0 = _mm256_max_ps(t_near, t0);
                        t1 = _mm256_min_ps(t_far, t1);
                    }
                    let hits = _mm256_and_ps(
                        _mm256_cmp_ps::<_CMP_LE_OQ>(t0, _mm256_mul_ps(t1, far_scale)),
                        entering,
                    );
                    let h = _mm256_movemask_ps(hits) as u32;
                    if h != 0 {
                        hit[slot] = h;
                        any |= 1 << slot;
                        if !ANY_HIT {
                            near[slot] = hmin(_mm256_blendv_ps(inf, t0, hits));
                        }
                    }
                }
                if any != 0 {
                    let first = any.trailing_zeros() as usize;
                    let mut next = first;
                    if ANY_HIT {
                        // Any occluder will do: no order (as the single-ray any-hit query).
                        let mut rest = any & (any - 1);
                        while rest != 0 {
                            let s = rest.trailing_zeros() as usize;
                            rest &= rest - 1;
                            self.prefetch(node.children[s]);
                            stack[sp] = Entry {
                                code: node.children[s],
                                mask: hit[s],
                                t: 0.0,
                            };
                            sp += 1;
                        }
                    } else {
                        // Nearest (by the packet's least entry distance) next, the others
                        // pushed far to near.
                        let mut order = [0usize; 8];
                        let mut k = 0;
                        let mut rest = any;
                        while rest != 0 {
                            let s = rest.trailing_zeros() as usize;
                            rest &= rest - 1;
                            let mut i = k;
                            while i > 0 && near[order[i - 1]] > near[s] {
                                order[i] = order[i - 1];
                                i -= 1;
                            }
                            order[i] = s;
                            k += 1;
                        }
                        for &s in order[1..k].iter().rev() {
                            self.prefetch(node.children[s]);
                            stack[sp] = Entry {
                                code: node.children[s],
                                mask: hit[s],
                                t: near[s],
                            };
                            sp += 1;
                        }
                        next = order[0];
                    }
                    cur = node.children[next];
                    mask = hit[next];
                    continue 'trace;
                }
            }
            // Pop the next slot some live lane may still need: with closest hits, lanes whose
            // hit so far is nearer than every entry distance of the slot are dropped.
            loop {
                if sp == 0 {
                    break 'trace;
                }
                sp -= 1;
                let e = stack[sp];
                let mut m = e.mask & live;
                if !ANY_HIT && m != 0 {
                    let beyond = _mm256_cmp_ps::<_CMP_LE_OQ>(
                        _mm256_set1_ps(e.t),
                        _mm256_mul_ps(load(&cull), far_scale),
                    );
                    m &= _mm256_movemask_ps(beyond) as u32;
                }
                if m != 0 {
                    cur = e.code;
                    mask = m;
                    break;
                }
            }
        }
        closest.map(|c| c.hit)
    }
}
