//! The checks on sequences that every temporal metric makes before it reads pixels.

use super::error::{Result, TemporalError};
use crate::error::{MetricsError, Role};
use crate::image::{check_finite, validate_pair, RgbImage};

fn size(img: &RgbImage) -> (usize, usize) {
    (img.width(), img.height())
}

/// Checks frame `index` of one sequence on its own: not empty, every value finite, and the
/// size of the frame before it (when there is one).
pub(crate) fn check_frame(
    role: Role,
    index: usize,
    frame: &RgbImage,
    previous: Option<&RgbImage>,
) -> Result<()> {
    let bad = |cause| TemporalError::Frame {
        frame: index,
        cause,
    };
    if frame.pixels().is_empty() {
        return Err(bad(MetricsError::Empty {
            role,
            width: frame.width(),
            height: frame.height(),
        }));
    }
    if let Some(p) = previous {
        check_same_size(role, index, frame, p)?;
    }
    check_finite(frame, role).map_err(bad)
}

/// Checks that frame `index` has the size of the frame before it.
pub(crate) fn check_same_size(
    role: Role,
    index: usize,
    frame: &RgbImage,
    previous: &RgbImage,
) -> Result<()> {
    if size(previous) == size(frame) {
        Ok(())
    } else {
        Err(TemporalError::FrameSize {
            role,
            frame: index,
            size: size(frame),
            previous: size(previous),
        })
    }
}

/// Checks a whole sequence: at least `needed` frames (for `what`), each valid and of one size.
pub(crate) fn check_sequence(
    role: Role,
    frames: &[RgbImage],
    needed: usize,
    what: &'static str,
) -> Result<()> {
    if frames.is_empty() {
        return Err(TemporalError::EmptySequence { role });
    }
    if frames.len() < needed {
        return Err(TemporalError::TooFewFrames {
            what,
            needed,
            got: frames.len(),
        });
    }
    for (i, f) in frames.iter().enumerate() {
        check_frame(role, i, f, i.checked_sub(1).map(|p| &frames[p]))?;
    }
    Ok(())
}

/// Checks a test sequence and its reference: each on its own (test first), then that they have
/// as many frames and that each test frame has its reference frame's size.
pub(crate) fn check_pair_of_sequences(
    test: &[RgbImage],
    reference: &[RgbImage],
    needed: usize,
    what: &'static str,
) -> Result<()> {
    for (frames, role) in [(test, Role::Test), (reference, Role::Reference)] {
        if frames.is_empty() {
            return Err(TemporalError::EmptySequence { role });
        }
    }
    if test.len() != reference.len() {
        return Err(TemporalError::LengthMismatch {
            test: test.len(),
            reference: reference.len(),
        });
    }
    check_sequence(Role::Test, test, needed, what)?;
    check_sequence(Role::Reference, reference, needed, what)?;
    for (i, (t, r)) in test.iter().zip(reference).enumerate() {
        validate_pair(t, r).map_err(|cause| TemporalError::Frame { frame: i, cause })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    fn grey(w: usize, h: usize) -> RgbImage {
        RgbImage::from_fn(w, h, |_, _| Rgb::splat(0.5))
    }

    #[test]
    fn sequences_are_checked() {
        let what = "the test";
        assert_eq!(
            check_sequence(Role::Test, &[], 2, what),
            Err(TemporalError::EmptySequence { role: Role::Test })
        );
        let e = check_sequence(Role::Reference, &[grey(2, 2)], 2, what).unwrap_err();
        assert_eq!(e.to_string(), "the test needs at least 2 frames, got 1");
        let e =
            check_sequence(Role::Test, &[grey(2, 2), grey(2, 2), grey(3, 2)], 2, what).unwrap_err();
        assert_eq!(
            e.to_string(),
            "frame 2 of the test sequence is 3x2 but frame 1 is 2x2"
        );
        let empty = RgbImage::new(0, 0, vec![]).unwrap();
        let e = check_sequence(Role::Reference, &[empty.clone(), empty], 2, what).unwrap_err();
        assert_eq!(e.to_string(), "frame 0: the reference image is empty (0x0)");
        let mut px = grey(2, 2).into_pixels();
        px[3].y = f32::NAN;
        let nan = RgbImage::new(2, 2, px).unwrap();
        let e = check_sequence(Role::Test, &[grey(2, 2), nan], 2, what).unwrap_err();
        assert_eq!(
            e.to_string(),
            "frame 1: the test image has a non-finite value (NaN) at pixel (1, 1), channel G"
        );
    }

    #[test]
    fn pairs_of_sequences_are_checked() {
        let what = "x";
        let two = [grey(2, 2), grey(2, 2)];
        assert!(check_pair_of_sequences(&two, &two, 2, what).is_ok());
        assert_eq!(
            check_pair_of_sequences(&two, &[], 2, what),
            Err(TemporalError::EmptySequence {
                role: Role::Reference
            })
        );
        let e = check_pair_of_sequences(&two, &two[..1], 2, what).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the test sequence has 2 frames but the reference sequence has 1"
        );
        let other = [grey(3, 3), grey(3, 3)];
        let e = check_pair_of_sequences(&two, &other, 2, what).unwrap_err();
        assert_eq!(
            e.to_string(),
            "frame 0: the test image is 2x2 but the reference image is 3x3"
        );
    }
}
