//! The nearest-first traversal stack of the wide BVHs and of the four- and eight-wide top
//! levels (two-level, IOSP-2): child codes still to visit, pushed far to near so the nearest
//! pops first, with their entry distances so that a pop skips subtrees that start beyond the
//! closest hit found since they were pushed.

use super::FAR_SCALE;
use std::mem::MaybeUninit;

/// Slots still to visit: up to `CAP` child codes and, with `TSTACK`, their entry distances
/// (without it, every popped slot is visited: the wide BVHs' `no-tstack` option).
///
/// The arrays are left uninitialised: zeroing 2 KB per ray cost more than a short traversal
/// (and 1.5 KB, 7 % of a clustered trace).
pub(crate) struct Stack<const CAP: usize, const TSTACK: bool> {
    codes: [MaybeUninit<u32>; CAP],
    ts: [MaybeUninit<f32>; CAP],
    len: usize,
}

impl<const CAP: usize, const TSTACK: bool> Stack<CAP, TSTACK> {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Self {
            codes: [const { MaybeUninit::uninit() }; CAP],
            ts: [const { MaybeUninit::uninit() }; CAP],
            len: 0,
        }
    }

    /// Pushes child `code`, entered at distance `t`.
    #[inline(always)]
    pub(crate) fn push(&mut self, code: u32, t: f32) {
        self.codes[self.len].write(code);
        if TSTACK {
            self.ts[self.len].write(t);
        }
        self.len += 1;
    }

    /// The most recently pushed slot that may still hold something within `cull_t` (its
    /// entry distance within `cull_t` widened by [`FAR_SCALE`]).
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) fn pop(&mut self, cull_t: f32) -> Option<u32> {
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

/// Inserts child `code`, entered at distance `t`, into the `n` hit children `hits[..n]` of one
/// node kept sorted by entry distance (insertion sort; equal distances keep the order they
/// were offered in). Returns the new count. (A free function over the caller's array and count
/// rather than a type holding both: the count then stays in a register.) The loop over a
/// node's hit lanes that calls it stays in each caller: one helper taking the child's code as
/// a closure cost IOSP-2 up to 1.5 % more instructions (docs/benchmarks.md, "Issue 29: one
/// loop over a top node's hit children?").
#[inline(always)]
pub(crate) fn insert_by_distance(hits: &mut [(f32, u32)], n: usize, t: f32, code: u32) -> usize {
    let mut k = n;
    while k > 0 && hits[k - 1].0 > t {
        hits[k] = hits[k - 1];
        k -= 1;
    }
    hits[k] = (t, code);
    n + 1
}

impl<const CAP: usize> Stack<CAP, true> {
    /// Pushes all but the nearest of the sorted hit children `hits` (from
    /// [`insert_by_distance`]), far to near, and returns the nearest, the one to visit next;
    /// `None` if no child was hit.
    #[inline(always)]
    pub(crate) fn push_all_but_nearest(&mut self, hits: &[(f32, u32)]) -> Option<u32> {
        let (&(_, nearest), rest) = hits.split_first()?;
        for &(t, code) in rest.iter().rev() {
            self.push(code, t);
        }
        Some(nearest)
    }
}
