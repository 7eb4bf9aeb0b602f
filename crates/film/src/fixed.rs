//! Exact sums. Every statistic the film keeps is a sum over samples; each sample's value is
//! rounded once to a fixed-point grid of 2⁻³² and added into a 128-bit integer. Integer
//! addition is associative, so a pixel's sums are the same bits in whatever order its samples
//! arrive: two renders of sample ranges `0..a` and `a..b` (on two machines, or before and
//! after a checkpoint) add up to exactly the render of `0..b`, and so do image regions and
//! light-path splats that land in any order.
//!
//! Why not floating point with a fixed reduction order (per-block statistics combined along a
//! fixed tree, the other design the issue allows): it would make exactness depend on every
//! split falling on block boundaries and on every consumer following the tree, and a pixel
//! would hold one partial sum per tree level. Integers make any split exact with one sum.
//!
//! Costs, chosen on purpose:
//! - Resolution: 2⁻³² ≈ 2.3·10⁻¹⁰ per sample (the mean's error is below that), far under an
//!   `f32` output's precision for anything but near-black pixels.
//! - Range: a sample's value is clamped to ±2⁶⁰ (10¹⁸); the sums then hold 2³⁴ samples
//!   without overflow. It was ±2³¹ ("a radiance of two billion is a bug"), while a scene may
//!   have emitters of radiance `rt_core::material::MAX_RADIANCE` (10¹⁵): every sample seeing
//!   them was cut to 2·10⁹, and `bad/emitters-zero-and-max` came out at 6.5·10⁷ (path) and
//!   8.1·10⁷ (BDPT) where the image is 8.3·10¹¹.
//! - Squares (for variances) of values below 2³¹ are rounded from the rounded value on the
//!   2⁻³² grid, so a constant pixel's variance may come out as ~10⁻¹⁰ instead of zero; those
//!   of larger values, which would overflow it, go to a second sum on a grid of 2³²
//!   ([`Squares3`]; relative resolution 2⁻³⁰ or better).
//! - Memory: 16 bytes per channel and sum instead of 4 (see [`crate::FilmMemory`]), 32 for
//!   the squares of radiance.

use rt_core::glam::Vec3;

/// One unit of the grid, as a real number: 2³².
pub(crate) const ONE: f64 = 4_294_967_296.0;
/// Largest magnitude a sample's value is kept at: 2⁶⁰.
const LIMIT: f32 = (1u64 << 60) as f32;
/// Largest magnitude whose square the 2⁻³² grid holds (2³¹): squares of larger values go to
/// [`Squares3`]'s coarse sum; the features' squares ([`Sum3::add_squares`]) are clamped here.
const SQUARE_LIMIT: f32 = 2_147_483_648.0;

/// `x` on the grid, rounded to nearest (halves away from zero), clamped to ±2⁶⁰.
#[inline]
pub(crate) fn to_fixed(x: f32) -> i128 {
    let v = f64::from(x.clamp(-LIMIT, LIMIT)) * ONE;
    // `as` maps NaN (never passed: callers drop non-finite samples) to 0.
    (v + 0.5f64.copysign(v)) as i128
}

/// The square of `x` (clamped to ±2³¹) on the grid, rounded to nearest from the rounded value.
#[inline]
fn square(x: f32) -> i128 {
    let q = to_fixed(x.clamp(-SQUARE_LIMIT, SQUARE_LIMIT));
    (q * q + (1 << 31)) >> 32
}

/// `x²` for `|x| ≥ 2³¹` (clamped to 2⁶⁰) in units of 2³², rounded to nearest: the square of an
/// `f32` is exact in `f64`, and so is the division by a power of two.
#[inline]
fn coarse_square(x: f32) -> i128 {
    let x = f64::from(x.clamp(-LIMIT, LIMIT));
    (x * x / ONE).round() as i128
}

/// A grid sum as a real number. Sums that fit in 64 bits (nearly all) take the hardware
/// conversion; both round to nearest, so the value is the same either way.
#[inline]
pub(crate) fn real(s: i128) -> f64 {
    match i64::try_from(s) {
        Ok(v) => v as f64 / ONE,
        Err(_) => s as f64 / ONE,
    }
}

