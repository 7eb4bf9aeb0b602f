//! Top-down binned-SAH construction (Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies", 2007), evaluated on all three axes.

use super::node::Node;
use super::{compact, evh_split, BuildParams};
use glam::{Vec3, Vec3A};
use rt_core::Aabb;
use std::mem::MaybeUninit;

/// Size of the traversal stack. The build keeps every leaf at depth `MAX_DEPTH - 1` or less, and
/// ordered traversal pushes at most one entry per inner ancestor, so the stack cannot overflow.
pub(crate) const MAX_DEPTH: usize = 64;

/// Upper bound on [`BuildParams::bins`], so the bins live in a fixed array on the stack.
pub const MAX_BINS: usize = 64;

/// Below this many triangles a subtree is built on the current thread: splitting off a rayon
/// task costs more than building a few thousand triangles.
const PARALLEL_MIN_PRIMS: usize = 4096;

/// Build parameters after clamping to what the builder supports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Config {
    pub max_leaf: usize,
    pub bins: usize,
    pub traversal_cost: f64,
    pub intersection_cost: f64,
    pub parallel: bool,
    pub split: super::Split,
    pub compact_leaves: bool,
}

impl From<&BuildParams> for Config {
    fn from(p: &BuildParams) -> Self {
        let cost = |c: f32, default: f64| {
            if c.is_finite() && c >= 0.0 {
                c as f64
            } else {
                default
            }
        };
        Self {
            max_leaf: p.max_leaf_size.clamp(1, u32::MAX as usize),
            bins: p.bins.clamp(2, MAX_BINS),
            traversal_cost: cost(p.traversal_cost, 1.0),
            intersection_cost: cost(p.intersection_cost, 1.0),
            parallel: p.parallel,
            split: p.split,
            compact_leaves: p.compact_leaves,
        }
    }
}

/// A reference as the builder sees it: the bounds of a triangle, or of a piece of it when
/// splitting, and the triangle's index in the caller's order.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRef {
    pub bounds: Aabb,
    pub index: u32,
}

impl PrimRef {
    /// Halving before adding keeps the centroid finite for coordinates near `f32::MAX`.
    #[inline]
    fn centroid(&self) -> Vec3 {
        self.bounds.min * 0.5 + self.bounds.max * 0.5
    }
}

/// Nodes (root first, children of each inner node adjacent) and the caller's triangle index of
/// every leaf slot. With splitting a triangle may fill several slots, in one leaf or several.
pub(crate) struct Built {
    pub nodes: Vec<Node>,
    pub order: Vec<u32>,
}

/// Builds the hierarchy over `triangles`. An empty input gives no nodes at all.
///
/// # Panics
///
/// If there are more than `u32::MAX / 2` references (triangles, or pieces when splitting).
pub(crate) fn build(triangles: &[[Vec3; 3]], cfg: &Config) -> Built {
    // This panics beyond u32::MAX / 2 references, the count that the u32 node and slot indices
    // and the depth invariant of `build_node` allow.
    let mut refs = evh_split::references(triangles, cfg.split, cfg.parallel);
    if refs.is_empty() {
        return Built {
            nodes: Vec::new(),
            order: Vec::new(),
        };
    }
    let mut nodes = Vec::with_capacity(2 * refs.len());
    nodes.push(PLACEHOLDER);
    let root = build_node(&mut refs, 0, 0, cfg, &mut nodes);
    nodes[0] = root;
    nodes.shrink_to_fit();
    let mut order: Vec<u32> = refs.iter().map(|r| r.index).collect();
    if cfg.compact_leaves {
        compact::compact_leaves(&mut nodes, &mut order);
    }
    Built { nodes, order }
}

/// Builds a hierarchy over boxes (a top level over objects): leaf slots index `boxes`. Empty
/// boxes are left out. The SAH, bins and leaf size of `params` apply.
pub(crate) fn build_over_boxes(boxes: &[Aabb], params: &BuildParams) -> Built {
    let mut cfg = Config::from(params);
    cfg.compact_leaves = false;
    let mut refs: Vec<PrimRef> = boxes
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.is_empty())
        .map(|(i, &bounds)| PrimRef {
            bounds,
            index: i as u32,
        })
        .collect();
    if refs.is_empty() {
        return Built {
            nodes: Vec::new(),
            order: Vec::new(),
        };
    }
    let mut nodes = Vec::with_capacity(2 * refs.len());
    nodes.push(PLACEHOLDER);
    let root = build_node(&mut refs, 0, 0, &cfg, &mut nodes);
    nodes[0] = root;
    let order = refs.iter().map(|r| r.index).collect();
    Built { nodes, order }
}

