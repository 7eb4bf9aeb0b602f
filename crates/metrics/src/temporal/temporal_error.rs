//! Temporal error: how much consecutive frames of one sequence differ in luminance.

use super::error::Result;
use super::frames::{check_frame, check_sequence};
use super::TemporalError;
use super::TemporalSeries;
use crate::error::Role;
use crate::image::RgbImage;
use crate::reduce::ordered_sum;
use rt_core::Rgb;

/// Rec. 709 luminance `0.2126 R + 0.7152 G + 0.0722 B` of linear values, in `f64`, unclamped.
#[inline]
pub(crate) fn luminance(p: Rgb) -> f64 {
    0.2126 * f64::from(p.x) + 0.7152 * f64::from(p.y) + 0.0722 * f64::from(p.z)
}

/// Mean over pixels of `|Y(current) − Y(previous)|` for two frames already checked to be
/// valid and of one size.
pub(crate) fn mean_luminance_change(previous: &RgbImage, current: &RgbImage) -> f64 {
    let [sum] = ordered_sum(current.height(), |y| {
        let mut s = 0.0;
        for (&a, &b) in previous.row(y).iter().zip(current.row(y)) {
            s += (luminance(b) - luminance(a)).abs();
        }
        [s]
    });
    sum / current.pixels().len() as f64
}

/// Temporal error of a sequence: for each pair of consecutive frames, the mean over pixels of
/// the absolute difference of their luminances, and the mean of those over the pairs.
///
/// This is the temporal-stability measure of Schied et al., "Spatiotemporal Variance-Guided
/// Filtering" (HPG 2017), as Voorhuis ("Beyond SVGF", MSc thesis, Utrecht 2018) uses it over 60 frames of a
/// fixed camera and a static scene, where an ideal denoiser would output the same image every
/// frame and any change is flicker. Luminance is Rec. 709, `0.2126 R + 0.7152 G + 0.0722 B`, of
/// the *linear* values, neither clamped nor tone-mapped (the sources do not say which they
/// use; tone-map the frames first to measure on display values). With a moving camera or
/// changing light the true image changes too; use [`temporal_relmse`](super::temporal_relmse)
/// there.
///
/// `per_pair[i]` is the value of frames `i` and `i + 1`; every pair has the same pixel count,
/// so `mean` is also the mean over all pixels of all pairs. Needs at least two frames of one
/// size, non-empty and finite.
pub fn temporal_error(frames: &[RgbImage]) -> Result<TemporalSeries> {
    check_sequence(Role::Test, frames, 2, "the temporal error")?;
    Ok(TemporalSeries::from_pairs(
        frames
            .windows(2)
            .map(|w| mean_luminance_change(&w[0], &w[1]))
            .collect(),
    ))
}

