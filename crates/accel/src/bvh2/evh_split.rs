//! Triangle splitting before the build: the Edge Volume Heuristic and the Bounding Box Area
//! Heuristic (Dammertz, "Acceleration Methods for Ray Tracing based Global Illumination", 2011,
//! §4.3).
//!
//! The box of a long triangle that is not aligned with the axes is mostly empty space, and every
//! ray through that space tests the triangle for nothing. Splitting the triangle at edge
//! midpoints gives pieces with much tighter boxes. The pieces are never stored or intersected:
//! each becomes one *reference* (its box and the original triangle's index), the builder
//! partitions the references, and a leaf intersects the original triangle, so hits stay exact.
//!
//! - EVH splits at the edge whose edge box has the largest volume while that volume exceeds
//!   `V_scene / 2^t`. Edges in an axis plane have no volume and are never split, so tight
//!   axis-aligned triangles cost nothing. Whether and where an edge is split depends only on the
//!   edge, so the two triangles sharing an edge split it at the same points and closed meshes
//!   stay closed without any topology information.
//! - BBAH splits while the piece's box area exceeds `A_scene / 2^t`. The thesis does not say
//!   which edge; the EVH rule is used, falling back to the longest edge when every edge lies in
//!   an axis plane. It makes sizes more uniform but is not watertight and adds many more
//!   references.
//!
//! References are counted first and then written into an exactly sized array, as in the thesis:
//! scanning twice is cheaper than growing the array.

use super::build::PrimRef;
use super::Split;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use rt_core::Aabb;
use std::cmp::Ordering;

/// Levels of splitting per triangle at most. A piece at this depth is one of up to 2^24 pieces
/// of its triangle; only thresholds far beyond the thesis' t = 14 get here, and it stops a huge
/// `t` (a threshold of zero) from splitting down to rounding noise.
const MAX_SPLIT_DEPTH: u32 = 24;

/// Triangles per unit of parallel work.
const CHUNK: usize = 1024;

/// The references of `triangles` under `split`, one per piece, in triangle order: what
/// [`Bvh2::build`](super::Bvh2::build) partitions. For tests and benchmarks (the number of
/// references over the number of triangles is the memory and build cost of splitting).
pub fn split_references(triangles: &[[Vec3; 3]], split: Split) -> Vec<(Aabb, u32)> {
    references(triangles, split, true)
        .into_iter()
        .map(|r| (r.bounds, r.index))
        .collect()
}

/// The pieces of `triangles` under `split` with their original triangle's index, in the order
/// of [`split_references`]. For tests: shared edges must be split at the same points.
pub fn split_pieces(triangles: &[[Vec3; 3]], split: Split) -> Vec<([Vec3; 3], u32)> {
    let mut out = Vec::new();
    let splitter = Splitter::new(split, triangles);
    for (i, tri) in triangles.iter().enumerate() {
        match &splitter {
            Some(s) => s.for_each_piece(tri, &mut |piece, _| out.push((*piece, i as u32))),
            None => out.push((*tri, i as u32)),
        }
    }
    out
}

/// The builder's references: one per triangle without splitting, one per piece with it.
///
/// # Panics
///
/// If there are more than `u32::MAX / 2` references, the most node indices can address.
pub(super) fn references(triangles: &[[Vec3; 3]], split: Split, parallel: bool) -> Vec<PrimRef> {
    let Some(splitter) = Splitter::new(split, triangles) else {
        check_count(triangles.len());
        return triangles
            .iter()
            .enumerate()
            .map(|(i, t)| PrimRef {
                bounds: Aabb::from_points(t),
                index: i as u32,
            })
            .collect();
    };

    let count = |chunk: &[[Vec3; 3]]| chunk.iter().map(|t| splitter.count(t)).sum::<usize>();
    let counts: Vec<usize> = if parallel {
        triangles.par_chunks(CHUNK).map(count).collect()
    } else {
        triangles.chunks(CHUNK).map(count).collect()
    };
    check_count(counts.iter().sum());

    let mut refs = vec![
        PrimRef {
            bounds: Aabb::EMPTY,
            index: 0,
        };
        counts.iter().sum()
    ];
    let mut outs = Vec::with_capacity(counts.len());
    let mut rest = refs.as_mut_slice();
    for &n in &counts {
        let (head, tail) = rest.split_at_mut(n);
        outs.push(head);
        rest = tail;
    }
    let emit = |(c, (chunk, out)): (usize, (&[[Vec3; 3]], &mut [PrimRef]))| {
        let mut slots = out.iter_mut();
        for (k, tri) in chunk.iter().enumerate() {
            let index = (c * CHUNK + k) as u32;
            splitter.for_each_piece(tri, &mut |_, bounds| {
                // The count pass ran the same deterministic recursion.
                *slots.next().expect("count and emit passes disagree") = PrimRef { bounds, index };
            });
        }
    };
    if parallel {
        triangles
            .par_chunks(CHUNK)
            .zip(outs)
            .enumerate()
            .for_each(emit);
    } else {
        triangles.chunks(CHUNK).zip(outs).enumerate().for_each(emit);
    }
    refs
}