const PLACEHOLDER: Node = Node {
    bounds: [0.0; 6],
    index: 0,
    count: 0,
};

/// `ceil(log2(n))` for `n >= 1`: the depth a median-split subtree over `n` triangles needs.
fn ceil_log2(n: usize) -> usize {
    if n <= 1 {
        0
    } else {
        (usize::BITS - (n - 1).leading_zeros()) as usize
    }
}

/// Builds the subtree over `refs` (which start at leaf slot `first`), appends its descendants to
/// `out` and returns its root, which the caller stores.
///
/// `refs` are triangle references: triangles, or pieces of them when splitting.
///
/// Invariant, true at the root because there are fewer than 2^31 references:
/// `depth + ceil_log2(n) <= MAX_DEPTH - 1`.
/// SAH splits may be as lopsided as 1 : n-1, so they are allowed only while the invariant would
/// hold for a child of n - 1 triangles; beyond that, median splits lower `ceil_log2` by one per
/// level and the invariant survives, which bounds the depth without ever refusing to split.
fn build_node(
    refs: &mut [PrimRef],
    first: u32,
    depth: usize,
    cfg: &Config,
    out: &mut Vec<Node>,
) -> Node {
    let n = refs.len();
    debug_assert!(n > 0 && depth + ceil_log2(n) < MAX_DEPTH);
    let (bounds, centroids) = bounds_and_centroid_bounds(refs);
    if n == 1 {
        return Node::leaf(bounds, first, 1);
    }

    let sah_allowed = depth + 1 + ceil_log2(n) < MAX_DEPTH;
    let split = if sah_allowed {
        find_sah_split(refs, &centroids, cfg)
    } else {
        None
    };
    if n <= cfg.max_leaf {
        let leaf_cost = cfg.intersection_cost * n as f64;
        let split_cost = split
            .map(|s| cfg.traversal_cost + cfg.intersection_cost * s.cost / surface_area(&bounds));
        // A NaN or infinite cost (flat or point-sized parent, overflowing coordinates) gives no
        // reason to split, so the small node stays a leaf.
        if !split_cost.is_some_and(|c| c < leaf_cost) {
            return Node::leaf(bounds, first, n as u32);
        }
    }

    let mid = match split {
        Some(s) => partition(refs, |r| {
            s.binner.bin(r.centroid(), s.axis) <= s.last_left_bin
        }),
        None => median_split(refs, &centroids),
    };
    debug_assert!(0 < mid && mid < n);

    let (left_refs, right_refs) = refs.split_at_mut(mid);
    let right_first = first + mid as u32;
    let pair = out.len();
    out.push(PLACEHOLDER);
    out.push(PLACEHOLDER);
    let (left, right) = if cfg.parallel && n >= PARALLEL_MIN_PRIMS {
        let (left, (mut right, mut right_nodes)) = rayon::join(
            || build_node(left_refs, first, depth + 1, cfg, out),
            || {
                let mut v = Vec::new();
                let r = build_node(right_refs, right_first, depth + 1, cfg, &mut v);
                (r, v)
            },
        );
        // The right subtree was numbered from zero in its own vector.
        let base = out.len() as u32;
        for node in std::iter::once(&mut right).chain(right_nodes.iter_mut()) {
            if !node.is_leaf() {
                node.index += base;
            }
        }
        out.append(&mut right_nodes);
        (left, right)
    } else {
        let left = build_node(left_refs, first, depth + 1, cfg, out);
        let right = build_node(right_refs, right_first, depth + 1, cfg, out);
        (left, right)
    };
    out[pair] = left;
    out[pair + 1] = right;
    Node::inner(bounds, pair as u32)
}

/// The box of `refs` and the box of their centroids, in SIMD registers (one pass over every
/// reference at every level of the build).
fn bounds_and_centroid_bounds(refs: &[PrimRef]) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut c_lo, mut c_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for r in refs {
        let (min, max) = (Vec3A::from(r.bounds.min), Vec3A::from(r.bounds.max));
        // The new value first, as in `Bin::add`: a NaN centroid (a reference spanning -inf to
        // inf) leaves the running box alone, as `f32::min` in `Aabb::grown` does.
        lo = min.min(lo);
        hi = max.max(hi);
        // Same arithmetic as `PrimRef::centroid`, so binning sees the same centroids.
        let c = min * 0.5 + max * 0.5;
        c_lo = c.min(c_lo);
        c_hi = c.max(c_hi);
    }
    (
        Aabb::new(lo.into(), hi.into()),
        Aabb::new(c_lo.into(), c_hi.into()),
    )
}

