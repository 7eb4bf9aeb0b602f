//! The checks every metric makes before it reads pixels. The image type itself is
//! [`rt_core::RgbImage`].

use crate::error::{MetricsError, Result, Role};
pub use rt_core::RgbImage;

/// The first non-finite channel value in row-major order, as an error about `role`.
pub(crate) fn check_finite(img: &RgbImage, role: Role) -> Result<()> {
    // A fast scan first: images are almost always clean, and only a failure needs the
    // position.
    if img.pixels().iter().all(|p| p.is_finite()) {
        return Ok(());
    }
    for (i, p) in img.pixels().iter().enumerate() {
        for (c, channel) in ['R', 'G', 'B'].into_iter().enumerate() {
            if !p[c].is_finite() {
                return Err(MetricsError::NonFinite {
                    role,
                    x: i % img.width(),
                    y: i / img.width(),
                    channel,
                    value: p[c],
                });
            }
        }
    }
    Ok(())
}

/// Checks that two images can be compared: neither is empty, they have the same size, and every
/// value is finite (test image first). Every metric in this crate calls it; callers that want to
/// report problems before doing other work can call it themselves.
pub fn validate_pair(test: &RgbImage, reference: &RgbImage) -> Result<()> {
    for (img, role) in [(test, Role::Test), (reference, Role::Reference)] {
        if img.pixels().is_empty() {
            return Err(MetricsError::Empty {
                role,
                width: img.width(),
                height: img.height(),
            });
        }
    }
    let size = |i: &RgbImage| (i.width(), i.height());
    if size(test) != size(reference) {
        return Err(MetricsError::SizeMismatch {
            test: size(test),
            reference: size(reference),
        });
    }
    check_finite(test, Role::Test)?;
    check_finite(reference, Role::Reference)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::Rgb;

    #[test]
    fn pairs_are_validated_in_a_fixed_order() {
        let a = RgbImage::from_fn(3, 2, |_, _| Rgb::ONE);
        let empty = RgbImage::new(0, 5, vec![]).unwrap();
        assert!(validate_pair(&a, &a).is_ok());
        assert_eq!(
            validate_pair(&empty, &a),
            Err(MetricsError::Empty {
                role: Role::Test,
                width: 0,
                height: 5
            })
        );
        assert!(matches!(
            validate_pair(&a, &empty),
            Err(MetricsError::Empty {
                role: Role::Reference,
                ..
            })
        ));
        let b = RgbImage::from_fn(2, 3, |_, _| Rgb::ONE);
        let e = validate_pair(&a, &b).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the test image is 3x2 but the reference image is 2x3"
        );
        let mut nan = a.clone().into_pixels();
        nan[4].z = f32::INFINITY;
        nan[5].x = f32::NAN;
        let nan = RgbImage::new(3, 2, nan).unwrap();
        let e = validate_pair(&a, &nan).unwrap_err();
        assert_eq!(
            e,
            MetricsError::NonFinite {
                role: Role::Reference,
                x: 1,
                y: 1,
                channel: 'B',
                value: f32::INFINITY
            }
        );
        assert_eq!(
            e.to_string(),
            "the reference image has a non-finite value (inf) at pixel (1, 1), channel B"
        );
        // The test image is checked first.
        assert!(matches!(
            validate_pair(&nan, &nan),
            Err(MetricsError::NonFinite {
                role: Role::Test,
                ..
            })
        ));
    }
}
