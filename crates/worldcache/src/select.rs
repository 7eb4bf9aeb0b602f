//! Which point receives a sample (thesis §3.1, Eq. 1): one of the three nearest points, drawn
//! with "barycentric" probabilities, instead of always the nearest (hard Voronoi edges) or the
//! cell of a jittered position (Binder et al. 2019; holes under world-space filtering).
//!
//! The thesis' equations were lost in the text we have; we read Eq. 1.2–1.3 as the 3D analogue
//! of barycentric areas, `a_i = d_j² · d_k²` normalised, i.e. `w_i ∝ 1/d_i²` (inverse squared
//! distance), and Eq. 1.4 as the branchless inverse CDF
//! `i = sat(⌊ξ / w0⌋) + sat(⌊ξ / (w0 + w1)⌋)`. The nearest point always has the largest
//! probability. This is a reconstruction (seed digest §1.4, \[recon\]).

use crate::discretisation::{Connectivity, Discretisation};
use crate::hash::{pcg, unit};
use crate::key::Key;
use glam::Vec3;

/// How a sample at a position picks the point that receives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Selection {
    /// One of the three nearest points, with probabilities ∝ 1/d² (the thesis).
    Barycentric,
    /// Always the nearest point.
    Nearest,
    /// The nearest point to the position jittered in its tangent plane by up to `radius`
    /// point spacings (uniform on the disc; Binder et al. 2019).
    Jitter {
        /// Jitter radius in point spacings.
        radius: f32,
    },
}

/// The three nearest candidates, nearest first (fewer if fewer candidates exist).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest3 {
    /// Squared distances (infinite for missing entries).
    pub d2: [f32; 3],
    /// Positions.
    pub pos: [Vec3; 3],
    /// Keys (`Key(0)` for missing entries).
    pub key: [Key; 3],
}

/// The three candidates nearest to `x` under connectivity `c`. Ties are broken by key, so the
/// result does not depend on the enumeration order.
///
/// Voxels are visited nearest first and skipped once they lie wholly beyond the current
/// third-nearest distance, which gives the same three as scanning every voxel of the
/// neighbourhood (claim 5's test checks this against a full scan and brute force).
#[inline]
pub fn nearest3<D: Discretisation>(points: &D, x: Vec3, c: Connectivity) -> Nearest3 {
    let mut n = Nearest3::EMPTY;
    points.for_each_candidate_pruned(x, c, |p, k| {
        n.insert(x, p, k);
        n.d2[2]
    });
    n
}

impl Nearest3 {
    const EMPTY: Nearest3 = Nearest3 {
        d2: [f32::INFINITY; 3],
        pos: [Vec3::ZERO; 3],
        key: [Key(0); 3],
    };

    /// Offers candidate `p` (key `k`) for query `x`.
    #[inline]
    fn insert(&mut self, x: Vec3, p: Vec3, k: Key) {
        let n = self;
        let d2 = (p - x).length_squared();
        let before = |n: &Nearest3, i: usize| d2 < n.d2[i] || (d2 == n.d2[i] && k < n.key[i]);
        if !before(n, 2) {
            return;
        }
        let mut i = 2;
        while i > 0 && before(n, i - 1) {
            n.d2[i] = n.d2[i - 1];
            n.pos[i] = n.pos[i - 1];
            n.key[i] = n.key[i - 1];
            i -= 1;
        }
        n.d2[i] = d2;
        n.pos[i] = p;
        n.key[i] = k;
    }
}

/// Normalised selection probabilities of three points at squared distances `d2` (∝ 1/d²;
/// missing points, at infinite distance, get 0; a point at distance 0 gets everything).
#[inline]
pub fn barycentric_weights(d2: [f32; 3]) -> [f32; 3] {
    if d2[0] <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let inv = d2.map(|d| if d.is_finite() { 1.0 / d } else { 0.0 });
    let sum = inv[0] + inv[1] + inv[2];
    inv.map(|w| w / sum)
}

/// The branchless inverse CDF of Eq. 1.4: index 0, 1 or 2 for `xi` in [0, 1).
#[inline]
pub fn pick(w: [f32; 3], xi: f32) -> usize {
    let sat = |v: f32| v.floor().clamp(0.0, 1.0);
    let i = sat(xi / w[0]) + sat(xi / (w[0] + w[1]));
    // NaN (0/0 cannot happen for w0 > 0) would cast to 0.
    i as usize
}

/// The key that receives a sample at `x` (surface normal `n`) under `selection`, drawing from
/// the per-sample hash `xi` (e.g. of pixel and frame). `None` if no candidate exists (a voxel
/// outside the key range).
#[inline]
pub fn select<D: Discretisation>(
    points: &D,
    selection: Selection,
    c: Connectivity,
    x: Vec3,
    n: Vec3,
    xi: u32,
) -> Option<Key> {
    let h = pcg(xi);
    match selection {
        Selection::Barycentric => {
            let near = nearest3(points, x, c);
            let i = pick(barycentric_weights(near.d2), unit(h));
            Some(near.key[i]).filter(|k| k.0 != 0)
        }
        Selection::Nearest => Some(nearest3(points, x, c).key[0]).filter(|k| k.0 != 0),
        Selection::Jitter { radius } => {
            let (u1, u2) = (unit(h), unit(pcg(h)));
            let r = radius * points.spacing() * u1.sqrt();
            let phi = std::f32::consts::TAU * u2;
            let frame = rt_core::frame::Frame::from_normal(n.normalize_or(Vec3::Z));
            let xj = x + frame.s * (r * phi.cos()) + frame.t * (r * phi.sin());
            Some(nearest3(points, xj, c).key[0]).filter(|k| k.0 != 0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pick_is_the_inverse_cdf() {
        let w = [0.5, 0.3, 0.2];
        assert_eq!(pick(w, 0.0), 0);
        assert_eq!(pick(w, 0.49), 0);
        assert_eq!(pick(w, 0.51), 1);
        assert_eq!(pick(w, 0.79), 1);
        assert_eq!(pick(w, 0.81), 2);
        assert_eq!(pick(w, 0.999_999), 2);
        assert_eq!(pick([1.0, 0.0, 0.0], 0.99), 0);
    }

    #[test]
    fn weights_are_inverse_squared_distance() {
        let w = barycentric_weights([1.0, 2.0, 4.0]);
        // 1 : 1/2 : 1/4 normalised.
        assert!((w[0] - 4.0 / 7.0).abs() < 1e-6);
        assert!((w[1] - 2.0 / 7.0).abs() < 1e-6);
        assert!((w[2] - 1.0 / 7.0).abs() < 1e-6);
    }
}