fn check_count(n: usize) {
    // Node indices are u32 and there are up to 2n - 1 nodes.
    assert!(
        n <= (u32::MAX / 2) as usize,
        "Bvh2 supports at most 2^31 - 1 triangle references, got {n}"
    );
}

/// When a piece is split.
#[derive(Clone, Copy, Debug)]
enum Rule {
    /// While its largest edge-box volume exceeds the threshold.
    EdgeVolume,
    /// While its box area exceeds the threshold.
    BoxArea,
}

/// A heuristic with the threshold it takes from the scene.
#[derive(Clone, Copy, Debug)]
struct Splitter {
    rule: Rule,
    threshold: f64,
}

impl Splitter {
    /// `None` when nothing can be split: no splitting asked for, or a flat, empty or overflowing
    /// scene (where `V / 2^t` or `A / 2^t` means nothing).
    ///
    /// The scene box covers the finite triangles only, so one infinite triangle does not turn
    /// splitting off for the rest.
    fn new(split: Split, triangles: &[[Vec3; 3]]) -> Option<Self> {
        let (rule, t) = match split {
            Split::None => return None,
            Split::Evh { t } => (Rule::EdgeVolume, t),
            Split::Bbah { t } => (Rule::BoxArea, t),
        };
        let scene = triangles
            .iter()
            .filter(|t| is_finite(t))
            .fold(Aabb::EMPTY, |b, t| b.union(Aabb::from_points(t)));
        let e = scene.extent().as_dvec3();
        let measure = match rule {
            Rule::EdgeVolume => e.x * e.y * e.z,
            Rule::BoxArea => area(e),
        };
        // 0.5^t underflows to zero for huge t; the depth limit then ends the recursion.
        let threshold = measure * 0.5f64.powi(t.min(2048) as i32);
        (measure > 0.0 && measure.is_finite()).then_some(Self { rule, threshold })
    }

    /// Number of pieces `tri` is split into.
    fn count(&self, tri: &[Vec3; 3]) -> usize {
        let mut n = 0;
        self.for_each_piece(tri, &mut |_, _| n += 1);
        n
    }

    /// Calls `f` with every piece of `tri` and the piece's box. Degenerate and non-finite
    /// triangles are not split.
    fn for_each_piece(&self, tri: &[Vec3; 3], f: &mut impl FnMut(&[Vec3; 3], Aabb)) {
        let bounds = Aabb::from_points(tri);
        if !is_finite(tri) || is_degenerate(tri) {
            f(tri, bounds);
            return;
        }
        let magnitude = bounds.min.abs().max(bounds.max.abs());
        self.recurse(tri, 0, &bounds, magnitude, f);
    }

    fn recurse(
        &self,
        piece: &[Vec3; 3],
        depth: u32,
        tri_bounds: &Aabb,
        magnitude: Vec3,
        f: &mut impl FnMut(&[Vec3; 3], Aabb),
    ) {
        if depth < MAX_SPLIT_DEPTH {
            if let Some(k) = self.edge_to_split(piece) {
                let (a, b, c) = (piece[k], piece[(k + 1) % 3], piece[(k + 2) % 3]);
                // Floating-point addition is commutative, so both triangles of a shared edge
                // get the same point, which `a + (b - a) * 0.5` would not guarantee. Halving
                // first keeps the sum finite for coordinates near `f32::MAX`.
                let m = a * 0.5 + b * 0.5;
                if m != a && m != b {
                    self.recurse(&[a, m, c], depth + 1, tri_bounds, magnitude, f);
                    self.recurse(&[m, b, c], depth + 1, tri_bounds, magnitude, f);
                    return;
                }
            }
        }
        f(
            piece,
            conservative_bounds(piece, depth, tri_bounds, magnitude),
        );
    }

