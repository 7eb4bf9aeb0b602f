//! Up to eight triangles of a heap tested against one ray at once, gathered straight from the
//! triangle array (IOSP stores nothing else, so there are no precomputed packets to load).
//!
//! The heap traversal uses this at the bottom of the tree, where a node's own two triangles and
//! its children's four sit at known slots: testing the six together costs less than the two
//! child slab tests plus the scalar triangle tests of the children entered (see the module
//! doc's deviations). Each lane performs exactly the operations of
//! [`rt_core::triangle::intersect_triangle`] (the QBVH's [`watertight_lanes!`] kernel), so
//! answers are unchanged bit for bit.

use crate::traversal::{Closest, Counter};
use crate::wide::tri4::RayPrecomp4;
use crate::wide::Avx2;
use glam::Vec3;
use rt_core::triangle::intersect_triangle;

/// Lanes per test.
pub(crate) const LANES: usize = 8;

/// Gathers index floats as `i32` offsets from the start of the triangle array: 9 floats a
/// triangle, so heaps up to this many triangles can be gathered; larger ones test lane by lane.
const MAX_GATHER_TRIANGLES: usize = (i32::MAX as usize) / 9 - 1;

/// How a heap's slot groups are tested: eight-wide AVX2 when the CPU has it (detected once
/// per build), else one triangle at a time.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlotTest {
    avx2: Option<Avx2>,
}

impl SlotTest {
    /// The widest test this CPU runs.
    pub(crate) fn detect() -> Self {
        Self {
            avx2: Avx2::detect(),
        }
    }

    /// Tests the triangles at `slots[..count]` of `tris` (lanes from `count` on must repeat a
    /// valid slot: they are tested too, and a repeated triangle only ties) and offers the hits
    /// to `closest` as prims `offset + slot`, in lane order. Returns true when an any-hit query
    /// has its answer.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run<const ANY_HIT: bool, C: Counter>(
        self,
        pre: &RayPrecomp4,
        tris: &[[Vec3; 3]],
        offset: u32,
        slots: &[u32; LANES],
        count: usize,
        t_max: f32,
        closest: &mut Closest,
        counter: &mut C,
    ) -> bool {
        counter.triangles(count as u64);
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            if tris.len() <= MAX_GATHER_TRIANGLES {
                let h = gather8(avx2, pre, tris, slots, t_max);
                let mut mask = h.mask & ((1u32 << count) - 1);
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let prim = offset + slots[lane];
                    if closest.offer::<ANY_HIT>(h.t[lane], prim, h.b1[lane], h.b2[lane]) {
                        return true;
                    }
                }
                return false;
            }
        }
        for &s in &slots[..count] {
            if let Some(h) = intersect_triangle(&pre.scalar, &tris[s as usize], t_max) {
                if closest.offer::<ANY_HIT>(h.t, offset + s, h.b1, h.b2) {
                    return true;
                }
            }
        }
        false
    }
}

/// Hits of the eight lanes (`mask` bit per lane; `t`, `b1`, `b2` meaningful where set).
#[cfg(target_arch = "x86_64")]
struct Hits8 {
    mask: u32,
    t: [f32; LANES],
    b1: [f32; LANES],
    b2: [f32; LANES],
}

/// The AVX2 test of eight slots, after checking every slot is in bounds (a bad slot is a
/// traversal bug, and a gather would read past the array).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
#[allow(unsafe_code)]
fn gather8(
    _avx2: Avx2,
    pre: &RayPrecomp4,
    tris: &[[Vec3; 3]],
    slots: &[u32; LANES],
    t_max: f32,
) -> Hits8 {
    assert!(slots.iter().all(|&s| (s as usize) < tris.len()));
    // SAFETY: `Avx2` exists only where the CPU has AVX2; every slot is below `tris.len()`,
    // which is at most `MAX_GATHER_TRIANGLES`, so each gathered float lies inside `tris` and
    // its offset fits an `i32`.
    unsafe { gather8_avx2(pre, tris, slots, t_max) }
}

/// # Safety
///
/// The CPU must have AVX2; every slot must be below `tris.len()` and `tris.len()` at most
/// [`MAX_GATHER_TRIANGLES`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
unsafe fn gather8_avx2(
    pre: &RayPrecomp4,
    tris: &[[Vec3; 3]],
    slots: &[u32; LANES],
    t_max: f32,
) -> Hits8 {
    use crate::wide::tri4::{avx, watertight_lanes};
    use rt_core::ray::gamma;
    use std::arch::x86_64::*;
    // `[Vec3; 3]` is nine packed `f32`s (glam's `Vec3` is `repr(C)` without padding).
    const _: () = assert!(std::mem::size_of::<[Vec3; 3]>() == 36);
    let base = tris.as_ptr().cast::<f32>();
    let nine = _mm256_set1_epi32(9);
    // SAFETY: reads 32 bytes from a `[u32; 8]`.
    let at = unsafe { _mm256_loadu_si256(slots.as_ptr().cast()) };
    let first = _mm256_mullo_epi32(at, nine);
    // SAFETY: float `9 * slot + 3 * vertex + axis` of the array lies inside `tris` because
    // each slot is below `tris.len()` (the caller's contract), and fits an `i32`.
    let gather = |vertex: usize, axis: usize| unsafe {
        _mm256_i32gather_ps::<4>(base.add(3 * vertex + axis), first)
    };
    macro_rules! load {
        ($vertex:expr, $axis:expr) => {
            gather($vertex, $axis)
        };
    }
    let (zero_edge, hits, t, b1, b2) = watertight_lanes!(avx, pre, t_max, load);
    let mut h = Hits8 {
        mask: hits,
        t: [0.0; LANES],
        b1: [0.0; LANES],
        b2: [0.0; LANES],
    };
    // SAFETY: each store writes 32 bytes to a whole `[f32; 8]`.
    unsafe {
        _mm256_storeu_ps(h.t.as_mut_ptr(), t);
        _mm256_storeu_ps(h.b1.as_mut_ptr(), b1);
        _mm256_storeu_ps(h.b2.as_mut_ptr(), b2);
    }
    // Lanes with an edge function of zero are redone by the scalar test in double precision.
    let mut redo = zero_edge;
    while redo != 0 {
        let lane = redo.trailing_zeros() as usize;
        redo &= redo - 1;
        h.mask &= !(1 << lane);
        if let Some(x) = intersect_triangle(&pre.scalar, &tris[slots[lane] as usize], t_max) {
            h.mask |= 1 << lane;
            h.t[lane] = x.t;
            h.b1[lane] = x.b1;
            h.b2[lane] = x.b2;
        }
    }
    h
}
