//! The IOSP-0 heap over a slice of triangles: its builder, its traversal and its invariant
//! check, shared by [`Iosp0`](super::Iosp0) (one heap over the scene) and
//! [`Iosp2`](super::Iosp2) (one heap per top-level leaf).
//!
//! A heap of `n` triangles has `ceil(n / 2)` nodes; node `j` owns slots `2j` and `2j + 1`
//! (only `2j` for the last node when `n` is odd), lies at depth `floor(log2(j + 1))`, is
//! bounded on axis `depth % 3`, and its children `2j + 1`, `2j + 2` (when below the node count)
//! were partitioned on the next level's axis with the lower half on the left.

use super::lanes::{SlotTest, LANES};
use super::split::{complete_split, heap_contains};
use super::{slab_of, TriBox};
use crate::traversal::{Closest, Counter, SlabRay, FAR_SCALE};
use crate::wide::tri4::RayPrecomp4;
use glam::Vec3;
use rayon::prelude::*;

/// Heaps are limited to `2^31` triangles, so node indices `2j + 2` never overflow a `u32`.
pub(crate) const MAX_TRIANGLES: usize = 1 << 31;

/// Traversal stack entries: one per level at most, and a heap of `2^31` triangles has 31.
const STACK: usize = 32;

/// Nodes of a level processed on the current thread below this many triangles in the level.
const PARALLEL_MIN: usize = 8192;

/// Depth of heap node `j`.
#[inline(always)]
pub(crate) fn depth(j: u32) -> u32 {
    31 - (j + 1).leading_zeros()
}

/// One node of a level still to place: its heap index, its triangles' range in the work array,
/// and whether its subtree holds the heap's one-triangle last node.
#[derive(Clone, Copy)]
struct Task {
    node: u32,
    start: usize,
    len: usize,
    short: bool,
}

/// What placing one node produced: its pair and its children's tasks.
struct Placed {
    node: u32,
    pair: [u32; 2],
    children: [Option<Task>; 2],
}

/// Orders `boxes` into an IOSP-0 heap: returns `order`, where `order[slot]` is the index into
/// `boxes` of the triangle placed at `slot`. Level by level, top down: each node takes the
/// triangle with the lowest minimum and then the one with the highest maximum on its axis, and
/// splits the rest at the object median of the next axis into the exact sizes of its two
/// complete subtrees. The nodes of a level own disjoint ranges of the work array, so they are
/// placed in parallel; the result does not depend on the thread count.
pub(crate) fn build(boxes: &[TriBox]) -> Vec<u32> {
    let n = boxes.len();
    debug_assert!(n <= MAX_TRIANGLES);
    let mut order = vec![0u32; n];
    let mut work: Vec<u32> = (0..n as u32).collect();
    let mut level = if n == 0 {
        Vec::new()
    } else {
        vec![Task {
            node: 0,
            start: 0,
            len: n,
            short: n % 2 == 1,
        }]
    };
    let mut axis = 0;
    while !level.is_empty() {
        // Cut the work array into the level's ranges, which are disjoint and ascending.
        let mut slices = Vec::with_capacity(level.len());
        let mut rest: &mut [u32] = &mut work;
        let mut at = 0;
        for task in &level {
            let (_, tail) = rest.split_at_mut(task.start - at);
            let (mine, tail) = tail.split_at_mut(task.len);
            slices.push((*task, mine));
            rest = tail;
            at = task.start + task.len;
        }
        let last_node = (n.div_ceil(2) - 1) as u32;
        let place = |(task, s): (Task, &mut [u32])| place(boxes, last_node, axis, task, s);
        let placed: Vec<Placed> = if at - level[0].start >= PARALLEL_MIN {
            slices.into_par_iter().map(place).collect()
        } else {
            slices.into_iter().map(place).collect()
        };
        let mut next = Vec::with_capacity(placed.len() * 2);
        for p in placed {
            let slot = 2 * p.node as usize;
            order[slot] = p.pair[0];
            if slot + 1 < n {
                order[slot + 1] = p.pair[1];
            }
            next.extend(p.children.into_iter().flatten());
        }
        level = next;
        axis = (axis + 1) % 3;
    }
    order
}

