//! "The same image within noise": a z-test of two renders on blocks of pixels.
//!
//! Each pixel of a film carries its mean and the estimated variance of that mean (exact sums, in
//! `rt-film`). For independent renders `a` and `b` of the same image, the difference of the
//! sums over a block of pixels has variance `Σ (var_a + var_b)`, so
//! `z = Σ (mean_a − mean_b) / sqrt(Σ (var_a + var_b))` is close to standard normal per block
//! and channel (the central limit theorem over the block's pixels and samples); the same holds
//! for the whole image. The test fails if any `|z|` exceeds the two-sided normal quantile at a
//! family-wise false-alarm rate `α`, half of it split over the blocks and channels and half
//! over the three whole-image channels (Bonferroni), so the tolerances follow from the
//! estimator's variance and `α` alone. Blocks localise leaks and missing shadows; the whole
//! image catches faint acne spread everywhere.
//!
//! Variances estimated from a few independent runs ([`Estimate::from_runs`], e.g. 16) are
//! themselves uncertain: the difference over their square root follows Student's t with the
//! Welch–Satterthwaite degrees of freedom (15 for a block whose variance is all from 16 runs,
//! more where a film's sample variance or many pixels' run variances add up), whose tails are
//! far heavier than the normal's at the quantiles used here (two-sided 10⁻⁵: t₁₅ 6.9 against
//! 4.4). Each `z` is therefore reported as the normal quantile of the same tail probability
//! ([`normal_equivalent`]), and judged against the normal critical values, so that `α` is the
//! false-alarm rate it claims either way.
//!
//! Two guards: a pixel whose samples were all equal has zero estimated variance, and there the
//! means may still differ by the rounding of the running mean, so each pixel's variance is at
//! least `(ε · mean)²` (ε the f32 machine epsilon); and our variance estimate treats the
//! stratified Sobol' samples as independent, which overestimates it (`docs/validation.md`), so
//! the test is conservative rather than flaky.

use rt_film::Film;

/// Outcome of [`compare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Blocks × channels tested.
    pub block_tests: usize,
    /// Largest `|z|` over the blocks.
    pub max_block_z: f64,
    /// Tolerance of the blocks: the two-sided normal quantile at `α / 2` split over them.
    pub block_crit: f64,
    /// `z` of the whole-image difference, of the channel with the largest `|z|`.
    pub image_z: f64,
    /// Tolerance of the whole image: the two-sided quantile at `α / 2` split over 3 channels.
    pub image_crit: f64,
}

impl Comparison {
    /// True if neither a block nor the whole image differs by more than its tolerance.
    pub fn same_within_noise(&self) -> bool {
        self.max_block_z <= self.block_crit && self.image_z.abs() <= self.image_crit
    }

    /// The larger of `max|z| / tolerance` of the blocks and of the whole image: above 1 means
    /// a difference was detected.
    pub fn detection(&self) -> f64 {
        (self.max_block_z / self.block_crit).max(self.image_z.abs() / self.image_crit)
    }
}

/// Family-wise false-alarm probability of the comparisons of the stress suite. Their seeds are
/// fixed, so a false alarm would be a reproducible failure, not a flaky one; 10⁻³ keeps it
/// unlikely across every case and budget while leaving the test its power.
pub const ALPHA: f64 = 1e-3;

/// Compares two films of the same size on `block × block` pixel blocks (edge blocks smaller)
/// and as a whole. Half of `alpha` goes to the blocks, half to the whole image: a faint change
/// everywhere (acne) shows in the whole image long before any one block, a local one (a leak
/// in a corner) in its block.
///
/// # Panics
/// If the films differ in size (a bug in the caller).
pub fn compare(a: &Film, b: &Film, block: u32, alpha: f64) -> Comparison {
    assert_eq!((a.width(), a.height()), (b.width(), b.height()));
    let estimate = |f: &Film| Estimate {
        mean: f.mean_image(),
        variance: f
            .variance_image()
            .expect("compared films keep the variance buffer"),
        runs: None,
    };
    compare_estimates(&estimate(a), &estimate(b), a.width(), block, alpha)
}

