//! Triangle–box overlap: the separating axis test of Akenine-Möller ("Fast 3D triangle-box
//! overlap testing", JGT 2001), in double precision, and the conservative form the grids bin
//! with.

use super::Binning;
use glam::{DVec3, Vec3};

/// True if triangle `tri` and the box `min..max` (closed) overlap, by the separating axis test
/// in double precision. Degenerate triangles (segments, points) are handled: their vanishing
/// axes separate nothing.
pub fn triangle_box_overlap(tri: &[Vec3; 3], min: Vec3, max: Vec3) -> bool {
    let v = tri.map(|p| p.as_dvec3());
    let (c, h) = ((min + max).as_dvec3() * 0.5, (max - min).as_dvec3() * 0.5);
    sat(&v.map(|p| p - c), h, h)
}

/// Separating axis test of the triangle `v` (relative to the box centre) against the box of
/// half size `half_box` on the three box axes and `half_fat` on the other ten.
fn sat(v: &[DVec3; 3], half_box: DVec3, half_fat: DVec3) -> bool {
    for a in 0..3 {
        let lo = v[0][a].min(v[1][a]).min(v[2][a]);
        let hi = v[0][a].max(v[1][a]).max(v[2][a]);
        if lo > half_box[a] || hi < -half_box[a] {
            return false;
        }
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let n = e[0].cross(e[1]);
    if separates(n, v, half_fat) {
        return false;
    }
    for edge in e {
        for unit in [DVec3::X, DVec3::Y, DVec3::Z] {
            if separates(unit.cross(edge), v, half_fat) {
                return false;
            }
        }
    }
    true
}

#[inline(always)]
fn separates(axis: DVec3, v: &[DVec3; 3], half: DVec3) -> bool {
    let p = v.map(|x| axis.dot(x));
    let r = half.dot(axis.abs());
    p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r
}

/// One triangle prepared for binning.
pub(crate) struct Binner {
    v: [DVec3; 3],
    /// Bounding box.
    pub lo: DVec3,
    pub hi: DVec3,
    /// Extra growth of the cell on the non-box axes; infinite for slivers.
    fat: f64,
    binning: Binning,
}

impl Binner {
    /// `diagonal` is the domain's diagonal (the longest distance a hit is usually computed at).
    pub fn new(tri: &[Vec3; 3], diagonal: f64, binning: Binning) -> Self {
        let v = tri.map(|p| p.as_dvec3());
        let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
        let l2 = e.iter().map(|e| e.length_squared()).fold(0.0, f64::max);
        let cross = e[0].cross(e[1]).length();
        // Relative error of the watertight test's distance, ~ eps L^2 / |cross| (see the module
        // documentation), times the distance scale; `64 eps` leaves room for the constant.
        let fat = if cross > 0.0 {
            64.0 * f32::EPSILON as f64 * l2 / cross * diagonal
        } else {
            f64::INFINITY
        };
        Self {
            lo: v[0].min(v[1]).min(v[2]),
            hi: v[0].max(v[1]).max(v[2]),
            v,
            fat,
            binning,
        }
    }

    /// True if the triangle is to be listed in the cell `lo..hi` grown by `margin`.
    pub fn overlaps(&self, lo: DVec3, hi: DVec3, margin: DVec3) -> bool {
        let c = (lo + hi) * 0.5;
        let half_box = (hi - lo) * 0.5 + margin;
        if (self.lo - c).cmpgt(half_box).any() || (self.hi - c).cmplt(-half_box).any() {
            return false;
        }
        if self.binning == Binning::Boxes || !self.fat.is_finite() {
            return true;
        }
        let half_fat = half_box + DVec3::splat(self.fat);
        sat(&self.v.map(|p| p - c), half_box, half_fat)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separating_axes() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        // Inside, touching a face, and a big triangle cutting through the box.
        assert!(triangle_box_overlap(
            &[Vec3::splat(0.2), Vec3::splat(0.3), Vec3::new(0.2, 0.5, 0.2)],
            lo,
            hi
        ));
        assert!(triangle_box_overlap(
            &[
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0)
            ],
            lo,
            hi
        ));
        assert!(triangle_box_overlap(
            &[
                Vec3::new(-5.0, -5.0, 0.5),
                Vec3::new(5.0, -5.0, 0.5),
                Vec3::new(0.0, 5.0, 0.5)
            ],
            lo,
            hi
        ));
        // Overlapping boxes, separated by the triangle's plane.
        let far_corner = [
            Vec3::new(2.0, 0.9, 0.9),
            Vec3::new(0.9, 2.0, 0.9),
            Vec3::new(0.9, 0.9, 2.0),
        ];
        assert!(!triangle_box_overlap(&far_corner, lo, hi));
        // Separated by an edge axis only: the boxes and the planes overlap, x + y >= 2.1.
        let edge = [
            Vec3::new(1.6, 0.5, 0.5),
            Vec3::new(0.5, 1.6, 0.5),
            Vec3::new(1.6, 1.6, 0.5),
        ];
        assert!(!triangle_box_overlap(&edge, lo, hi));
        assert!(triangle_box_overlap(
            &edge.map(|v| v - Vec3::new(0.1, 0.1, 0.0)),
            lo,
            hi
        ));
        // A degenerate segment through the box, and one beside it.
        let seg = [Vec3::splat(-1.0), Vec3::splat(2.0), Vec3::splat(2.0)];
        assert!(triangle_box_overlap(&seg, lo, hi));
        let beside = [
            Vec3::new(-1.0, -1.0, 3.0),
            Vec3::new(2.0, 2.0, -3.0),
            Vec3::splat(2.0),
        ];
        assert!(triangle_box_overlap(&beside, lo, hi) == overlaps_by_sampling(&beside, lo, hi));
    }

    fn overlaps_by_sampling(t: &[Vec3; 3], lo: Vec3, hi: Vec3) -> bool {
        let n = 200;
        (0..=n).any(|i| {
            (0..=n - i).any(|j| {
                let (b1, b2) = (i as f32 / n as f32, j as f32 / n as f32);
                let p = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
                p.cmpge(lo).all() && p.cmple(hi).all()
            })
        })
    }

    #[test]
    fn agrees_with_sampling_on_random_triangles() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 3.0 - 1.0
        };
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        let (mut rejected_by_sat_only, mut sampled_in) = (0, 0);
        for _ in 0..2000 {
            let t = [0; 3].map(|_| Vec3::new(next(), next(), next()));
            let sat = triangle_box_overlap(&t, lo, hi);
            let sampled = overlaps_by_sampling(&t, lo, hi);
            // Sampling finds points of real overlaps only, so it never contradicts a `false`.
            assert!(sat || !sampled, "{t:?}");
            sampled_in += usize::from(sampled);
            let tb = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            let boxes = tb.0.cmple(hi).all() && tb.1.cmpge(lo).all();
            rejected_by_sat_only += usize::from(boxes && !sat);
        }
        assert!(sampled_in > 200 && rejected_by_sat_only > 50);
    }

    #[test]
    fn slivers_fall_back_to_their_box() {
        let sliver = [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.5, 0.5, 0.500001),
        ];
        let b = Binner::new(&sliver, 2.0, Binning::Exact);
        // A cell inside the box but off the sliver.
        let (lo, hi) = (DVec3::new(0.8, 0.0, 0.0), DVec3::new(1.0, 0.2, 0.2));
        assert!(b.overlaps(lo, hi, DVec3::ZERO));
        let good = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let b = Binner::new(&good, 2.0, Binning::Exact);
        assert!(!b.overlaps(
            DVec3::new(0.8, 0.8, 0.0),
            DVec3::new(1.0, 1.0, 0.1),
            DVec3::ZERO
        ));
    }
}