/// One step of the temporal error restricted to a region: the mean over the pixels where
/// `mask` is true (row-major, one entry per pixel) of `|Y(current) − Y(previous)|`; `None`
/// when the mask selects no pixel. Voorhuis judges reflection reprojection by the flicker of
/// the reflections, which a whole-image mean dilutes with the diffuse pixels that every
/// variant treats alike; the mask is then the specular pixels.
pub fn luminance_change_in(
    previous: &RgbImage,
    current: &RgbImage,
    mask: &[bool],
) -> Result<Option<f64>> {
    check_frame(Role::Test, 0, previous, None)?;
    check_frame(Role::Test, 1, current, Some(previous))?;
    if mask.len() != current.pixels().len() {
        return Err(TemporalError::MaskSize {
            mask: mask.len(),
            pixels: current.pixels().len(),
        });
    }
    let w = current.width();
    let [sum, count] = ordered_sum(current.height(), |y| {
        let (mut s, mut n) = (0.0, 0.0);
        let row = &mask[y * w..(y + 1) * w];
        for ((&a, &b), &m) in previous.row(y).iter().zip(current.row(y)).zip(row) {
            if m {
                s += (luminance(b) - luminance(a)).abs();
                n += 1.0;
            }
        }
        [s, n]
    });
    Ok((count > 0.0).then(|| sum / count))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(c: [f32; 3]) -> RgbImage {
        RgbImage::from_fn(9, 7, |_, _| Rgb::from_array(c))
    }

    #[test]
    fn a_constant_sequence_has_no_temporal_error() {
        let frames = vec![constant([0.3, 0.6, 0.9]); 5];
        let t = temporal_error(&frames).unwrap();
        assert_eq!(t.mean, 0.0);
        assert_eq!(t.per_pair, vec![0.0; 4]);
    }

    #[test]
    fn alternating_frames_give_their_luminance_difference() {
        // Y(a) = 0.2126·1 = 0.2126 and Y(b) = 0.7152·0.5 + 0.0722·1 = 0.4298: every pixel
        // changes by |0.2126 − 0.4298| = 0.2172 at every step, up or down.
        let (a, b) = (constant([1.0, 0.0, 0.0]), constant([0.0, 0.5, 1.0]));
        let frames = vec![a.clone(), b.clone(), a, b];
        let t = temporal_error(&frames).unwrap();
        assert_eq!(t.per_pair.len(), 3);
        for v in &t.per_pair {
            assert!((v - 0.2172).abs() < 1e-7, "{v}");
        }
        assert!((t.mean - 0.2172).abs() < 1e-7);
    }

    #[test]
    fn per_pair_values_follow_the_frames() {
        // One pixel of four changes by 0.4 in luminance (a grey step: Y = value) between frames
        // 1 and 2 only: per pair 0, 0.1, 0; the mean is 0.1 / 3.
        let flat = RgbImage::from_fn(2, 2, |_, _| Rgb::splat(0.2));
        let step = RgbImage::from_fn(2, 2, |x, y| {
            Rgb::splat(if (x, y) == (1, 0) { 0.6 } else { 0.2 })
        });
        let t = temporal_error(&[flat.clone(), flat, step.clone(), step]).unwrap();
        let expected = [0.0, 0.1, 0.0];
        for (v, e) in t.per_pair.iter().zip(expected) {
            assert!((v - e).abs() < 1e-7, "{:?}", t.per_pair);
        }
        assert!((t.mean - 0.1 / 3.0).abs() < 1e-7);
    }

    #[test]
    fn a_masked_step_counts_only_the_masked_pixels() {
        // Pixel (1, 0) changes by 0.4; masked with (0, 0) only the mean is 0.2, masked alone
        // 0.4, masked out 0; an empty mask has no value; a short mask is refused.
        let flat = RgbImage::from_fn(2, 2, |_, _| Rgb::splat(0.2));
        let step = RgbImage::from_fn(2, 2, |x, y| {
            Rgb::splat(if (x, y) == (1, 0) { 0.6 } else { 0.2 })
        });
        let at = |m: [bool; 4]| luminance_change_in(&flat, &step, &m).unwrap();
        assert!((at([true, true, false, false]).unwrap() - 0.2).abs() < 1e-7);
        assert!((at([false, true, false, false]).unwrap() - 0.4).abs() < 1e-7);
        assert_eq!(at([true, false, true, true]), Some(0.0));
        assert_eq!(at([false; 4]), None);
        let e = luminance_change_in(&flat, &step, &[true; 3]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the mask has 3 entries but the frames have 4 pixels"
        );
    }

    #[test]
    fn one_frame_is_too_few() {
        let e = temporal_error(&[constant([1.0; 3])]).unwrap_err();
        assert!(matches!(
            e,
            TemporalError::TooFewFrames {
                needed: 2,
                got: 1,
                ..
            }
        ));
        assert_eq!(
            e.to_string(),
            "the temporal error needs at least 2 frames, got 1"
        );
        assert!(matches!(
            temporal_error(&[]),
            Err(TemporalError::EmptySequence { .. })
        ));
    }
}