/// Per-pixel estimates and the variances of those estimates, row-major: what [`compare`] reads
/// from a film, or what independent renders give for a technique whose film knows no
/// per-pixel variance (a light tracer's splats: [`Estimate::from_runs`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Pixel estimates.
    pub mean: Vec<rt_core::Rgb>,
    /// Variance of each pixel estimate.
    pub variance: Vec<rt_core::Rgb>,
    /// `Some(k)`: the variances are the spread of `k` independent runs ([`Estimate::from_runs`]),
    /// estimates with `k − 1` degrees of freedom, so a difference over their square root
    /// follows Student's t, not the normal. `None`: estimated from many samples per pixel (a
    /// film's variance buffer), where the normal is right.
    pub runs: Option<u32>,
}

impl Estimate {
    /// The average of independent images of one estimator (at least 2) and, per pixel, the
    /// variance of that average from their spread.
    ///
    /// # Panics
    /// With fewer than two images or images of different sizes.
    pub fn from_runs(runs: &[Vec<rt_core::Rgb>]) -> Self {
        assert!(runs.len() >= 2, "the spread needs two runs at least");
        let n = runs[0].len();
        assert!(runs.iter().all(|r| r.len() == n));
        let k = runs.len() as f32;
        let mean: Vec<rt_core::Rgb> = (0..n)
            .map(|i| runs.iter().map(|r| r[i]).sum::<rt_core::Rgb>() / k)
            .collect();
        let variance = (0..n)
            .map(|i| {
                let ss: rt_core::Rgb = runs.iter().map(|r| (r[i] - mean[i]).powf(2.0)).sum();
                ss / ((k - 1.0) * k)
            })
            .collect();
        Self {
            mean,
            variance,
            runs: Some(runs.len() as u32),
        }
    }
}

/// [`compare`] on two estimates of an image `width` pixels wide.
///
/// # Panics
/// If the estimates differ in size (a bug in the caller).
pub fn compare_estimates(
    a: &Estimate,
    b: &Estimate,
    width: u32,
    block: u32,
    alpha: f64,
) -> Comparison {
    assert_eq!(a.mean.len(), b.mean.len());
    let w = width.max(1);
    let h = a.mean.len() as u32 / w;
    let block = block.max(1);
    let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
    // Per block and channel: sum of differences, sum of variances, and the Welch–Satterthwaite
    // denominator `Σ v²/(k − 1)` of the variances estimated from runs.
    let mut sums = vec![[(0.0f64, 0.0f64, 0.0f64); 3]; (bw * bh) as usize];
    let mut image = [(0.0f64, 0.0f64, 0.0f64); 3];
    let welch = |v: f64, runs: Option<u32>| match runs {
        Some(k) => v * v / f64::from(k.max(2) - 1),
        None => 0.0,
    };
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (ma, mb) = (a.mean[i], b.mean[i]);
            let (va, vb) = (a.variance[i], b.variance[i]);
            let k = ((y / block) * bw + x / block) as usize;
            for c in 0..3 {
                let floor = |m: f32| (f32::EPSILON as f64 * m as f64).powi(2);
                let d = ma[c] as f64 - mb[c] as f64;
                let (va, vb) = (
                    (va[c] as f64).max(floor(ma[c])),
                    (vb[c] as f64).max(floor(mb[c])),
                );
                let q = welch(va, a.runs) + welch(vb, b.runs);
                for s in [&mut sums[k][c], &mut image[c]] {
                    s.0 += d;
                    s.1 += va + vb;
                    s.2 += q;
                }
            }
        }
    }
    let z = |(d, v, q): (f64, f64, f64)| {
        if d == 0.0 {
            0.0
        } else {
            normal_equivalent(d / v.sqrt(), v * v / q)
        }
    };
    let max_block_z = sums
        .iter()
        .flatten()
        .map(|s| z(*s).abs())
        .fold(0.0f64, f64::max);
    let image_z =
        image.iter().map(|s| z(*s)).fold(
            0.0f64,
            |best, zi| if zi.abs() > best.abs() { zi } else { best },
        );
    let block_tests = sums.len() * 3;
    Comparison {
        block_tests,
        max_block_z,
        block_crit: normal_quantile_upper(alpha / 2.0 / (2.0 * block_tests as f64)),
        image_z,
        image_crit: normal_quantile_upper(alpha / 2.0 / (2.0 * 3.0)),
    }
}