/// Places one node: its bounding pair at the front of `s`, the rest cut between the children.
fn place(boxes: &[TriBox], last_node: u32, axis: usize, task: Task, s: &mut [u32]) -> Placed {
    let lo = |i: u32| boxes[i as usize].lo[axis];
    let hi = |i: u32| boxes[i as usize].hi[axis];
    let first = argmin(s, |a, b| lo(a).total_cmp(&lo(b)));
    s.swap(0, first);
    if s.len() == 1 {
        return Placed {
            node: task.node,
            pair: [s[0], s[0]],
            children: [None, None],
        };
    }
    let second = 1 + argmin(&s[1..], |a, b| hi(b).total_cmp(&hi(a)));
    s.swap(1, second);
    let pair = [s[0], s[1]];
    // Nodes in this subtree: len = 2h, or 2h - 1 when it holds the one-triangle last node.
    let h = (task.len + task.short as usize) / 2;
    let (hl, hr) = complete_split(h as u64);
    let (hl, hr) = (hl as usize, hr as usize);
    debug_assert_eq!(task.len - 2, 2 * (hl + hr) - task.short as usize);
    // Only the subtree holding the heap's last node is one triangle short.
    let left = 2 * task.node + 1;
    let short_left = task.short && heap_contains(left as u64, last_node as u64);
    let short_right = task.short && !short_left;
    let rest = &mut s[2..];
    let n_left = 2 * hl - short_left as usize;
    let next = (axis + 1) % 3;
    if n_left > 0 && n_left < rest.len() {
        rest.select_nth_unstable_by(n_left, |&a, &b| {
            boxes[a as usize]
                .key(next)
                .total_cmp(&boxes[b as usize].key(next))
        });
    }
    let child = |node, start, len, short| {
        (len > 0).then_some(Task {
            node,
            start,
            len,
            short,
        })
    };
    Placed {
        node: task.node,
        pair,
        children: [
            child(left, task.start + 2, n_left, short_left),
            child(
                left + 1,
                task.start + 2 + n_left,
                rest.len() - n_left,
                short_right,
            ),
        ],
    }
}

fn argmin(s: &[u32], cmp: impl Fn(u32, u32) -> std::cmp::Ordering) -> usize {
    let mut best = 0;
    for i in 1..s.len() {
        if cmp(s[i], s[best]).is_lt() {
            best = i;
        }
    }
    best
}

/// Closest (or, with `ANY_HIT`, any) hit in the heap `tris`, reporting slot `i` as prim
/// `offset + i`, into `closest`, for a ray whose interval over the heap's bounds is
/// `[t0, t1]` (the caller clips it to the scene's or the top-level leaf's box). Returns true
/// when an any-hit query has its answer. Does not allocate: the stack and the batch are arrays.
///
/// The triangles of entered nodes are not tested at once but batched, eight at a time, for
/// `lanes` (see the module doc's deviations): the batch is tested when full and before every
/// pop from the stack, so the culling distance a popped node is checked against includes every
/// triangle entered before it. A node whose children are both leaves adds its children's
/// triangles to the batch instead of testing their slabs; a heap of at most eight triangles is
/// tested whole.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn traverse<const ANY_HIT: bool, C: Counter>(
    tris: &[[Vec3; 3]],
    offset: u32,
    slab: &SlabRay,
    pre: &RayPrecomp4,
    lanes: SlotTest,
    (t0, t1): (f32, f32),
    t_max: f32,
    closest: &mut Closest,
    counter: &mut C,
) -> bool {
    let n = tris.len();
    if n == 0 {
        return false;
    }
    if n <= LANES {
        counter.leaf();
        let slots: [u32; LANES] = std::array::from_fn(|i| i.min(n - 1) as u32);
        return lanes.run::<ANY_HIT, C>(pre, tris, offset, &slots, n, t_max, closest, counter);
    }
    let nodes = n.div_ceil(2) as u32;
    let mut batch = [0u32; LANES];
    let mut len = 0;
    // Tests the batch; unused lanes repeat its first slot.
    macro_rules! flush {
        () => {
            if len > 0 {
                let first = batch[0];
                batch[len..].fill(first);
                let count = std::mem::replace(&mut len, 0);
                if lanes
                    .run::<ANY_HIT, C>(pre, tris, offset, &batch, count, t_max, closest, counter)
                {
                    return true;
                }
            }
        };
    }
    // (node, its slab's axis, interval) of far children still to visit.
    let mut stack = [(0u32, 0usize, 0f32, 0f32); STACK];
    let mut sp = 0;
    let (mut node, mut axis, mut t0, mut t1) = (0u32, 0usize, t0, t1);
    loop {
        let a = 2 * node as usize;
        let b = (a + 1).min(n - 1);
        counter.boxes(1);
        let (lo, hi) = slab_of(&tris[a], &tris[b], axis);
        let (near, far) = slab.slab(axis, lo, hi);
        // `max`/`min` drop the NaN of `0 * inf` (a ray in the plane of a face): conservative.
        let tn = t0.max(near);
        let tf = t1.min(far).min(closest.cull_t);
        let mut descended = false;
        if tn <= tf * FAR_SCALE {
            counter.leaf();
            let left = 2 * node + 1;
            // With both children leaves (the left child's first child is past the end), their
            // slots 4j + 2 ..= 4j + 5 (fewer at the end of the heap) join this node's in the
            // batch instead of having their slabs tested.
            let leaf_children = left < nodes && 2 * left + 1 >= nodes;
            // The children's four triangles are next (queued, or read for their slabs) and
            // far from this node in the heap: start loading them now.
            if left < nodes {
                prefetch_slots(tris, 2 * left as usize, 4);
            }
            let own = 1 + (b > a) as usize;
            let kids = if leaf_children {
                (n - 2 * left as usize).min(4)
            } else {
                0
            };
            if len + own + kids > LANES {
                flush!();
            }
            batch[len..len + own].copy_from_slice(&[a as u32, b as u32][..own]);
            len += own;
            let c = 2 * left;
            batch[len..len + kids].copy_from_slice(&[c, c + 1, c + 2, c + 3][..kids]);
            len += kids;
            if left < nodes && !leaf_children {
                let right = left + 1;
                let child_axis = if axis == 2 { 0 } else { axis + 1 };
                node = if right >= nodes {
                    left
                } else if slab.negative(child_axis) {
                    stack[sp] = (left, child_axis, tn, tf);
                    sp += 1;
                    right
                } else {
                    stack[sp] = (right, child_axis, tn, tf);
                    sp += 1;
                    left
                };
                (axis, t0, t1) = (child_axis, tn, tf);
                descended = true;
            }
        }
        if !descended {
            flush!();
            loop {
                if sp == 0 {
                    return false;
                }
                sp -= 1;
                let (next, next_axis, e0, e1) = stack[sp];
                if e0 <= closest.cull_t * FAR_SCALE {
                    (node, axis, t0, t1) = (next, next_axis, e0, e1);
                    break;
                }
            }
        }
    }
}