/// Surface area in f64, so that boxes of extent up to `f32::MAX` do not overflow.
fn surface_area(b: &Aabb) -> f64 {
    let e = b.extent().as_dvec3();
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// Maps centroids to bins along each axis. Partitioning reuses the exact arithmetic of binning,
/// so the sides get exactly the counts the SAH evaluated and neither can be empty.
#[derive(Clone, Copy, Debug)]
struct Binner {
    min: Vec3,
    scale: Vec3,
    bins: usize,
}

impl Binner {
    fn new(centroids: &Aabb, bins: usize) -> Self {
        let e = centroids.extent();
        // A zero extent gives an infinite scale; `bin` turns the resulting NaN into bin 0, so
        // such an axis simply offers no split.
        Self {
            min: centroids.min,
            scale: Vec3::splat(bins as f32) / e,
            bins,
        }
    }

    #[inline]
    fn bin(&self, c: Vec3, axis: usize) -> usize {
        // `as usize` saturates and maps NaN to 0, so this is total for any input.
        (((c[axis] - self.min[axis]) * self.scale[axis]) as usize).min(self.bins - 1)
    }
}

#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    /// Bins `0..=last_left_bin` go left.
    last_left_bin: usize,
    /// `area(left) * n_left + area(right) * n_right`, not yet divided by the parent's area.
    cost: f64,
    binner: Binner,
}

/// One bin of the sweep. The box is kept in SIMD registers (`Vec3A`): binning unions every
/// reference into three bins, and that loop is most of the build time.
#[derive(Clone, Copy, Debug)]
struct Bin {
    min: Vec3A,
    max: Vec3A,
    count: usize,
}

const EMPTY_BIN: Bin = Bin {
    min: Vec3A::INFINITY,
    max: Vec3A::NEG_INFINITY,
    count: 0,
};

impl Bin {
    #[inline]
    fn add(&mut self, min: Vec3A, max: Vec3A) {
        // The new value first: SSE `minps`/`maxps` return the second operand when either is
        // NaN, so the running box never turns NaN (as with `f32::min` in `Aabb::union`).
        self.min = min.min(self.min);
        self.max = max.max(self.max);
        self.count += 1;
    }

    #[inline]
    fn merge(&mut self, o: &Bin) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
        self.count += o.count;
    }

    /// Surface area times count, the bin's (or run's) SAH term.
    #[inline]
    fn cost(&self) -> f64 {
        surface_area(&Aabb::new(self.min.into(), self.max.into())) * self.count as f64
    }
}

/// The cheapest binned split over all three axes, or `None` if no axis separates the centroids
/// (all coincide) or every candidate's cost overflows.
fn find_sah_split(refs: &[PrimRef], centroids: &Aabb, cfg: &Config) -> Option<Split> {
    let binner = Binner::new(centroids, cfg.bins);
    // Only the `cfg.bins` bins in use are initialised: copying three whole `MAX_BINS` rows of
    // empty bins (9 KB) was a tenth of the build's instructions, once per node.
    let mut store = [[MaybeUninit::<Bin>::uninit(); MAX_BINS]; 3];
    let bins: [&mut [Bin]; 3] = store.each_mut().map(|row| {
        let row = &mut row[..cfg.bins];
        for b in row.iter_mut() {
            b.write(EMPTY_BIN);
        }
        // SAFETY: every element of `row` was just initialised, and `MaybeUninit<Bin>` has the
        // layout of `Bin`.
        #[allow(unsafe_code)]
        unsafe {
            std::slice::from_raw_parts_mut(row.as_mut_ptr().cast::<Bin>(), row.len())
        }
    });
    let mut bins = bins;
    for r in refs {
        let c = r.centroid();
        let (min, max) = (Vec3A::from(r.bounds.min), Vec3A::from(r.bounds.max));
        for (axis, axis_bins) in bins.iter_mut().enumerate() {
            axis_bins[binner.bin(c, axis)].add(min, max);
        }
    }

    let mut best: Option<Split> = None;
    for (axis, axis_bins) in bins.iter().enumerate() {
        // A boundary between two empty bins gives the same partition as the boundary after the
        // last non-empty bin before it, so only boundaries after non-empty bins are candidates.
        // For the many small nodes near the leaves this skips most of the sweep.
        let mut occupied = [0u8; MAX_BINS];
        let mut m = 0;
        for (i, bin) in axis_bins[..cfg.bins].iter().enumerate() {
            if bin.count > 0 {
                occupied[m] = i as u8;
                m += 1;
            }
        }
        let occupied = &occupied[..m];
        // right_cost[k]: area * count of the occupied bins k.. .
        let mut right_cost = [0.0f64; MAX_BINS];
        let mut run = EMPTY_BIN;
        for k in (1..m).rev() {
            run.merge(&axis_bins[usize::from(occupied[k])]);
            right_cost[k] = run.cost();
        }
        let mut run = EMPTY_BIN;
        for k in 0..m.saturating_sub(1) {
            run.merge(&axis_bins[usize::from(occupied[k])]);
            let cost = run.cost() + right_cost[k + 1];
            // NaN and infinite costs never compare less, so they are never chosen.
            if cost < best.map_or(f64::INFINITY, |b| b.cost) {
                best = Some(Split {
                    axis,
                    last_left_bin: usize::from(occupied[k]),
                    cost,
                    binner,
                });
            }
        }
    }
    best
}