    /// The edge (`k` for `piece[k]`–`piece[k + 1]`) to split next, or `None` to stop.
    fn edge_to_split(&self, piece: &[Vec3; 3]) -> Option<usize> {
        let edges = [0, 1, 2].map(|k| Edge::new(piece[k], piece[(k + 1) % 3]));
        let by_volume = |i: &usize, j: &usize| edges[*i].cmp_volume(&edges[*j]);
        let k = (0..3).max_by(by_volume)?;
        match self.rule {
            Rule::EdgeVolume => (edges[k].volume > self.threshold).then_some(k),
            Rule::BoxArea => {
                let e = Aabb::from_points(piece).extent().as_dvec3();
                if area(e) <= self.threshold {
                    None
                } else if edges[k].volume > 0.0 {
                    Some(k)
                } else {
                    (0..3).max_by(|i, j| edges[*i].cmp_length(&edges[*j]))
                }
            }
        }
    }
}

/// What the split decision looks at of an edge. Everything is symmetric in the endpoints, so the
/// decision is the same from either triangle of a shared edge.
struct Edge {
    volume: f64,
    length2: f64,
    /// The endpoints, lexicographically smaller first: the tie-breaker, so that equal volumes
    /// are ordered by the edges themselves and not by their place in the triangle.
    key: [Vec3; 2],
}

impl Edge {
    fn new(a: Vec3, b: Vec3) -> Self {
        let d = (a.as_dvec3() - b.as_dvec3()).abs();
        let key = if lex_cmp(a, b) == Ordering::Greater {
            [b, a]
        } else {
            [a, b]
        };
        Self {
            volume: d.x * d.y * d.z,
            length2: d.length_squared(),
            key,
        }
    }

    fn cmp_volume(&self, o: &Self) -> Ordering {
        self.volume
            .total_cmp(&o.volume)
            .then_with(|| self.cmp_key(o))
    }

    fn cmp_length(&self, o: &Self) -> Ordering {
        self.length2
            .total_cmp(&o.length2)
            .then_with(|| self.cmp_key(o))
    }

    fn cmp_key(&self, o: &Self) -> Ordering {
        lex_cmp(self.key[0], o.key[0]).then_with(|| lex_cmp(self.key[1], o.key[1]))
    }
}

fn lex_cmp(a: Vec3, b: Vec3) -> Ordering {
    a.x.total_cmp(&b.x)
        .then_with(|| a.y.total_cmp(&b.y))
        .then_with(|| a.z.total_cmp(&b.z))
}

/// The box of a piece at `depth`, grown so that the boxes of all pieces cover the whole original
/// triangle despite the rounded midpoints.
///
/// Each midpoint is within `u·M` per axis of the exact midpoint of its two (already rounded)
/// endpoints, with `u = 2^-24` and `M` the largest magnitude of the triangle on that axis, so by
/// induction a vertex made at depth `d` is within `d·u·M` of where exact arithmetic would have
/// put it. The exact pieces tile the triangle, and a point of an exact piece is within the same
/// distance of the rounded piece, so growing by `d·u·M` (doubled, to absorb the rounding of the
/// growth itself, plus the smallest subnormal per level, for halving subnormals) is enough. The
/// grown box never leaves the triangle's box, which holds every exact piece; for a triangle in
/// an axis plane it therefore stays flat.
fn conservative_bounds(piece: &[Vec3; 3], depth: u32, tri_bounds: &Aabb, magnitude: Vec3) -> Aabb {
    let b = Aabb::from_points(piece);
    if depth == 0 {
        return b;
    }
    let d = depth as f32;
    let slack = magnitude * ((d + 2.0) * f32::EPSILON) + Vec3::splat(d * f32::from_bits(1));
    Aabb::new(
        (b.min - slack).max(tri_bounds.min),
        (b.max + slack).min(tri_bounds.max),
    )
}

fn area(e: DVec3) -> f64 {
    2.0 * (e.x * e.y + e.x * e.z + e.y * e.z)
}

fn is_finite(tri: &[Vec3; 3]) -> bool {
    tri.iter().all(|v| v.is_finite())
}

