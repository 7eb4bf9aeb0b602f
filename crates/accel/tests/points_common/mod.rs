//! Point sets shared by the point kd-tree tests: uniform, clustered, duplicated, lattice
//! (exact distance ties), flat and single-point sets, each with radii for the covering query.
#![allow(dead_code)] // each test binary uses a different subset

use glam::Vec3;
use rt_accel::points::PointItem;
pub use rt_testkit::Rng;

/// The kinds of point sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Uniform in [-1, 1]^3, radii log-uniform in [1e-3, 0.3].
    Uniform,
    /// Tight clusters of very different spreads, a few points far away; radii spanning 1e-4
    /// to 1 so that some subtrees hold large radii and others only small ones.
    Clustered,
    /// A quarter as many distinct points, each repeated (some payloads repeated too),
    /// coordinates on a 1/4 grid so that many are equal; radii 0, 0.25 or 0.5 exactly.
    Duplicated,
    /// Integer lattice points: distances from lattice and half-lattice queries tie exactly;
    /// radii exactly 1.
    Lattice,
    /// All on the plane z = 0.5 (no extent on one axis).
    Flat,
    /// One point repeated.
    Same,
}

pub const KINDS: [Kind; 6] = [
    Kind::Uniform,
    Kind::Clustered,
    Kind::Duplicated,
    Kind::Lattice,
    Kind::Flat,
    Kind::Same,
];

/// `n` items of `kind`; payloads are their input index unless the kind repeats them.
pub fn items(kind: Kind, n: usize, seed: u64) -> Vec<PointItem> {
    let mut rng = Rng::new(seed ^ ((kind as u64) << 32));
    match kind {
        Kind::Uniform => (0..n)
            .map(|i| {
                let r = 10f32.powf(rng.range(-3.0, -0.5));
                PointItem::with_radius(rng.cube(), i as u32, r)
            })
            .collect(),
        Kind::Clustered => {
            let centres: Vec<(Vec3, f32)> = (0..1 + n / 200)
                .map(|_| (rng.cube() * 10.0, 10f32.powf(rng.range(-4.0, 0.0))))
                .collect();
            (0..n)
                .map(|i| {
                    let p = if rng.chance(0.01) {
                        rng.cube() * 1000.0
                    } else {
                        let (c, s) = centres[rng.below(centres.len())];
                        c + rng.cube() * s
                    };
                    let r = if rng.chance(0.002) {
                        1.0
                    } else {
                        10f32.powf(rng.range(-4.0, -1.0))
                    };
                    PointItem::with_radius(p, i as u32, r)
                })
                .collect()
        }
        Kind::Duplicated => {
            let distinct: Vec<Vec3> = (0..n.div_ceil(4))
                .map(|_| (rng.cube() * 4.0).round() / 4.0)
                .collect();
            (0..n)
                .map(|i| {
                    let p = distinct[rng.below(distinct.len())];
                    let payload = if rng.chance(0.1) { 7 } else { i as u32 };
                    let r = [0.0, 0.25, 0.5][rng.below(3)];
                    PointItem::with_radius(p, payload, r)
                })
                .collect()
        }
        Kind::Lattice => {
            let side = (n as f32).cbrt().ceil().max(1.0) as usize;
            (0..n)
                .map(|i| {
                    let p = Vec3::new(
                        (i % side) as f32,
                        (i / side % side) as f32,
                        (i / (side * side)) as f32,
                    );
                    PointItem::with_radius(p, i as u32, 1.0)
                })
                .collect()
        }
        Kind::Flat => (0..n)
            .map(|i| {
                let mut p = rng.cube();
                p.z = 0.5;
                PointItem::with_radius(p, i as u32, rng.range(0.0, 0.2))
            })
            .collect(),
        Kind::Same => (0..n)
            .map(|i| PointItem::with_radius(Vec3::new(0.25, -0.5, 1.0), i as u32, 0.1))
            .collect(),
    }
}

/// Query points for `items`: random ones in (and a little beyond) their bounding box, the
/// stored points themselves and points a tiny step from them, points far outside, and
/// (for lattices) half-integer points equidistant from several items.
pub fn queries(items: &[PointItem], count: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng::new(seed.wrapping_mul(31) + 7);
    let (lo, hi) = items
        .iter()
        .fold((Vec3::splat(-1.0), Vec3::splat(1.0)), |(lo, hi), it| {
            (lo.min(it.point), hi.max(it.point))
        });
    let margin = (hi - lo) * 0.1;
    let mut qs = vec![Vec3::splat(1e6), Vec3::new(-3e5, 2.0, 0.0)];
    while qs.len() < count {
        let q = match rng.below(4) {
            0 if !items.is_empty() => items[rng.below(items.len())].point,
            1 if !items.is_empty() => {
                items[rng.below(items.len())].point
                    + rng.unit_vec() * 10f32.powf(rng.range(-6.0, -2.0))
            }
            2 => (rng.vec_in(0.0, 1.0) * (hi - lo)).floor() + lo + 0.5 * rng.below(2) as f32,
            _ => lo - margin + rng.vec_in(0.0, 1.0) * (hi - lo + 2.0 * margin),
        };
        qs.push(q);
    }
    qs
}