/// Exact sum of one scalar per sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Sum1(pub i128);

impl Sum1 {
    #[inline]
    pub fn add(&mut self, x: f32) {
        self.0 += to_fixed(x);
    }

    #[inline]
    pub fn add_square(&mut self, x: f32) {
        self.0 += square(x);
    }

    #[inline]
    pub fn merge(&mut self, o: &Sum1) {
        self.0 += o.0;
    }

    /// The sum divided by `n` (zero for `n = 0`).
    #[inline]
    pub fn mean(&self, n: u64) -> f32 {
        if n == 0 {
            return 0.0;
        }
        (real(self.0) / n as f64) as f32
    }
}

/// Exact sums of three channels per sample (a colour, a normal, a position).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Sum3(pub [i128; 3]);

impl Sum3 {
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        // Most parts of a lighting split and many AOVs are zero for a given sample.
        if v == Vec3::ZERO {
            return;
        }
        for (s, x) in self.0.iter_mut().zip(v.to_array()) {
            *s += to_fixed(x);
        }
    }

    #[inline]
    pub fn add_squares(&mut self, v: Vec3) {
        if v == Vec3::ZERO {
            return;
        }
        for (s, x) in self.0.iter_mut().zip(v.to_array()) {
            *s += square(x);
        }
    }

    #[inline]
    pub fn merge(&mut self, o: &Sum3) {
        for (s, x) in self.0.iter_mut().zip(o.0) {
            *s += x;
        }
    }

    #[inline]
    pub fn minus(&self, o: &Sum3) -> Sum3 {
        Sum3([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }

    /// The sums divided by `n` (zero for `n = 0`).
    #[inline]
    pub fn mean(&self, n: u64) -> Vec3 {
        if n == 0 {
            return Vec3::ZERO;
        }
        let k = n as f64;
        Vec3::from_array(self.0.map(|s| (real(s) / k) as f32))
    }
}

/// Unbiased sample variance from a count, a sum and a sum of squares, in `f64` (the sums are
/// exact, so only the final subtraction rounds); zero below two samples, never negative.
#[inline]
pub(crate) fn sample_variance(n: u64, sum: i128, squares: i128) -> f32 {
    variance_from(n, sum, real(squares))
}

/// [`sample_variance`] from the sum of squares as a real number.
#[inline]
fn variance_from(n: u64, sum: i128, squares: f64) -> f32 {
    if n < 2 {
        return 0.0;
    }
    let (s, n) = (real(sum), n as f64);
    ((squares - s * s / n) / (n - 1.0)).max(0.0) as f32
}

/// Exact sums of the squares of a colour's channels over a range of up to ±2⁶⁰: squares of
/// values below 2³¹ on the 2⁻³² grid (`fine`), of larger ones on a grid of 2³² (`coarse`), so
/// neither overflows and both stay integers (order-independent).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Squares3 {
    pub fine: [i128; 3],
    pub coarse: [i128; 3],
}

impl Squares3 {
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        if v == Vec3::ZERO {
            return;
        }
        for (k, x) in v.to_array().into_iter().enumerate() {
            if x.abs() < SQUARE_LIMIT {
                self.fine[k] += square(x);
            } else {
                self.coarse[k] += coarse_square(x);
            }
        }
    }

    #[inline]
    pub fn merge(&mut self, o: &Squares3) {
        for k in 0..3 {
            self.fine[k] += o.fine[k];
            self.coarse[k] += o.coarse[k];
        }
    }

    /// The sum of squares of channel `k` as a real number.
    #[inline]
    fn real(&self, k: usize) -> f64 {
        real(self.fine[k]) + self.coarse[k] as f64 * ONE
    }

    /// Unbiased sample variance per channel of `n` samples summing to `sum`.
    #[inline]
    pub fn variance(&self, n: u64, sum: &Sum3) -> Vec3 {
        Vec3::from_array(std::array::from_fn(|k| {
            variance_from(n, sum.0[k], self.real(k))
        }))
    }
}

