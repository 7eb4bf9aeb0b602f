//! The IOSP-4 builder: top-down binned SAH where every node first pulls out its two bounding
//! triangles (thesis §7.2.2).
//!
//! A node's set is never smaller than two, so every node has two bounding triangles (a
//! one-triangle scene excepted). The SAH sees that a node shrinks its box along one axis only:
//! a child's box is the parent's effective box (the intersection of its ancestors' slabs, the
//! scene box at the root) with only the partition axis clipped to the child's extent.

use super::iosp4::word;
use super::TriBox;
use rt_core::Aabb;
use std::collections::VecDeque;

/// Remaining triangles at or below which a node becomes a leaf (the thesis' "at least 4
/// triangles per leaf" setting, shared with its reference BVH).
pub(crate) const LEAF_SIZE: usize = 4;

/// The most extra triangles a leaf can hold (3 bits).
pub(crate) const MAX_EXTRAS: usize = 7;

/// SAH bins per axis (the thesis uses 10).
const BINS: usize = 10;

/// Below this depth nodes are split by the SAH, from it on at the object median, so the depth
/// stays below `SAH_DEPTH + 31` and the traversal stack cannot overflow.
pub(crate) const SAH_DEPTH: u32 = 32;

/// SAH cost of a node visit relative to one triangle test.
const TRAVERSAL_COST: f32 = 1.0;

/// What the builder produced.
pub(crate) struct Built {
    /// One word per node, root first.
    pub words: Vec<u32>,
    /// Triangle ids in slot order: the bounding pairs of all nodes, then the leaves' extras.
    pub order: Vec<u32>,
    /// Slots taken by bounding triangles (where the extras start).
    pub bound_slots: usize,
    /// The root's bounding axis.
    pub root_axis: u8,
}

struct Task {
    node: u32,
    start: usize,
    len: usize,
    axis: usize,
    /// The parent's effective box: `[lo; 3]`, `[hi; 3]`.
    eff: ([f32; 3], [f32; 3]),
    depth: u32,
}

pub(crate) fn build(boxes: &[TriBox], bounds: Aabb) -> Built {
    let n = boxes.len();
    let root_axis = if n == 0 { 0 } else { bounds.largest_axis() };
    let mut words: Vec<u32> = Vec::new();
    let mut pairs: Vec<[u32; 2]> = Vec::new();
    let mut extras: Vec<u32> = Vec::new();
    let mut work: Vec<u32> = (0..n as u32).collect();
    let mut queue = VecDeque::new();
    if n > 0 {
        words.push(0);
        pairs.push([0, 0]);
        queue.push_back(Task {
            node: 0,
            start: 0,
            len: n,
            axis: root_axis,
            eff: (bounds.min.to_array(), bounds.max.to_array()),
            depth: 0,
        });
    }
    // Breadth first, so that a node's two children are allocated side by side.
    while let Some(task) = queue.pop_front() {
        let s = &mut work[task.start..task.start + task.len];
        let a = task.axis;
        let first = argmin_by(s, |i| boxes[i as usize].lo[a]);
        s.swap(0, first);
        let node = task.node as usize;
        if s.len() == 1 {
            pairs[node] = [s[0], s[0]];
            words[node] = word::leaf(0, 0);
            continue;
        }
        let second = 1 + argmin_by(&s[1..], |i| -boxes[i as usize].hi[a]);
        s.swap(1, second);
        pairs[node] = [s[0], s[1]];
        let mut eff = task.eff;
        let (lo, hi) = extent(boxes, &s[..2], a);
        (eff.0[a], eff.1[a]) = (lo, hi);
        let rest = &mut s[2..];
        let r = rest.len();
        let split = if r <= LEAF_SIZE {
            None
        } else {
            let sah = (task.depth < SAH_DEPTH)
                .then(|| sah_split(boxes, rest, eff))
                .flatten();
            match sah {
                Some((cost, ..)) if cost >= r as f32 && r <= MAX_EXTRAS => None,
                Some((_, k, bin, b)) => Some((k, partition(boxes, rest, k, bin, b))),
                None => Some(median(boxes, rest)),
            }
        };
        match split {
            None => {
                words[node] = word::leaf(r as u32, extras.len() as u32);
                extras.extend_from_slice(rest);
            }
            Some((k, n_left)) => {
                let child = words.len() as u32;
                words[node] = word::inner(k as u32, child);
                words.extend([0, 0]);
                pairs.extend([[0, 0], [0, 0]]);
                let start = task.start + 2;
                for (c, start, len) in [(0, start, n_left), (1, start + n_left, r - n_left)] {
                    queue.push_back(Task {
                        node: child + c,
                        start,
                        len,
                        axis: k,
                        eff,
                        depth: task.depth + 1,
                    });
                }
            }
        }
    }
    let bound_slots = if n == 1 { 1 } else { 2 * words.len() };
    let mut order: Vec<u32> = pairs.iter().flatten().copied().collect();
    order.truncate(bound_slots);
    order.extend(extras);
    Built {
        words,
        order,
        bound_slots,
        root_axis: root_axis as u8,
    }
}

