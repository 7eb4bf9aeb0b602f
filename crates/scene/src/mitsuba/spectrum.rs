//! Spectra reduced to RGB as Mitsuba 3's RGB variants reduce them (`spectrum_list_to_srgb` in
//! Mitsuba's `src/core/spectrum.cpp`): the piecewise-linear spectrum is weighted by the CIE
//! 1931 matching functions (and by the D65 illuminant for reflectances) at 1000 evenly
//! spaced wavelengths over 360–830 nm, summed, normalised by the integral of ȳ and taken
//! from XYZ to linear Rec. 709 RGB.
//! Reflectances are clamped to [0, 1], emission only below at 0, as Mitsuba does; each clamp
//! is a warning. The tables are Mitsuba's own (`cie.rs`, generated).

use super::cie::{LAMBDA_MAX, LAMBDA_MIN, STEP, TABLE, UNIFORM_EMITTER, Y_NORMALIZATION};

/// What a spectrum describes, which decides how Mitsuba reduces it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    /// A reflectance or transmittance: weighted by D65, clamped to [0, 1].
    Reflectance,
    /// Emitted radiance: unweighted, clamped at 0 only.
    Emission,
    /// An index of refraction or other unbounded quantity: as emission.
    Unbounded,
}

/// The RGB of the uniform spectrum `value` in `role`.
pub(super) fn uniform(value: f64, role: Role) -> [f64; 3] {
    match role {
        // Mitsuba turns a uniform emitter spectrum into the RGB of illuminant E.
        Role::Emission => UNIFORM_EMITTER.map(|c| c * value),
        Role::Reflectance | Role::Unbounded => [value; 3],
    }
}

/// The RGB of the piecewise-linear spectrum through `(wavelengths[i], values[i])`, and
/// whether it was clamped. `wavelengths` must be increasing with at least two entries.
pub(super) fn to_rgb(wavelengths: &[f64], values: &[f64], role: Role) -> ([f64; 3], bool) {
    const STEPS: usize = 1000;
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    let d65 = role == Role::Reflectance;
    let mut xyz = [0.0f64; 3];
    for i in 0..STEPS {
        let w = LAMBDA_MIN + (i as f64 / (STEPS - 1) as f64) * (LAMBDA_MAX - LAMBDA_MIN);
        if w < first || w > last {
            continue;
        }
        // The last knot at or below `w`, never the final one (Mitsuba's find_interval).
        let k = wavelengths[1..wavelengths.len() - 1].partition_point(|&x| x <= w);
        let (w0, w1, v0, v1) = (wavelengths[k], wavelengths[k + 1], values[k], values[k + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let [x, y, z, illuminant] = cie_at(w);
        let s = v * if d65 { illuminant } else { 1.0 };
        xyz[0] += x * s;
        xyz[1] += y * s;
        xyz[2] += z * s;
    }
    let scale = (LAMBDA_MAX - LAMBDA_MIN) / STEPS as f64 * Y_NORMALIZATION;
    let rgb = xyz_to_srgb(xyz.map(|c| c * scale));
    let upper = if role == Role::Reflectance {
        1.0
    } else {
        f64::INFINITY
    };
    let clamped = rgb.map(|c| c.clamp(0.0, upper));
    (clamped, clamped != rgb)
}

/// The tables at `w` nm, linear between knots.
fn cie_at(w: f64) -> [f64; 4] {
    let t = ((w - LAMBDA_MIN) / STEP).clamp(0.0, (TABLE.len() - 1) as f64);
    let i = (t as usize).min(TABLE.len() - 2);
    let f = t - i as f64;
    let (a, b) = (TABLE[i], TABLE[i + 1]);
    [0, 1, 2, 3].map(|c| a[c] * (1.0 - f) + b[c] * f)
}

/// CIE XYZ to linear Rec. 709 (sRGB primaries, D65 white).
fn xyz_to_srgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.240479 * x - 1.537150 * y - 0.498535 * z,
        -0.969256 * x + 1.875991 * y + 0.041556 * z,
        0.055648 * x - 0.204043 * y + 1.057311 * z,
    ]
}

/// sRGB-encoded (gamma) component in [0, 1] to linear.
pub(super) fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::super::cie::CASES;
    use super::*;

    #[test]
    fn matches_mitsubas_reduction() {
        for (w, v, bounded, d65, want) in CASES {
            let role = match (bounded, d65) {
                (true, true) => Role::Reflectance,
                (false, false) => Role::Emission,
                _ => unreachable!("no such case in the table"),
            };
            let (got, _) = to_rgb(w, v, role);
            for c in 0..3 {
                let rel = (got[c] - want[c]).abs() / want[c].abs().max(1e-3);
                // Mitsuba sums in single precision, we in double: 1e-5 relative covers it.
                assert!(rel < 1e-5, "{w:?} {v:?}: {got:?} vs Mitsuba's {want:?}");
            }
        }
    }

    #[test]
    fn a_flat_reflectance_is_grey_and_emission_is_not_weighted() {
        let (rgb, clamped) = to_rgb(&[360.0, 830.0], &[0.5, 0.5], Role::Reflectance);
        assert!(!clamped);
        for c in rgb {
            assert!((c - 0.5).abs() < 2e-3, "{rgb:?}");
        }
        // A flat emission spectrum is illuminant E: the same as Mitsuba's uniform emitter.
        let (e, _) = to_rgb(&[360.0, 830.0], &[2.0, 2.0], Role::Emission);
        let u = uniform(2.0, Role::Emission);
        for c in 0..3 {
            assert!((e[c] - u[c]).abs() < 1e-3 * u[c], "{e:?} vs {u:?}");
        }
    }

    #[test]
    fn reflectances_are_clamped_and_say_so() {
        let (rgb, clamped) = to_rgb(&[400.0, 700.0], &[3.0, 3.0], Role::Reflectance);
        assert!(clamped);
        assert_eq!(rgb, [1.0; 3]);
    }

    #[test]
    fn srgb_decoding_is_the_standard_curve() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-12);
        assert!((srgb_to_linear(0.5) - 0.214041).abs() < 1e-6);
    }
}