/// Mean over all pixels and channels of a film that keeps its variance buffer, and its standard
/// error (from the per-pixel variances of the mean; pixels are independent).
///
/// # Panics
/// If the film keeps no variance buffer.
pub fn image_mean(film: &Film) -> (f64, f64) {
    let n = film.pixels().len() as f64 * 3.0;
    let (mut sum, mut var) = (0.0, 0.0);
    for p in film.pixels() {
        let (m, v) = (
            p.mean(),
            p.variance_of_mean().expect("the film keeps its variance"),
        );
        sum += (m.x + m.y + m.z) as f64;
        var += (v.x + v.y + v.z) as f64;
    }
    (sum / n, var.sqrt() / n)
}

/// Complementary error function, `erfc(x)`, with relative error below 1.2·10⁻⁷ everywhere
/// (Numerical Recipes' Chebyshev fit).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// The standard normal value with the tail probability of `t` under Student's t with `nu`
/// degrees of freedom (sign kept; `nu` infinite or beyond 10⁶: `t` itself). What a t
/// statistic is worth on the normal scale of [`Comparison`]'s critical values.
pub fn normal_equivalent(t: f64, nu: f64) -> f64 {
    if !nu.is_finite() || nu > 1e6 || t == 0.0 {
        return t;
    }
    let p = student_t_upper(t.abs(), nu);
    let z = if p <= 0.0 {
        40.0
    } else {
        normal_quantile_upper(p.min(0.5))
    };
    z.copysign(t)
}

/// `P(T > t)` for Student's t with `nu` degrees of freedom and `t ≥ 0`:
/// `I_{ν/(ν+t²)}(ν/2, 1/2) / 2`.
pub fn student_t_upper(t: f64, nu: f64) -> f64 {
    0.5 * incomplete_beta(0.5 * nu, 0.5, nu / (nu + t * t))
}

/// The regularised incomplete beta function `I_x(a, b)` by its continued fraction (Numerical
/// Recipes §6.4: modified Lentz, relative accuracy about 10⁻¹⁴).
fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_fraction(b, a, 1.0 - x) / b
    }
}