fn argmin_by(s: &[u32], key: impl Fn(u32) -> f32) -> usize {
    let mut best = 0;
    for i in 1..s.len() {
        if key(s[i]).total_cmp(&key(s[best])).is_lt() {
            best = i;
        }
    }
    best
}

fn extent(boxes: &[TriBox], s: &[u32], axis: usize) -> (f32, f32) {
    s.iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &i| {
            let b = &boxes[i as usize];
            (lo.min(b.lo[axis]), hi.max(b.hi[axis]))
        })
}

fn area(lo: [f32; 3], hi: [f32; 3]) -> f32 {
    let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]].map(|x| x.max(0.0));
    2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
}

/// Lowest (doubled) centroid and bins per unit of it.
type Binning = (f32, f32);

/// The binning of `s` on `axis`; `None` when all centroids coincide.
fn binning(boxes: &[TriBox], s: &[u32], axis: usize) -> Option<Binning> {
    let (lo, hi) = s
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &i| {
            let k = boxes[i as usize].key(axis);
            (lo.min(k), hi.max(k))
        });
    let scale = BINS as f32 / (hi - lo) * (1.0 - 1e-6);
    (hi > lo && scale.is_finite()).then_some((lo, scale))
}

#[inline]
fn bin_of(key: f32, (lo, scale): Binning) -> usize {
    // `as` saturates and maps NaN to 0: total for any key.
    (((key - lo) * scale) as usize).min(BINS - 1)
}

/// Best SAH split of `s` (at least 5 triangles): `(cost in triangle tests, axis, last bin of
/// the left side, the binning)`, with at least two triangles on each side; `None` if no bin boundary
/// separates two and two or the box is degenerate.
fn sah_split(
    boxes: &[TriBox],
    s: &[u32],
    (elo, ehi): ([f32; 3], [f32; 3]),
) -> Option<(f32, usize, usize, Binning)> {
    let parent = area(elo, ehi);
    if !(parent > 0.0 && parent.is_finite()) {
        return None;
    }
    let mut best: Option<(f32, usize, usize, Binning)> = None;
    for k in 0..3 {
        let Some(b) = binning(boxes, s, k) else {
            continue;
        };
        let mut count = [0usize; BINS];
        let mut lo = [f32::INFINITY; BINS];
        let mut hi = [f32::NEG_INFINITY; BINS];
        for &i in s {
            let t = &boxes[i as usize];
            let j = bin_of(t.key(k), b);
            count[j] += 1;
            lo[j] = lo[j].min(t.lo[k]);
            hi[j] = hi[j].max(t.hi[k]);
        }
        // Right-side extents for splits after bin j (bins j+1..).
        let mut right = [(0usize, f32::INFINITY, f32::NEG_INFINITY); BINS];
        let mut acc = (0, f32::INFINITY, f32::NEG_INFINITY);
        for j in (1..BINS).rev() {
            acc = (acc.0 + count[j], acc.1.min(lo[j]), acc.2.max(hi[j]));
            right[j - 1] = acc;
        }
        let mut left = (0, f32::INFINITY, f32::NEG_INFINITY);
        for j in 0..BINS - 1 {
            left = (left.0 + count[j], left.1.min(lo[j]), left.2.max(hi[j]));
            let (nl, nr) = (left.0, right[j].0);
            if nl < 2 || nr < 2 {
                continue;
            }
            let clipped = |l: f32, h: f32| {
                let (mut a, mut b) = (elo, ehi);
                (a[k], b[k]) = (l, h);
                area(a, b)
            };
            let cost = TRAVERSAL_COST
                + (clipped(left.1, left.2) * nl as f32
                    + clipped(right[j].1, right[j].2) * nr as f32)
                    / parent;
            if cost.is_finite() && best.is_none_or(|(c, ..)| cost < c) {
                best = Some((cost, k, j, b));
            }
        }
    }
    best
}

/// Moves the triangles of bins `..=bin` on `axis` to the front; returns their count.
fn partition(boxes: &[TriBox], s: &mut [u32], axis: usize, bin: usize, b: Binning) -> usize {
    let mut n_left = 0;
    for i in 0..s.len() {
        if bin_of(boxes[s[i] as usize].key(axis), b) <= bin {
            s.swap(i, n_left);
            n_left += 1;
        }
    }
    n_left
}

/// Object median on the axis of the largest centroid extent: `(axis, left count)`.
fn median(boxes: &[TriBox], s: &mut [u32]) -> (usize, usize) {
    let spread = |k: usize| {
        let (lo, hi) = s
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &i| {
                let c = boxes[i as usize].key(k);
                (lo.min(c), hi.max(c))
            });
        hi - lo
    };
    let k = (0..3)
        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)))
        .unwrap_or(0);
    let m = s.len() / 2;
    s.select_nth_unstable_by(m, |&a, &b| {
        boxes[a as usize]
            .key(k)
            .total_cmp(&boxes[b as usize].key(k))
    });
    (k, m)
}
