//! The pieces of one À-Trous tap that do not depend on the image: the B3-spline generating
//! kernel, the tap offsets of each level, and the fast `exp(−x)` of the edge-stopping weight.

/// The 1-D B3-spline interpolation kernel (1/16, 1/4, 3/8, 1/4, 1/16) of Murtagh's À-Trous
/// transform (thesis §6.5.1); every entry is a short binary fraction, so the 5×5 products are
/// exact in `f32` and sum to exactly one.
pub(crate) const B3: [f32; 5] = [1.0 / 16.0, 0.25, 0.375, 0.25, 1.0 / 16.0];

/// The 25 weights of the 5×5 outer product, row-major (`h[5·j + i] = B3[j]·B3[i]`).
pub(crate) fn kernel_2d() -> [f32; 25] {
    let mut h = [0.0; 25];
    for (j, &a) in B3.iter().enumerate() {
        for (i, &b) in B3.iter().enumerate() {
            h[5 * j + i] = a * b;
        }
    }
    h
}

/// Tap spacing of level `level` (0-based): `2^level` pixels, so the five taps per axis of level
/// `i` sit at `2^i·{−2, −1, 0, 1, 2}` (errata §6.3: spacing 2^i, not 2^(i−1) zeros).
pub(crate) fn step_width(level: usize) -> usize {
    1 << level
}

/// Offsets of the five taps per axis at `level`.
pub(crate) fn tap_offsets(level: usize) -> [isize; 5] {
    let s = step_width(level) as isize;
    [-2 * s, -s, 0, s, 2 * s]
}

/// Largest exponent kept: `exp(−87)` ≈ 1.6·10⁻³⁸ is the smallest normal `f32` power of two
/// reached, and a weight that small is zero for every purpose here.
const MAX_EXPONENT: f32 = 87.0;

/// `exp(−x)` for `x ≥ 0` (larger `x` are clamped to 87, NaN gives the value at 87), written
/// with plain `f32` adds, multiplies and integer bit operations only (no conversions), so that the compiler vectorises
/// it and every vector width and the scalar code give the same bits.
///
/// Cody–Waite range reduction `−x = n·ln 2 + r` with `|r| ≤ ln 2 / 2`, then the degree-6 Taylor
/// polynomial of `e^r` (truncation error `|r|⁷/7! ≤ 1.2·10⁻⁷`) scaled by `2^n` through the
/// exponent bits. Relative error below 4·10⁻⁷ over `[0, 87]` (tested against `f64::exp`);
/// `exp_neg(0)` is exactly 1, so a tap identical to the centre has full weight.
#[inline(always)]
pub(crate) fn exp_neg(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    // ln 2 split so that n·LN2_HI is exact for |n| < 2^9.
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    // Adding and subtracting 1.5·2^23 rounds to the nearest integer without a rounding
    // instruction SSE2 lacks.
    const ROUND: f32 = 12_582_912.0;
    // `if` rather than `f32::min`: it maps onto one vector min instruction (NaN gives 87).
    let x = -(if x < MAX_EXPONENT { x } else { MAX_EXPONENT });
    // The sum's low mantissa bits hold n itself, which gives 2^n by integer operations only.
    let big = x * LOG2E + ROUND;
    let n = big - ROUND;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    let scale = f32::from_bits(
        big.to_bits()
            .wrapping_sub(ROUND.to_bits())
            .wrapping_add(127)
            << 23,
    );
    p * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn b3_kernel_sums_to_one_with_centre_nine_sixty_fourths() {
        let h = kernel_2d();
        assert_eq!(h.iter().sum::<f32>(), 1.0);
        assert_eq!(h[12], 9.0 / 64.0);
        assert_eq!(h[0], 1.0 / 256.0);
        assert_eq!(h[2], 3.0 / 128.0);
        // Symmetric under both mirrors and the transpose.
        for j in 0..5 {
            for i in 0..5 {
                assert_eq!(h[5 * j + i], h[5 * i + j]);
                assert_eq!(h[5 * j + i], h[5 * (4 - j) + (4 - i)]);
            }
        }
    }

    #[test]
    fn taps_are_two_to_the_level_apart() {
        assert_eq!(tap_offsets(0), [-2, -1, 0, 1, 2]);
        assert_eq!(tap_offsets(1), [-4, -2, 0, 2, 4]);
        for level in 0..10 {
            let o = tap_offsets(level);
            let s = 1isize << level;
            assert_eq!(o, [-2 * s, -s, 0, s, 2 * s], "level {level}");
        }
    }

    #[test]
    fn fast_exp_is_accurate_and_exact_at_zero() {
        assert_eq!(exp_neg(0.0), 1.0);
        let mut worst = 0.0f64;
        let mut x = 0.0f32;
        while x < 87.0 {
            let got = exp_neg(x) as f64;
            let want = (-(x as f64)).exp();
            worst = worst.max(((got - want) / want).abs());
            x += 0.000_37 + x * 1e-4;
        }
        assert!(worst < 4e-7, "worst relative error {worst}");
        // Beyond the clamp, and NaN, the weight is the tiny value at 87, never NaN or negative.
        for x in [87.0, 1e3, f32::INFINITY, f32::NAN] {
            let e = exp_neg(x);
            assert!(e > 0.0 && e < 1e-37, "{x}: {e}");
        }
    }
}
