//! Mitsuba's `dielectric` and `roughdielectric`: reflection and refraction at the boundary of
//! two dielectrics, smooth (delta lobes) or through a microfacet distribution (Walter et al.
//! 2007), with Mitsuba's radiance scaling of refracted light (the BTDF is not symmetric:
//! `f(wo, wi) / ηo² = f(wi, wo) / ηi²`, with `η` the index on each direction's side).

use super::{reflect, Distribution, LocalBsdf, LocalSample};
use crate::material::{fresnel_dielectric, refract};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// A dielectric boundary: interior index over exterior index `eta` (above the surface, `+z`,
/// is the exterior); smooth when `distribution` is `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// The rough surface's normals; `None` for a smooth boundary.
    pub distribution: Option<Distribution>,
    /// Interior over exterior index of refraction.
    pub eta: f32,
    /// Factors on the reflected and the transmitted part (Mitsuba's `specular_reflectance`
    /// and `specular_transmittance`; 1 for a physical boundary).
    pub reflectance: Rgb,
    /// See `reflectance`.
    pub transmittance: Rgb,
}

impl RoughDielectric {
    /// `η_transmitted / η_incident` for light arriving from the side of `w`.
    #[inline]
    pub(crate) fn eta_from(&self, w: Vec3) -> f32 {
        if w.z > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    /// Fresnel reflectance for `wo` at the (upper) microfacet normal `m`.
    #[inline]
    fn fresnel(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        if c >= 0.0 {
            fresnel_dielectric(c, self.eta)
        } else {
            fresnel_dielectric(-c, 1.0 / self.eta)
        }
    }
}

impl LocalBsdf for RoughDielectric {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(d) = self.distribution else {
            return (Rgb::ZERO, 0.0);
        };
        if wo.z == 0.0 || wi.z == 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let reflected = wo.z * wi.z > 0.0;
        let eta = self.eta_from(wo);
        // The half vector of reflection, or the generalised one of refraction, turned up.
        let m = if reflected { wo + wi } else { wo + wi * eta }.normalize();
        let m = if m.z < 0.0 { -m } else { m };
        if !m.is_finite() {
            return (Rgb::ZERO, 0.0);
        }
        let (cos_om, cos_im) = (wo.dot(m), wi.dot(m));
        let dm = d.d(m);
        let g = d.g(wo, wi, m);
        let fr = self.fresnel(wo, m);
        // The normals are sampled as seen from `wo` turned into the upper hemisphere.
        let wo_up = if wo.z < 0.0 { -wo } else { wo };
        let pdf_m = d.pdf(wo_up, m);
        if reflected {
            let f = self.reflectance * (fr * dm * g / (4.0 * (wo.z * wi.z).abs()));
            let pdf = fr * pdf_m / (4.0 * cos_om.abs());
            (f, pdf)
        } else {
            // Refraction: both directions must face opposite sides of m as of the surface.
            if cos_om * cos_im >= 0.0 {
                return (Rgb::ZERO, 0.0);
            }
            let denom = cos_om + eta * cos_im;
            let denom2 = denom * denom;
            let f = self.transmittance
                * ((1.0 - fr) * dm * g * (cos_om * cos_im).abs() / ((wo.z * wi.z).abs() * denom2));
            // dωm/dωi = η² |wi·m| / (wo·m + η wi·m)².
            let pdf = (1.0 - fr) * pdf_m * eta * eta * cos_im.abs() / denom2;
            (f, pdf)
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let Some(d) = self.distribution else {
            return self.sample_smooth(wo, u_lobe);
        };
        let up = if wo.z < 0.0 { -1.0 } else { 1.0 };
        let m = d.sample(wo * up, u);
        let fr = self.fresnel(wo, m);
        let reflected = u_lobe < fr;
        let wi = if reflected {
            reflect(wo, m)
        } else {
            // Refract through m, oriented towards wo's side.
            let m_side = m * up;
            refract(wo, m_side, self.eta_from(wo))?.normalize()
        };
        // A reflection off a steep facet can leave through the surface, a refraction stay on
        // wo's side: `eval_pdf` would read either as the other event, so neither is a sample.
        if (wo.z * wi.z > 0.0) != reflected {
            return None;
        }
        self.sample_toward(wo, wi)
    }
}

impl RoughDielectric {
    fn sample_smooth(&self, wo: Vec3, u_lobe: f32) -> Option<LocalSample> {
        let eta = self.eta_from(wo);
        let fr = fresnel_dielectric(wo.z.abs(), eta);
        if u_lobe < fr {
            return Some(LocalSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: self.reflectance,
                pdf: fr,
                delta: true,
            });
        }
        let n = Vec3::new(0.0, 0.0, wo.z.signum());
        let wi = refract(wo, n, eta)?.normalize();
        // Radiance is compressed into the denser medium: 1/η² (Mitsuba's radiance mode).
        Some(LocalSample {
            wi,
            weight: self.transmittance / (eta * eta),
            pdf: 1.0 - fr,
            delta: true,
        })
    }
}
