//! The top tree of the on-demand QBVH: binned-SAH split planes chosen on a sample of the
//! triangles, every triangle classified through them in one pass, a counting sort of the
//! triangle indices by group, and an exact split of the few groups the sample underestimated.

use super::{TopNode, SAH_DEPTH};
use glam::Vec3;
use rayon::prelude::*;
use rt_core::Aabb;

/// Triangles sampled to choose the top tree's split planes (all of them in smaller scenes).
const SAMPLE: usize = 1 << 16;

/// SAH bins per split.
const BINS: usize = 16;

/// Largest number of refs binned per split (a strided sample of larger sets).
const SAH_SAMPLES: usize = 4096;

/// Scenes at least this large are prepared in parallel (when asked to).
const PARALLEL_MIN: usize = 1 << 15;

/// A triangle's box.
#[inline]
fn tri_box(t: &[Vec3; 3]) -> Aabb {
    Aabb::new(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

/// Centre of a box. The sample build and the classification both use exactly this, so a
/// sampled triangle is classified into the leaf its sample made.
#[inline]
fn centroid(b: &Aabb) -> Vec3 {
    (b.min + b.max) * 0.5
}

/// One triangle's box and caller index.
#[derive(Clone, Copy, Debug)]
struct Ref {
    bounds: Aabb,
    id: u32,
}

impl Ref {
    fn of(triangles: &[[Vec3; 3]], i: usize) -> Self {
        Self {
            bounds: tri_box(&triangles[i]),
            id: i as u32,
        }
    }
}

/// The box of a set of refs and the box of their centroids.
type Part = (Aabb, Aabb);

/// Bounds of the refs' boxes and of their centroids.
fn set_bounds(refs: &[Ref]) -> Part {
    refs.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), r| {
        (b.union(r.bounds), c.grown(centroid(&r.bounds)))
    })
}

/// A binned split: left are the centroids in bins `0..=last_left` along `axis`.
#[derive(Clone, Copy, Debug)]
struct Plane {
    axis: usize,
    lo: f32,
    scale: f32,
    /// `last_left + 1`.
    limit: f32,
}

impl Plane {
    /// NaN centroids land in bin 0 (`as` saturates), the same way every time.
    #[inline]
    fn bin(&self, c: Vec3) -> usize {
        (((c[self.axis] - self.lo) * self.scale) as usize).min(BINS - 1)
    }

    /// `self.bin(c) <= last_left`, exactly (NaN and negative positions are bin 0, and
    /// `last_left < BINS - 1`), without the conversion.
    #[inline]
    fn is_left(&self, c: Vec3) -> bool {
        !self.is_right(c)
    }

    /// `self.bin(c) > last_left`: false for a NaN position.
    #[inline]
    fn is_right(&self, c: Vec3) -> bool {
        (c[self.axis] - self.lo) * self.scale >= self.limit
    }
}