/// Asks for the cache lines of the triangles `slot..slot + count` (those in the heap).
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn prefetch_slots(tris: &[[Vec3; 3]], slot: usize, count: usize) {
    let end = (slot + count).min(tris.len());
    if slot >= end {
        return;
    }
    #[cfg(all(target_arch = "x86_64", target_feature = "sse"))]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let bytes = tris[slot..end].as_ptr_range();
        let (mut line, stop) = (bytes.start.cast::<i8>(), bytes.end.cast::<i8>());
        while line < stop {
            // SAFETY: a prefetch is a hint that never faults; `line` is inside the slice.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(line) };
            line = line.wrapping_add(64);
        }
        // SAFETY: as above, for the slice's last byte (its last line may start past `line`).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(stop.wrapping_sub(1)) };
    }
}

/// The first broken heap invariant, if any: every node's slab on its axis contains every
/// triangle of its subtree. `O(n log n)`.
pub(crate) fn check(tris: &[[Vec3; 3]]) -> Result<(), String> {
    let n = tris.len();
    let nodes = n.div_ceil(2);
    let boxes: Vec<TriBox> = tris.iter().map(TriBox::of).collect();
    for j in 0..nodes {
        let axis = (depth(j as u32) % 3) as usize;
        let (a, b) = (2 * j, (2 * j + 1).min(n - 1));
        let (lo, hi) = slab_of(&tris[a], &tris[b], axis);
        // Walk the subtree level by level: node ranges [first, last] at each depth.
        let (mut first, mut last) = (j, j);
        while first < nodes {
            for k in first..=last.min(nodes - 1) {
                for s in [2 * k, (2 * k + 1).min(n - 1)] {
                    let bx = &boxes[s];
                    if bx.lo[axis] < lo || bx.hi[axis] > hi {
                        return Err(format!(
                            "slot {s} (node {k}) leaves the slab [{lo}, {hi}] of node {j} on axis {axis}"
                        ));
                    }
                }
            }
            first = 2 * first + 1;
            last = 2 * last + 2;
        }
    }
    Ok(())
}

/// Number of levels of a heap of `n` triangles: one more than the last node's depth.
pub(crate) fn levels(n: usize) -> u32 {
    if n == 0 {
        0
    } else {
        depth((n.div_ceil(2) - 1) as u32) + 1
    }
}
