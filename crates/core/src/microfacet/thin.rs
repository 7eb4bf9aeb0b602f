//! Mitsuba's `thindielectric`: a thin dielectric sheet (a window pane, a soap film) whose two
//! parallel faces are one surface. Light reflects with the sheet's total reflectance, including
//! every internal bounce (`R' = 2R / (1 + R)` for a single face's Fresnel reflectance `R`), or
//! passes straight through, undeviated and without the 1/η² of a single boundary.

use super::{LocalBsdf, LocalSample};
use crate::material::fresnel_dielectric;
use crate::Rgb;
use glam::{Vec2, Vec3};

/// A thin dielectric sheet: both lobes are deltas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// Interior over exterior index of refraction.
    pub eta: f32,
    /// Factor on the reflected part (Mitsuba's `specular_reflectance`).
    pub reflectance: Rgb,
    /// Factor on the transmitted part (Mitsuba's `specular_transmittance`).
    pub transmittance: Rgb,
}

impl ThinDielectric {
    /// The sheet's reflectance at incident cosine `cos`: one face's, summed over the light
    /// bouncing between the faces (`R + T²R + T²R³ + … = 2R / (1 + R)`).
    pub fn reflectance_at(&self, cos: f32) -> f32 {
        let r = fresnel_dielectric(cos.abs(), self.eta);
        2.0 * r / (1.0 + r)
    }
}

impl LocalBsdf for ThinDielectric {
    fn eval_pdf(&self, _wo: Vec3, _wi: Vec3) -> (Rgb, f32) {
        (Rgb::ZERO, 0.0)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = self.reflectance_at(wo.z);
        Some(if u_lobe < r {
            LocalSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: self.reflectance,
                pdf: r,
                delta: true,
            }
        } else {
            LocalSample {
                wi: -wo,
                weight: self.transmittance,
                pdf: 1.0 - r,
                delta: true,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reflection and transmission sum to one at every angle, the reflectance is above one
    /// face's (internal bounces add to it) and the transmission goes straight through.
    #[test]
    fn a_thin_sheet_conserves_energy_and_does_not_bend_light() {
        let sheet = ThinDielectric {
            eta: 1.5,
            reflectance: Rgb::ONE,
            transmittance: Rgb::ONE,
        };
        for cos in [1.0f32, 0.7, 0.3, 0.05] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let r = sheet.reflectance_at(cos);
            assert!(r >= fresnel_dielectric(cos, 1.5) && r <= 1.0);
            let (mut flux, n) = (0.0f64, 1000);
            for i in 0..n {
                let u = (i as f32 + 0.5) / n as f32;
                let s = sheet.sample(wo, u, Vec2::ZERO).expect("a sample");
                assert!(s.wi == Vec3::new(-wo.x, 0.0, wo.z) || s.wi == -wo);
                flux += (s.weight.x / s.pdf * if s.wi == -wo { 1.0 - r } else { r }) as f64;
            }
            assert!(
                (flux / n as f64 - 1.0).abs() < 1e-5,
                "cos {cos}: {}",
                flux / n as f64
            );
        }
        // At normal incidence, glass of index 1.5: R = 0.04, so the sheet reflects 2·0.04/1.04.
        assert!((sheet.reflectance_at(1.0) - 0.08 / 1.04).abs() < 1e-6);
    }
}