/// The binned-SAH split along the largest axis of `cbounds`, or `None` if the centroids do not
/// spread over two bins (or their extent is not finite). Large sets bin a strided sample of
/// [`SAH_SAMPLES`] refs only (Dammertz §3.2 likewise estimates the SAH from a fraction of the
/// primitives at the high levels). Both sides of the split hold binned refs, so partitioning by
/// it never leaves a side empty.
fn choose_split(refs: &[Ref], cbounds: &Aabb) -> Option<Plane> {
    let axis = cbounds.largest_axis();
    let lo = cbounds.min[axis];
    let scale = BINS as f32 / (cbounds.max[axis] - lo);
    // A zero, NaN or infinite extent gives an infinite, NaN or zero scale.
    if !scale.is_finite() || scale <= 0.0 {
        return None;
    }
    let mut plane = Plane {
        axis,
        lo,
        scale,
        limit: 0.0,
    };
    let mut count = [0usize; BINS];
    let mut boxes = [Aabb::EMPTY; BINS];
    for r in refs.iter().step_by(refs.len().div_ceil(SAH_SAMPLES)) {
        let k = plane.bin(centroid(&r.bounds));
        count[k] += 1;
        boxes[k] = boxes[k].union(r.bounds);
    }
    let total: usize = count.iter().sum();
    // Half areas in f64, so that huge boxes do not overflow.
    let area = |b: &Aabb| {
        let e = b.extent().as_dvec3();
        e.x * e.y + e.y * e.z + e.z * e.x
    };
    let mut right_area = [0f64; BINS];
    let mut acc = Aabb::EMPTY;
    for k in (1..BINS).rev() {
        acc = acc.union(boxes[k]);
        right_area[k] = area(&acc);
    }
    let mut best: Option<(f64, usize)> = None;
    let mut left = Aabb::EMPTY;
    let mut n_left = 0;
    for k in 0..BINS - 1 {
        left = left.union(boxes[k]);
        n_left += count[k];
        let n_right = total - n_left;
        if n_left == 0 || n_right == 0 {
            continue;
        }
        let cost = area(&left) * n_left as f64 + right_area[k + 1] * n_right as f64;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, k));
        }
    }
    plane.limit = (best?.1 + 1) as f32;
    Some(plane)
}

