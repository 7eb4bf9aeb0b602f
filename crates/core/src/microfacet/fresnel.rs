//! Fresnel reflectance of conductors (complex index `η + iκ`), per colour channel.

use crate::Rgb;

/// Unpolarised Fresnel reflectance of a conductor with relative complex index `eta + i·k`
/// (per channel) at incident cosine `cos_i` (clamped to [0, 1]). The exact expression for
/// complex indices (Pharr, Jakob and Humphreys, *PBR*, 3rd ed., §8.2.1), as Mitsuba's
/// `fresnel_conductor`.
pub fn fresnel_conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c = cos_i.clamp(0.0, 1.0);
    Rgb::new(
        conductor_channel(c, eta.x, k.x),
        conductor_channel(c, eta.y, k.y),
        conductor_channel(c, eta.z, k.z),
    )
}

fn conductor_channel(cos: f32, eta: f32, k: f32) -> f32 {
    let cos2 = cos * cos;
    let sin2 = 1.0 - cos2;
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2_plus_b2 = (t0 * t0 + 4.0 * eta2 * k2).max(0.0).sqrt();
    let t1 = a2_plus_b2 + cos2;
    let a = (0.5 * (a2_plus_b2 + t0)).max(0.0).sqrt();
    let t2 = 2.0 * cos * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    let r = 0.5 * (rp + rs);
    if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::fresnel_dielectric;

    #[test]
    fn a_conductor_without_absorption_is_a_dielectric() {
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
            let c = fresnel_conductor(cos, Rgb::splat(1.5), Rgb::ZERO).x;
            let d = fresnel_dielectric(cos, 1.5);
            assert!((c - d).abs() < 1e-5, "cos {cos}: {c} against {d}");
        }
    }

    #[test]
    fn normal_incidence_has_the_closed_form() {
        // ((η−1)² + κ²) / ((η+1)² + κ²) at normal incidence.
        let (eta, k) = (0.2f32, 3.9f32);
        let want = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        let got = fresnel_conductor(1.0, Rgb::splat(eta), Rgb::splat(k)).x;
        assert!((got - want).abs() < 1e-5, "{got} against {want}");
        // Grazing incidence reflects everything.
        assert!(fresnel_conductor(0.0, Rgb::splat(eta), Rgb::splat(k)).x > 0.999);
    }
}
