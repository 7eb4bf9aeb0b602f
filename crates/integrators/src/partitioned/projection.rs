//! Projection maps (Jensen 1996; Dammertz 2011, §6.3.3): per light point, one bit per cell of
//! a 256 × 128 (φ, θ) map of its hemisphere, set where a specular triangle may be seen.
//! Caustic photons are only traced in set cells; the others could only reach a diffuse surface
//! first and would be discarded, so skipping them (and still counting them as emitted) changes
//! the cost, not the image.
//!
//! Deviation: each specular triangle is bounded by its bounding sphere's cone (half-angle
//! `asin(r / d)`) instead of the projected corners of its box. The cone is exactly
//! conservative, including near the pole and across the azimuth seam, where the corners'
//! rectangle is not; it sets a few more cells.

use rt_core::{frame::Frame, glam::Vec3};
use std::f32::consts::{PI, TAU};

/// Cells in azimuth.
pub(super) const PHI_CELLS: usize = 256;
/// Cells in polar angle.
pub(super) const THETA_CELLS: usize = 128;
const WORDS: usize = PHI_CELLS * THETA_CELLS / 64;

/// A specular triangle as the maps see it: its bounding sphere.
#[derive(Clone, Copy, Debug)]
pub(super) struct Occupant {
    pub center: Vec3,
    pub radius: f32,
}

/// The map of one light point.
pub(super) struct ProjectionMap {
    frame: Frame,
    /// Largest polar angle the map covers: π/2 for a one-sided emitter, π for two-sided.
    theta_max: f32,
    bits: Box<[u64; WORDS]>,
    set: usize,
}

impl ProjectionMap {
    /// The map of a light at `p` emitting around normal `n` (both hemispheres if
    /// `two_sided`), covering the cones of `occupants`.
    pub fn build(p: Vec3, n: Vec3, two_sided: bool, occupants: &[Occupant]) -> Self {
        let mut map = Self {
            frame: Frame::from_normal(n),
            theta_max: if two_sided { PI } else { PI / 2.0 },
            bits: Box::new([0; WORDS]),
            set: 0,
        };
        for o in occupants {
            map.cover(p, o);
            if map.set == PHI_CELLS * THETA_CELLS {
                break;
            }
        }
        map
    }

    /// Fraction of cells set.
    pub fn coverage(&self) -> f32 {
        self.set as f32 / (PHI_CELLS * THETA_CELLS) as f32
    }

    /// True if the cell of unit world direction `w` is set.
    pub fn allows(&self, w: Vec3) -> bool {
        let l = self.frame.to_local(w);
        let theta = l.z.clamp(-1.0, 1.0).acos();
        if theta > self.theta_max {
            return false;
        }
        let row = ((theta / self.theta_max) * THETA_CELLS as f32) as usize;
        let col = (((l.y.atan2(l.x) + PI) / TAU) * PHI_CELLS as f32) as usize;
        self.get(row.min(THETA_CELLS - 1), col.min(PHI_CELLS - 1))
    }

    fn get(&self, row: usize, col: usize) -> bool {
        let i = row * PHI_CELLS + col;
        self.bits[i / 64] >> (i % 64) & 1 == 1
    }

    fn set_cell(&mut self, row: usize, col: usize) {
        let i = row * PHI_CELLS + col;
        let (w, b) = (i / 64, 1u64 << (i % 64));
        if self.bits[w] & b == 0 {
            self.bits[w] |= b;
            self.set += 1;
        }
    }

    fn set_rows(&mut self, rows: std::ops::RangeInclusive<usize>, cols: Option<(f32, f32)>) {
        for row in rows {
            match cols {
                None => (0..PHI_CELLS).for_each(|c| self.set_cell(row, c)),
                Some((lo, hi)) => {
                    // Azimuth in [lo, hi] (radians, lo may be below -π, hi above π: the seam).
                    let to_col = |phi: f32| (((phi + PI) / TAU) * PHI_CELLS as f32).floor() as i64;
                    for c in to_col(lo)..=to_col(hi) {
                        self.set_cell(row, c.rem_euclid(PHI_CELLS as i64) as usize);
                    }
                }
            }
        }
    }

