//! Temporal relMSE: how far a sequence's frame-to-frame changes are from the reference's.

use super::error::{positive, Result};
use super::frames::check_pair_of_sequences;
use super::TemporalSeries;
use crate::image::RgbImage;
use crate::reduce::ordered_sum;

/// The test frames `t0 → t1` and the reference frames `r0 → r1` of one step.
pub(crate) struct Step<'a> {
    pub(crate) test: [&'a RgbImage; 2],
    pub(crate) reference: [&'a RgbImage; 2],
}

/// relMSE of the test difference `t1 − t0` against the reference difference `r1 − r0`, over
/// pixels and channels, for four frames already checked to be valid and of one size.
pub(crate) fn difference_relmse(step: &Step, epsilon: f64) -> f64 {
    let ([t0, t1], [r0, r1]) = (step.test, step.reference);
    let [sum] = ordered_sum(t1.height(), |y| {
        let mut s = 0.0;
        let rows = t0
            .row(y)
            .iter()
            .zip(t1.row(y))
            .zip(r0.row(y).iter().zip(r1.row(y)));
        for ((a0, a1), (b0, b1)) in rows {
            for c in 0..3 {
                // f32 − f32 is exact in f64, so equal differences give exactly 0.
                let dx = f64::from(a1[c]) - f64::from(a0[c]);
                let dy = f64::from(b1[c]) - f64::from(b0[c]);
                s += (dx - dy) * (dx - dy) / (dy * dy + epsilon);
            }
        }
        [s]
    });
    sum / (3 * t1.pixels().len()) as f64
}

/// Temporal relMSE of a test sequence against its reference sequence: for each step `t`
/// (frames `t − 1` → `t`), the relMSE of the test's frame difference `x = f_t − f_{t−1}`
/// against the reference's `y = r_t − r_{t−1}`,
///
/// ```text
/// mean over pixels and the 3 channels of (x − y)² / (y² + epsilon)
/// ```
///
/// and the mean of those over the steps. `per_pair[i]` is the step from frame `i` to `i + 1`.
///
/// Where temporal error ([`temporal_error`](super::temporal_error)) assumes the true image
/// does not change, this measures the change that should not be there under a moving camera
/// or changing light: a denoiser that lags or flickers changes differently from the
/// reference. It is ours (not from a paper); the form is relMSE's ([`relmse`](crate::relmse)),
/// with the reference *difference* in the denominator. Consequences of that choice:
/// - where the reference does not change (`y = 0`), a term is `x² / epsilon`: flicker counted
///   in units of epsilon, not relative to the pixel's brightness, so values are comparable only
///   at equal epsilon (report it, as for relMSE);
/// - where the reference changes a lot, the same absolute mismatch weighs less, as relMSE
///   weighs errors on bright pixels less;
/// - the reference must have converged far below the test's flicker: its own noise enters `y`.
///
/// `epsilon` (usually [`DEFAULT_EPSILON`](crate::DEFAULT_EPSILON) = 0.01) must be positive.
/// Needs two sequences of the same length, at least two frames, all of one size, non-empty and
/// finite.
pub fn temporal_relmse(
    test: &[RgbImage],
    reference: &[RgbImage],
    epsilon: f64,
) -> Result<TemporalSeries> {
    let epsilon = positive("epsilon", epsilon)?;
    check_pair_of_sequences(test, reference, 2, "the temporal relMSE")?;
    let per_pair = (1..test.len())
        .map(|t| {
            let step = Step {
                test: [&test[t - 1], &test[t]],
                reference: [&reference[t - 1], &reference[t]],
            };
            difference_relmse(&step, epsilon)
        })
        .collect();
    Ok(TemporalSeries::from_pairs(per_pair))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::temporal::TemporalError;
    use rt_core::Rgb;

    /// Dyadic values, so that adding a dyadic bias is exact in f32.
    fn ramp(offset: f32) -> RgbImage {
        RgbImage::from_fn(6, 5, move |x, y| {
            Rgb::new(x as f32 * 0.125 + offset, y as f32 * 0.25, offset * 2.0)
        })
    }

    #[test]
    fn identical_differences_give_zero() {
        // The test is the reference plus a constant bias (exact in f32): its differences are
        // the reference's, though no frame equals its reference frame.
        let reference: Vec<RgbImage> = [0.0, 0.25, 0.75].map(ramp).to_vec();
        let biased: Vec<RgbImage> = reference
            .iter()
            .map(|f| RgbImage::from_fn(6, 5, |x, y| f.pixels()[y * 6 + x] + Rgb::splat(0.5)))
            .collect();
        let t = temporal_relmse(&biased, &reference, 0.01).unwrap();
        assert_eq!(t.per_pair, vec![0.0, 0.0]);
        assert_eq!(t.mean, 0.0);
    }

    #[test]
    fn hand_computed_one_pixel_steps() {
        let px = |c: [f32; 3]| RgbImage::from_fn(1, 1, move |_, _| Rgb::from_array(c));
        // Step 1: x = (0.5, 0, 0), y = (0.25, 0, 1):
        //   (0.25² / (0.0625 + 0.01) + 0 + 1 / (1 + 0.01)) / 3.
        // Step 2: x = (0, 0, 0), y = (0, 0, 0): 0. A static reference with a flickering test:
        // step 3: x = (0.1, 0.1, 0.1), y = 0: 3 · 0.01 / 0.01 / 3 = 1.
        let test = [
            px([0.0; 3]),
            px([0.5, 0.0, 0.0]),
            px([0.5, 0.0, 0.0]),
            px([0.6, 0.1, 0.1]),
        ];
        let reference = [
            px([0.0; 3]),
            px([0.25, 0.0, 1.0]),
            px([0.25, 0.0, 1.0]),
            px([0.25, 0.0, 1.0]),
        ];
        let t = temporal_relmse(&test, &reference, 0.01).unwrap();
        let step1 = (0.0625 / 0.0725 + 1.0 / 1.01) / 3.0;
        let expected = [step1, 0.0, 1.0];
        for (v, e) in t.per_pair.iter().zip(expected) {
            assert!((v - e).abs() < 1e-6, "{:?}", t.per_pair);
        }
        assert!((t.mean - (step1 + 1.0) / 3.0).abs() < 1e-6);
        // Epsilon is a parameter: step 3 with epsilon 0.02 is 0.01 / 0.02 = 0.5.
        let t = temporal_relmse(&test, &reference, 0.02).unwrap();
        assert!((t.per_pair[2] - 0.5).abs() < 1e-6, "{:?}", t.per_pair);
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let two = [ramp(0.0), ramp(0.1)];
        assert!(matches!(
            temporal_relmse(&two, &two, 0.0),
            Err(TemporalError::InvalidOption {
                name: "epsilon",
                ..
            })
        ));
        assert!(matches!(
            temporal_relmse(&two[..1], &two[..1], 0.01),
            Err(TemporalError::TooFewFrames {
                needed: 2,
                got: 1,
                ..
            })
        ));
        assert!(matches!(
            temporal_relmse(&two, &two[..1], 0.01),
            Err(TemporalError::LengthMismatch {
                test: 2,
                reference: 1
            })
        ));
        let small = [
            RgbImage::from_fn(2, 2, |_, _| Rgb::ONE),
            RgbImage::from_fn(2, 2, |_, _| Rgb::ONE),
        ];
        assert!(matches!(
            temporal_relmse(&two, &small, 0.01),
            Err(TemporalError::Frame { frame: 0, .. })
        ));
    }
}