/// Zero area: collinear or coincident vertices. Such a triangle can never be hit through its
/// interior, so there is nothing to tighten.
fn is_degenerate(tri: &[Vec3; 3]) -> bool {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    (b - a).cross(c - a) == DVec3::ZERO
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pieces(tri: [Vec3; 3], split: Split, scene: &[[Vec3; 3]]) -> Vec<[Vec3; 3]> {
        let s = Splitter::new(split, scene).unwrap();
        let mut out = Vec::new();
        s.for_each_piece(&tri, &mut |p, _| out.push(*p));
        assert_eq!(out.len(), s.count(&tri));
        out
    }

    /// A diagonal triangle and a unit box: the scene box is the unit cube.
    fn scene(tri: [Vec3; 3]) -> Vec<[Vec3; 3]> {
        vec![tri, [Vec3::ZERO, Vec3::ONE, Vec3::ONE]]
    }

    #[test]
    fn edge_decision_ignores_direction_and_position_in_triangle() {
        let (a, b) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.9, 0.7, 0.8));
        let (e, f) = (Edge::new(a, b), Edge::new(b, a));
        assert_eq!(e.volume, f.volume);
        assert_eq!(e.key, f.key);
        assert_eq!(a * 0.5 + b * 0.5, b * 0.5 + a * 0.5);
    }

    #[test]
    fn evh_splits_diagonal_edges_until_below_threshold() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.5),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let t = 9;
        let p = pieces(tri, Split::Evh { t }, &scene(tri));
        assert!(p.len() > 1);
        let eps = 0.5f64.powi(t as i32);
        for piece in &p {
            for k in 0..3 {
                assert!(Edge::new(piece[k], piece[(k + 1) % 3]).volume <= eps);
            }
        }
        let area = |t: &[Vec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).length() as f64;
        let total: f64 = p.iter().map(area).sum();
        assert!((total - area(&tri)).abs() < 1e-5 * area(&tri));
    }

    #[test]
    fn evh_never_splits_axis_plane_triangles() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(pieces(tri, Split::Evh { t: 30 }, &scene(tri)), vec![tri]);
        // BBAH does, by the longest edge.
        assert!(pieces(tri, Split::Bbah { t: 6 }, &scene(tri)).len() > 1);
    }

    #[test]
    fn flat_or_empty_scenes_and_bad_triangles_are_not_split() {
        let flat = [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert!(Splitter::new(Split::Evh { t: 14 }, &[flat]).is_none());
        assert!(Splitter::new(Split::Evh { t: 14 }, &[]).is_none());
        assert!(Splitter::new(Split::None, &scene(flat)).is_none());
        let inf = [Vec3::ZERO, Vec3::ONE, Vec3::new(f32::INFINITY, 0.0, 1.0)];
        let collinear = [Vec3::ZERO, Vec3::ONE, Vec3::splat(0.5)];
        let mut tris = scene(flat);
        tris.push(inf);
        let s = Splitter::new(Split::Evh { t: 20 }, &tris).unwrap();
        assert_eq!(s.count(&inf), 1);
        assert_eq!(s.count(&collinear), 1);
    }

    #[test]
    fn huge_t_stops_where_midpoints_stop_moving() {
        // A threshold of zero splits every edge with volume; a triangle a few ulps wide runs out
        // of representable midpoints after a few levels instead of reaching the depth limit.
        let ulp = f32::EPSILON;
        let tri = [
            Vec3::ONE,
            Vec3::ONE + Vec3::new(4.0, 4.0, 2.0) * ulp,
            Vec3::ONE + Vec3::new(0.0, 4.0, 4.0) * ulp,
        ];
        let s = Splitter::new(Split::Evh { t: u32::MAX }, &scene(tri)).unwrap();
        assert_eq!(s.threshold, 0.0);
        let n = s.count(&tri);
        assert!(1 < n && n < 1000, "{n} pieces");
    }

    #[test]
    fn piece_boxes_stay_inside_the_triangle_box() {
        let tri = [
            Vec3::new(1e5, -3.0, 7.0),
            Vec3::new(1e5 + 1.0, 3.0, -7.0),
            Vec3::new(-2.0, 0.1, 0.3),
        ];
        let tri_box = Aabb::from_points(&tri);
        let s = Splitter::new(Split::Bbah { t: 12 }, &scene(tri)).unwrap();
        let mut union = Aabb::EMPTY;
        s.for_each_piece(&tri, &mut |p, b| {
            assert!(b.min.cmple(Aabb::from_points(p).min).all());
            assert!(b.min.cmpge(tri_box.min).all() && b.max.cmple(tri_box.max).all());
            union = union.union(b);
        });
        assert_eq!(union, tri_box);
    }
}