    /// Sets every cell the cone of `o`'s sphere seen from `p` touches.
    fn cover(&mut self, p: Vec3, o: &Occupant) {
        let v = o.center - p;
        let d = v.length();
        let all_rows = 0..=THETA_CELLS - 1;
        if d.is_nan() || d <= o.radius {
            // The light is inside the sphere (or the distance is not a number): everything.
            self.set_rows(all_rows, None);
            return;
        }
        let alpha = (o.radius / d).asin();
        let l = self.frame.to_local(v / d);
        let theta_c = l.z.clamp(-1.0, 1.0).acos();
        let lo = theta_c - alpha;
        let hi = theta_c + alpha;
        if lo > self.theta_max {
            return;
        }
        let to_row = |t: f32| {
            ((t.clamp(0.0, self.theta_max) / self.theta_max) * THETA_CELLS as f32) as usize
        };
        let rows = to_row(lo)..=to_row(hi).min(THETA_CELLS - 1);
        if lo <= 0.0 || hi >= PI {
            // The cone contains a pole: every azimuth.
            self.set_rows(rows, None);
            return;
        }
        let phi_c = l.y.atan2(l.x);
        // The azimuth half-width of a cone of half-angle α around polar angle θc, with no pole
        // inside (α < θc < π - α): asin(sin α / sin θc).
        let ratio = alpha.sin() / theta_c.sin();
        if ratio.is_nan() || ratio >= 1.0 {
            self.set_rows(rows, None);
            return;
        }
        let half = ratio.asin();
        // One cell of slack against rounding in the frame change.
        let slack = TAU / PHI_CELLS as f32;
        self.set_rows(rows, Some((phi_c - half - slack, phi_c + half + slack)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::rng::SplitMix64;
    use rt_core::sampling::uniform_sphere;

    /// Every direction that hits a sphere lands in a set cell: the map is conservative.
    #[test]
    fn directions_towards_an_occupant_are_always_allowed() {
        let mut rng = SplitMix64::new(3);
        for case in 0..200 {
            let p = Vec3::ZERO;
            let n = uniform_sphere(rng.vec2());
            let center = uniform_sphere(rng.vec2()) * (1.0 + 4.0 * rng.vec2().x);
            let radius = 0.05 + 0.5 * rng.vec2().x;
            let o = Occupant { center, radius };
            let map = ProjectionMap::build(p, n, case % 2 == 0, &[o]);
            for _ in 0..200 {
                // A direction inside the cone: towards a random point of the sphere.
                let q = center + uniform_sphere(rng.vec2()) * radius * rng.vec2().x.sqrt();
                let w = (q - p).normalize();
                let in_hemisphere = case % 2 == 0 || w.dot(n) >= 0.0;
                if in_hemisphere && (q - p).length() > radius {
                    assert!(
                        map.allows(w),
                        "case {case}: {w} towards {center} r {radius}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_small_occupant_covers_little_and_nothing_behind_is_set() {
        let o = Occupant {
            center: Vec3::new(7.0, 0.0, 7.0),
            radius: 0.5,
        };
        let map = ProjectionMap::build(Vec3::ZERO, Vec3::Z, false, &[o]);
        // A cone of 2.9° at 45° from the normal: a few cells of the 32768.
        assert!(
            map.coverage() > 0.0 && map.coverage() < 0.005,
            "{}",
            map.coverage()
        );
        let behind = Occupant {
            center: Vec3::new(0.0, 0.0, -10.0),
            radius: 0.5,
        };
        let empty = ProjectionMap::build(Vec3::ZERO, Vec3::Z, false, &[behind]);
        assert_eq!(empty.coverage(), 0.0);
        assert!(!map.allows(Vec3::X));
    }
}