/// [`sample_variance`] per channel.
#[inline]
pub(crate) fn sample_variance3(n: u64, sum: &Sum3, squares: &Sum3) -> Vec3 {
    Vec3::new(
        sample_variance(n, sum.0[0], squares.0[0]),
        sample_variance(n, sum.0[1], squares.0[1]),
        sample_variance(n, sum.0[2], squares.0[2]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_do_not_depend_on_order_and_round_to_the_grid() {
        let xs: Vec<f32> = (0..1000)
            .map(|i| ((i * 7919) % 1013) as f32 * 1e-3 + 1e-7 * i as f32)
            .collect();
        let mut forward = Sum3::default();
        let mut backward = Sum3::default();
        xs.iter().for_each(|&x| forward.add(Vec3::splat(x)));
        xs.iter().rev().for_each(|&x| backward.add(Vec3::splat(x)));
        assert_eq!(forward, backward);
        let (mut a, mut b) = (Sum3::default(), Sum3::default());
        xs[..333].iter().for_each(|&x| a.add(Vec3::splat(x)));
        xs[333..].iter().for_each(|&x| b.add(Vec3::splat(x)));
        a.merge(&b);
        assert_eq!(a, forward);
        let exact: f64 = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / 1000.0;
        assert!((f64::from(forward.mean(1000).x) - exact).abs() < 1e-6 * exact);
        assert_eq!(to_fixed(1.0), 1 << 32);
        assert_eq!(to_fixed(-0.75), -(3 << 30));
        assert_eq!(to_fixed(f32::MAX), 1 << 92, "clamped to 2^60");
        assert_eq!(to_fixed(1e-10), 0, "below half a unit");
        assert_eq!(to_fixed(2e-10), 1);
        // The fast conversion agrees with the general one across the 64-bit boundary.
        for s in [
            0i128,
            1,
            -7,
            (1 << 62) + 3,
            i64::MAX as i128,
            i64::MAX as i128 + 1,
            -(1 << 80) - 5,
        ] {
            assert_eq!(real(s).to_bits(), (s as f64 / ONE).to_bits(), "{s}");
        }
    }

    /// The mean and sample variance of `xs`, in `f64`.
    fn mean_and_variance(xs: &[f32]) -> (f64, f64) {
        let n = xs.len() as f64;
        let mean = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
        let var = xs
            .iter()
            .map(|&x| (f64::from(x) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (mean, var)
    }

    #[test]
    fn variance_from_exact_sums() {
        let xs = [0.5f32, 2.0, 7.25, 1.0, 1e-3, 4.0, 3.5];
        let (mut s, mut q) = (Sum1::default(), Sum1::default());
        for &x in &xs {
            s.add(x);
            q.add_square(x);
        }
        let (_, var) = mean_and_variance(&xs);
        let got = f64::from(sample_variance(xs.len() as u64, s.0, q.0));
        assert!((got - var).abs() < 1e-6 * var, "{got} vs {var}");
        // Large counts of the largest values stay in range.
        let mut big = Sum1::default();
        for _ in 0..1000 {
            big.add_square(2.0e9);
        }
        assert!(big.0 > 0);
        assert_eq!(sample_variance(1, 5, 5), 0.0);
    }

    /// Samples of an emitter of the largest radiance a scene may have (10¹⁵) keep their value
    /// and their variance; with the old clamp at 2³¹ the mean of these was 1.4·10⁹.
    #[test]
    fn bright_samples_keep_their_value_and_variance() {
        let xs = [1e15f32, 3e15, 0.5, 2e9, 7.0e12, 1e-3];
        let (mut s, mut q) = (Sum3::default(), Squares3::default());
        for &x in &xs {
            s.add(Vec3::splat(x));
            q.add(Vec3::splat(x));
        }
        let (mean, var) = mean_and_variance(&xs);
        let got_mean = f64::from(s.mean(xs.len() as u64).x);
        assert!(
            (got_mean - mean).abs() < 1e-6 * mean,
            "{got_mean} vs {mean}"
        );
        let got = f64::from(q.variance(xs.len() as u64, &s).y);
        assert!((got - var).abs() < 1e-6 * var, "{got} vs {var}");
        // 2³⁴ samples at the clamp do not overflow either sum.
        let top = f32::MAX;
        assert_eq!(to_fixed(top) << 34, (1i128 << 92) << 34);
        assert!(coarse_square(top).checked_mul(1 << 34).is_some());
    }
}