fn beta_fraction(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < tiny {
        d = tiny;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        for aa in [
            m * (b - m) * x / ((qam + m2) * (a + m2)),
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
        ] {
            d = 1.0 + aa * d;
            if d.abs() < tiny {
                d = tiny;
            }
            c = 1.0 + aa / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, nine terms: relative error below 10⁻¹⁴).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let sum = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// The `z` with `P(Z > z) = p` for a standard normal `Z` (`0 < p < 0.5`), by bisection on
/// [`erfc`]: a few dozen evaluations, once per comparison.
pub fn normal_quantile_upper(p: f64) -> f64 {
    let tail = |z: f64| 0.5 * erfc(z / std::f64::consts::SQRT_2);
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;
    use rt_film::{AovSet, FilmBuffers};

    #[test]
    fn student_t_tails_match_tables() {
        // Two-sided 5 % and 0.1 % points of t with 15 degrees of freedom, and of t with 1
        // (Cauchy: P(T > 1) = 1/4 exactly).
        assert!((student_t_upper(2.131_449_5, 15.0) - 0.025).abs() < 1e-7);
        assert!((student_t_upper(4.072_765_2, 15.0) - 0.0005).abs() < 1e-8);
        assert!((student_t_upper(1.0, 1.0) - 0.25).abs() < 1e-12);
        // The normal limit, and the normal scale of a t₁₅ value.
        assert!((student_t_upper(3.090_232, 1e7) - 0.001).abs() < 1e-6);
        assert!((normal_equivalent(4.072_765_2, 15.0) - 3.290_527).abs() < 1e-4);
        assert!((normal_equivalent(-2.131_449_5, 15.0) + 1.959_964).abs() < 1e-4);
        assert_eq!(normal_equivalent(2.5, f64::INFINITY), 2.5);
    }

    /// One pixel, three channel tests (critical value 3.76, each at a one-sided 1.7·10⁻⁴):
    /// a t of 4.5 from a variance of 16 runs would be "detected" on the normal scale, though
    /// t₁₅ exceeds 4.5 with probability 2·10⁻⁴, as often as the level allows.
    #[test]
    fn variances_from_runs_are_judged_by_student_t() {
        let est = |mean: f32, var: f32, runs| Estimate {
            mean: vec![Rgb::splat(mean)],
            variance: vec![Rgb::splat(var)],
            runs,
        };
        let exact = est(1.0, 0.0, None);
        let c = compare_estimates(&est(1.45, 0.01, None), &exact, 1, 1, ALPHA);
        assert!(
            (c.max_block_z - 4.5).abs() < 1e-3 && !c.same_within_noise(),
            "{c:?}"
        );
        let c = compare_estimates(&est(1.45, 0.01, Some(16)), &exact, 1, 1, ALPHA);
        assert!(c.max_block_z < 3.7 && c.same_within_noise(), "{c:?}");
        // A real difference is still one.
        let c = compare_estimates(&est(2.0, 0.01, Some(16)), &exact, 1, 1, ALPHA);
        assert!(!c.same_within_noise(), "{c:?}");
    }

    #[test]
    fn quantiles_match_tables() {
        assert!((normal_quantile_upper(0.025) - 1.959_964).abs() < 1e-5);
        assert!((normal_quantile_upper(0.001) - 3.090_232).abs() < 1e-5);
        assert!((normal_quantile_upper(1e-6) - 4.753_424).abs() < 1e-4);
    }

    fn film(values: impl Fn(u32, u32, u32) -> f32) -> Film {
        let mut f = Film::new(
            8,
            8,
            FilmBuffers::for_outputs(AovSet::default()).with_variance(),
        );
        for y in 0..8 {
            for x in 0..8 {
                for i in 0..16 {
                    f.add_sample(x, y, i, Rgb::splat(values(x, y, i)), None);
                }
            }
        }
        f
    }

    #[test]
    fn identical_statistics_pass_and_a_shifted_block_fails() {
        let noise = |x: u32, y: u32, i: u32| ((x * 7 + y * 13 + i * 5) % 11) as f32 / 10.0;
        let a = film(noise);
        let b = film(|x, y, i| noise(x, y, (i + 3) % 16));
        let c = compare(&a, &b, 4, ALPHA);
        assert!(c.same_within_noise(), "{c:?}");
        assert_eq!(c.block_tests, 4 * 3);
        // One block darker by 30 %: caught.
        let dark = film(|x, y, i| noise(x, y, i) * if x < 4 && y < 4 { 0.7 } else { 1.0 });
        let c = compare(&a, &dark, 4, ALPHA);
        assert!(!c.same_within_noise(), "{c:?}");
        // Zero-variance pixels that differ at all are a difference, not noise.
        let c = compare(&film(|_, _, _| 1.0), &film(|_, _, _| 1.001), 4, ALPHA);
        assert!(!c.same_within_noise(), "{c:?}");
        let c = compare(&film(|_, _, _| 0.0), &film(|_, _, _| 0.0), 4, ALPHA);
        assert_eq!((c.max_block_z, c.image_z), (0.0, 0.0));
    }
}