/// Moves the references satisfying `goes_left` to the front; returns how many there are.
fn partition(refs: &mut [PrimRef], goes_left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..refs.len() {
        if goes_left(&refs[i]) {
            refs.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

/// Splits at the median centroid along the widest centroid axis: the fallback when binning finds
/// nothing (coincident centroids) and the depth limiter. Always gives halves of `floor(n/2)` and
/// `ceil(n/2)`.
fn median_split(refs: &mut [PrimRef], centroids: &Aabb) -> usize {
    let axis = centroids.largest_axis();
    let mid = refs.len() / 2;
    refs.select_nth_unstable_by(mid, |a, b| {
        a.centroid()[axis].total_cmp(&b.centroid()[axis])
    });
    mid
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(max_leaf: usize) -> Config {
        Config::from(&BuildParams {
            max_leaf_size: max_leaf,
            ..BuildParams::default()
        })
    }

    #[test]
    fn ceil_log2_matches_definition() {
        assert_eq!(ceil_log2(1), 0);
        assert_eq!(ceil_log2(2), 1);
        assert_eq!(ceil_log2(3), 2);
        assert_eq!(ceil_log2(4), 2);
        assert_eq!(ceil_log2(5), 3);
        assert_eq!(ceil_log2(1 << 20), 20);
        assert_eq!(ceil_log2((1 << 20) + 1), 21);
    }

    #[test]
    fn params_are_clamped() {
        let c = Config::from(&BuildParams {
            max_leaf_size: 0,
            bins: 1000,
            traversal_cost: f32::NAN,
            intersection_cost: -1.0,
            parallel: false,
            ..BuildParams::default()
        });
        assert_eq!(c.max_leaf, 1);
        assert_eq!(c.bins, MAX_BINS);
        assert_eq!(c.traversal_cost, 1.0);
        assert_eq!(c.intersection_cost, 1.0);
    }

    #[test]
    fn coincident_centroids_split_by_median() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let built = build(&vec![tri; 100], &cfg(4));
        assert!(built.nodes.iter().all(|n| n.count <= 4));
        let mut order = built.order.clone();
        order.sort_unstable();
        assert!(order.iter().copied().eq(0..100));
    }

    #[test]
    fn lopsided_input_respects_depth_limit() {
        // Tiny triangles at exponentially growing distances: every SAH split peels off only the
        // farthest one, which without the limiter would give a chain 300 deep.
        let tris: Vec<[Vec3; 3]> = (0..300)
            .map(|i| {
                let x = 1.3f32.powi(i);
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1e-3, 0.0),
                    Vec3::new(x, 0.0, 1e-3),
                ]
            })
            .collect();
        let built = build(&tris, &cfg(1));
        let mut stack = vec![(0usize, 0usize)];
        let mut max_depth = 0;
        while let Some((i, d)) = stack.pop() {
            max_depth = max_depth.max(d);
            if let Some([l, r]) = built.nodes[i].children() {
                stack.push((l, d + 1));
                stack.push((r, d + 1));
            }
        }
        assert!(max_depth < MAX_DEPTH, "depth {max_depth}");
        assert!(
            max_depth > 20,
            "the input should have needed the limiter: {max_depth}"
        );
    }
}
