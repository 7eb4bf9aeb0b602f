//! Colour: linear RGB as `glam::Vec3`, luminance, and sRGB transfer functions.

use glam::Vec3;

/// Linear RGB radiance or reflectance (Rec. 709 primaries).
pub type Rgb = Vec3;

/// Luminance (Y) of linear Rec. 709 RGB.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// sRGB opto-electronic transfer function, for a linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`linear_to_srgb`].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips() {
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-5);
        }
        assert!((luminance(Vec3::ONE) - 1.0).abs() < 1e-6);
    }
}