/// Moves the refs satisfying `left` to the front; returns how many there are and the (box,
/// centroid box) of both parts, computed on the way.
fn partition(refs: &mut [Ref], left: impl Fn(&Ref) -> bool) -> (usize, Part, Part) {
    fn add(p: &mut Part, r: &Ref) {
        p.0 = p.0.union(r.bounds);
        p.1 = p.1.grown(centroid(&r.bounds));
    }
    let mut l = (Aabb::EMPTY, Aabb::EMPTY);
    let mut r = (Aabb::EMPTY, Aabb::EMPTY);
    let mut i = 0;
    let mut j = refs.len();
    loop {
        while i < j && left(&refs[i]) {
            add(&mut l, &refs[i]);
            i += 1;
        }
        while i < j && !left(&refs[j - 1]) {
            add(&mut r, &refs[j - 1]);
            j -= 1;
        }
        if i >= j {
            return (i, l, r);
        }
        // refs[i] belongs right and refs[j - 1] left.
        add(&mut r, &refs[i]);
        add(&mut l, &refs[j - 1]);
        refs.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

/// A node of the split-plane tree built on the sample: an inner node's split and its children
/// `child[0]` (left) and `child[1]`; a leaf has its id in `leaf` and points to itself, so that
/// a descent can run a fixed number of steps without branches.
#[derive(Clone, Copy, Debug)]
struct PNode {
    axis: u32,
    lo: f32,
    scale: f32,
    limit: f32,
    child: [u32; 2],
    /// The leaf's id, or [`INNER`].
    leaf: u32,
    depth: u32,
}

/// [`PNode::leaf`] of an inner node.
const INNER: u32 = u32::MAX;

/// Splits the sample `refs` (centroid box `cbounds`) until at most `leaf_size` remain, down to
/// depth [`SAH_DEPTH`] at most; returns the index of the subtree's root in `out`.
fn build_planes(
    refs: &mut [Ref],
    cbounds: &Aabb,
    depth: usize,
    leaf_size: usize,
    out: &mut Vec<PNode>,
    leaves: &mut u32,
) -> u32 {
    let index = out.len() as u32;
    let plane = if refs.len() > leaf_size && depth < SAH_DEPTH {
        choose_split(refs, cbounds)
    } else {
        None
    };
    // A leaf: whatever the test gives, both children are the leaf itself.
    let mut node = PNode {
        axis: 0,
        lo: 0.0,
        scale: 0.0,
        limit: f32::INFINITY,
        child: [index; 2],
        leaf: *leaves,
        depth: depth as u32,
    };
    let Some(plane) = plane else {
        out.push(node);
        *leaves += 1;
        return index;
    };
    out.push(node); // replaced below
    let (mid, l, r) = partition(refs, |r| plane.is_left(centroid(&r.bounds)));
    let (left_refs, right_refs) = refs.split_at_mut(mid);
    let left = build_planes(left_refs, &l.1, depth + 1, leaf_size, out, leaves);
    let right = build_planes(right_refs, &r.1, depth + 1, leaf_size, out, leaves);
    node = PNode {
        axis: plane.axis as u32,
        lo: plane.lo,
        scale: plane.scale,
        limit: plane.limit,
        child: [left, right],
        leaf: INNER,
        depth: depth as u32,
    };
    out[index as usize] = node;
    index
}

/// Writes the leaf of the plane tree `planes` (whose leaves are at most `depth` deep) that each
/// triangle of `tris` falls in to `out`. The test is [`Plane::is_right`]'s; eight triangles
/// descend in lockstep for a fixed `depth` steps, children picked by index, so the descents'
/// dependent loads overlap instead of waiting on each other and on branches.
fn classify(planes: &[PNode], depth: usize, tris: &[[Vec3; 3]], out: &mut [u32]) {
    const LANES: usize = 8;
    for (tris, out) in tris.chunks(LANES).zip(out.chunks_mut(LANES)) {
        let mut c = [[0.0f32; 3]; LANES];
        for (c, t) in c.iter_mut().zip(tris) {
            *c = centroid(&tri_box(t)).to_array();
        }
        let mut node = [0u32; LANES];
        for _ in 0..depth {
            for (n, c) in node.iter_mut().zip(&c) {
                let p = &planes[*n as usize];
                let right = (c[p.axis as usize] - p.lo) * p.scale >= p.limit;
                *n = p.child[right as usize];
            }
        }
        for (o, n) in out.iter_mut().zip(&node) {
            *o = planes[*n as usize].leaf;
        }
    }
}

/// The exact top-tree build of one set that exceeds the group size (the sample underestimated
/// it, or its centroids could not be separated by a plane): binned SAH, or halving by count when
/// the centroids cannot be binned and below depth [`SAH_DEPTH`]. Returns the root; the
/// descendants are appended to `out`, numbered from its start. Leaves hold their first slot of
/// the triangle order in `index`.
fn build_exact(
    refs: &mut [Ref],
    (bounds, cbounds): Part,
    first: u32,
    depth: usize,
    group_size: usize,
    out: &mut Vec<TopNode>,
) -> TopNode {
    let n = refs.len();
    if n <= group_size {
        return TopNode::new(&bounds, first, n as u32);
    }
    let plane = if depth < SAH_DEPTH {
        choose_split(refs, &cbounds)
    } else {
        None
    };
    let (mid, left, right) = match plane {
        Some(p) => partition(refs, |r| p.is_left(centroid(&r.bounds))),
        None => {
            let axis = cbounds.largest_axis();
            let mid = n / 2;
            // Equal centroids on the largest axis are equal on all: any halving will do.
            if cbounds.extent()[axis] > 0.0 {
                refs.select_nth_unstable_by(mid, |a, b| {
                    centroid(&a.bounds)[axis].total_cmp(&centroid(&b.bounds)[axis])
                });
            }
            let (l, r) = refs.split_at(mid);
            (mid, set_bounds(l), set_bounds(r))
        }
    };
    debug_assert!(0 < mid && mid < n);
    let (left_refs, right_refs) = refs.split_at_mut(mid);
    let pair = out.len();
    out.push(TopNode::PLACEHOLDER);
    out.push(TopNode::PLACEHOLDER);
    let l = build_exact(left_refs, left, first, depth + 1, group_size, out);
    let r = build_exact(
        right_refs,
        right,
        first + mid as u32,
        depth + 1,
        group_size,
        out,
    );
    out[pair] = l;
    out[pair + 1] = r;
    TopNode::new(&bounds, pair as u32, 0)
}

/// Replaces the plane tree's subtree at `i` by top-tree nodes appended to `out` and returns its
/// root. `parts[leaf]` is the root of each leaf's group or exact subtree and the subtree's
/// other nodes, numbered from zero.
fn assemble(
    planes: &[PNode],
    i: usize,
    parts: &mut [(TopNode, Vec<TopNode>)],
    out: &mut Vec<TopNode>,
) -> TopNode {
    let p = planes[i];
    match (p.leaf != INNER).then_some(p.leaf) {
        Some(id) => {
            let (mut root, mut sub) =
                std::mem::replace(&mut parts[id as usize], (TopNode::PLACEHOLDER, Vec::new()));
            if !root.is_leaf() {
                let base = out.len() as u32;
                for node in std::iter::once(&mut root).chain(sub.iter_mut()) {
                    if !node.is_leaf() {
                        node.index += base;
                    }
                }
                out.append(&mut sub);
            }
            root
        }
        None => {
            let [left, right] = p.child;
            let pair = out.len();
            out.push(TopNode::PLACEHOLDER);
            out.push(TopNode::PLACEHOLDER);
            let l = assemble(planes, left as usize, parts, out);
            let r = assemble(planes, right as usize, parts, out);
            out[pair] = l;
            out[pair + 1] = r;
            TopNode::new(&l.aabb().union(r.aabb()), pair as u32, 0)
        }
    }
}

/// Builds the top tree over `triangles` with groups of at most `group_size`: the nodes, root
/// first (none for no triangles), and the caller's triangle indices in group order. Leaves hold
/// their first slot of that order in `index` and their size in `count`.
pub(super) fn build_top(
    triangles: &[[Vec3; 3]],
    group_size: usize,
    parallel: bool,
) -> (Vec<TopNode>, Vec<u32>) {
    let n = triangles.len();
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let parallel = parallel && n >= PARALLEL_MIN;

    // 1. Split planes from a strided sample, split until the sample's share of a group remains.
    let stride = n.div_ceil(SAMPLE);
    let mut sample: Vec<Ref> = (0..n)
        .step_by(stride)
        .map(|i| Ref::of(triangles, i))
        .collect();
    let leaf_size = if stride == 1 {
        group_size
    } else {
        (group_size * sample.len() / n).max(1)
    };
    let mut planes = Vec::new();
    let mut n_leaves = 0;
    let (_, cbounds) = set_bounds(&sample);
    build_planes(
        &mut sample,
        &cbounds,
        0,
        leaf_size,
        &mut planes,
        &mut n_leaves,
    );
    drop(sample);
    let n_leaves = n_leaves as usize;

    // 2. Every triangle to its leaf.
    let max_depth = planes.iter().map(|p| p.depth as usize).max().unwrap_or(0);
    let mut leaf_of = vec![0u32; n];
    if parallel {
        const CHUNK: usize = 1 << 12;
        leaf_of
            .par_chunks_mut(CHUNK)
            .zip(triangles.par_chunks(CHUNK))
            .for_each(|(out, tris)| classify(&planes, max_depth, tris, out));
    } else {
        classify(&planes, max_depth, triangles, &mut leaf_of);
    }

    // 3. Counting sort of the triangle indices by leaf (ascending within a leaf).
    let mut start = vec![0usize; n_leaves + 1];
    for &l in &leaf_of {
        start[l as usize + 1] += 1;
    }
    for k in 0..n_leaves {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut order = vec![0u32; n];
    for (i, &l) in leaf_of.iter().enumerate() {
        order[next[l as usize]] = i as u32;
        next[l as usize] += 1;
    }
    drop(leaf_of);

    // 4. Each leaf's group, or an exact subtree where the sample underestimated the leaf.
    let mut depth = vec![0usize; n_leaves];
    for p in &planes {
        if p.leaf != INNER {
            depth[p.leaf as usize] = p.depth as usize;
        }
    }
    let mut slices = Vec::with_capacity(n_leaves);
    let mut rest = order.as_mut_slice();
    for k in 0..n_leaves {
        let (head, tail) = rest.split_at_mut(start[k + 1] - start[k]);
        slices.push((k, head));
        rest = tail;
    }
    let make = |(k, ids): (usize, &mut [u32])| -> (TopNode, Vec<TopNode>) {
        // Each leaf holds at least the sampled triangles that made it.
        assert!(!ids.is_empty(), "top-tree leaf {k} got no triangles");
        let first = start[k] as u32;
        if ids.len() <= group_size {
            let b = ids.iter().fold(Aabb::EMPTY, |b, &i| {
                b.union(tri_box(&triangles[i as usize]))
            });
            return (TopNode::new(&b, first, ids.len() as u32), Vec::new());
        }
        let mut refs: Vec<Ref> = ids
            .iter()
            .map(|&i| Ref::of(triangles, i as usize))
            .collect();
        let part = set_bounds(&refs);
        let mut sub = Vec::new();
        let root = build_exact(&mut refs, part, first, depth[k], group_size, &mut sub);
        for (id, r) in ids.iter_mut().zip(&refs) {
            *id = r.id;
        }
        (root, sub)
    };
    let mut parts: Vec<(TopNode, Vec<TopNode>)> = if parallel {
        slices.into_par_iter().map(make).collect()
    } else {
        slices.into_iter().map(make).collect()
    };

    // 5. The plane tree with its leaves replaced, boxes from the bottom up.
    let mut nodes = vec![TopNode::PLACEHOLDER];
    nodes[0] = assemble(&planes, 0, &mut parts, &mut nodes);
    (nodes, order)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_splits_by_predicate_and_bounds_both_sides() {
        let mut refs: Vec<Ref> = (0..10)
            .map(|i| Ref {
                bounds: Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32)),
                id: i,
            })
            .collect();
        let (mid, l, r) = partition(&mut refs, |r| r.id % 3 == 0);
        assert_eq!(mid, 4);
        assert!(refs[..mid].iter().all(|r| r.id % 3 == 0));
        assert!(refs[mid..].iter().all(|r| r.id % 3 != 0));
        assert_eq!((l.0.min.x, l.0.max.x, l.1.max.x), (0.0, 9.0, 9.0));
        assert_eq!((r.0.min.x, r.0.max.x, r.1.min.x), (1.0, 8.0, 1.0));
    }

    /// Points on a line, `n` of them, as degenerate triangles.
    fn line(n: usize) -> Vec<[Vec3; 3]> {
        (0..n).map(|i| [Vec3::new(i as f32, 0.0, 0.0); 3]).collect()
    }

    fn check(nodes: &[TopNode], order: &[u32], n: usize, group_size: usize) {
        let mut sorted = order.to_vec();
        sorted.sort_unstable();
        assert!(sorted.iter().copied().eq(0..n as u32));
        let leaves: Vec<_> = nodes.iter().filter(|x| x.is_leaf()).collect();
        assert!(leaves.iter().all(|l| l.count as usize <= group_size));
        assert_eq!(leaves.iter().map(|l| l.count as usize).sum::<usize>(), n);
    }

    #[test]
    fn sampled_planes_and_exact_fixups_bound_every_group() {
        // Large enough to sample; equal centroids force the count-halving fallback.
        for (n, g) in [(200_000, 1000), (150_000, 7), (70_000, 70_000)] {
            let tris = line(n);
            let (nodes, order) = build_top(&tris, g, true);
            check(&nodes, &order, n, g);
        }
        let same = vec![[Vec3::ONE; 3]; 100_000];
        let (nodes, order) = build_top(&same, 3000, false);
        check(&nodes, &order, same.len(), 3000);
        assert!(nodes.len() > 2 * 100_000 / 3000);
    }
}
