//! The guide vector of every sample (SBMF step A, Bauszat thesis §4.2.1): first-hit shading
//! normal, world position and albedo, concatenated, each divided by its own standard deviation
//! so that one unit-σ Gaussian of the Euclidean distance weighs all three.
//!
//! Deviation (the thesis does not say how the features are scaled; seed-000 digest §1.3): the
//! position's σ is given in *pixel footprints*, the median world distance between the mean
//! hit positions of horizontally neighbouring pixels, so that it means the same in millimetres
//! and in metres and at any resolution (a σ of 16 footprints lets the filter reach about 16
//! pixels along a surface, not further). Misses keep their zero normal and albedo and sit at
//! the origin of the normalised position space: their zero normal is a whole unit normal away
//! from any hit's.

use rt_core::glam::DVec3;
use rt_film::SampleRecords;

/// Guide dimensions: normal (3), position (3), albedo (3).
pub(crate) const DIMS: usize = 9;

/// One sample's normalised guide.
pub(crate) type Guide = [f32; DIMS];

/// The guides of all samples, in record order.
pub(crate) fn guides(
    records: &SampleRecords,
    sigma_normal: f32,
    sigma_position: f32,
    sigma_albedo: f32,
) -> Vec<Guide> {
    let footprint = pixel_footprint(records);
    let inv_p = 1.0 / (sigma_position as f64 * footprint);
    let (inv_n, inv_a) = (1.0 / sigma_normal, 1.0 / sigma_albedo);
    (0..records.len())
        .map(|j| {
            let n = records.normal()[j] * inv_n;
            let a = records.albedo()[j] * inv_a;
            let p = if records.is_hit(j) {
                (records.position()[j].as_dvec3() * inv_p).as_vec3()
            } else {
                rt_core::glam::Vec3::ZERO
            };
            [n.x, n.y, n.z, p.x, p.y, p.z, a.x, a.y, a.z]
        })
        .collect()
}

/// The median world distance between the mean hit positions of horizontally neighbouring
/// pixels that both have hits (1 if there are none, or if the median is not positive).
fn pixel_footprint(records: &SampleRecords) -> f64 {
    let w = records.width() as usize;
    let mean_hit = |i: usize| {
        let (mut sum, mut n) = (DVec3::ZERO, 0u32);
        for j in records.pixel_range(i) {
            if records.is_hit(j) {
                sum += records.position()[j].as_dvec3();
                n += 1;
            }
        }
        (n > 0).then(|| sum / n as f64)
    };
    let means: Vec<Option<DVec3>> = (0..records.offsets().len() - 1).map(mean_hit).collect();
    let mut d: Vec<f64> = (0..means.len())
        .filter(|i| (i + 1) % w.max(1) != 0)
        .filter_map(|i| Some((means[i + 1]? - means[i]?).length()))
        .filter(|d| d.is_finite())
        .collect();
    if d.is_empty() {
        return 1.0;
    }
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    if *m > 0.0 {
        *m
    } else {
        1.0
    }
}

/// Squared Euclidean distance of two guides.
#[inline]
pub(crate) fn dist2(a: &Guide, b: &Guide) -> f32 {
    let mut s = 0.0;
    for d in 0..DIMS {
        let t = a[d] - b[d];
        s += t * t;
    }
    s
}

/// The Gaussian weight `φ` of Eqs. 4.1–4.4 (unit σ in normalised guide space).
#[inline]
pub(crate) fn phi(a: &Guide, b: &Guide) -> f32 {
    (-0.5 * dist2(a, b)).exp()
}
