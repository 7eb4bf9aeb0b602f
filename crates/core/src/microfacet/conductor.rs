//! Mitsuba's `conductor` and `roughconductor`: specular or microfacet reflection with the
//! Fresnel reflectance of a complex index of refraction. One-sided unless `two_sided` (then it
//! reflects alike on both sides, as inside Mitsuba's `twosided` wrapper).

use super::{reflect, Distribution, LocalBsdf, LocalSample};
use crate::microfacet::fresnel_conductor;
use crate::Rgb;
use glam::{Vec2, Vec3};

/// A conductor: smooth when `distribution` is `None`, rough otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    /// The rough surface's normals; `None` for a smooth (mirror) conductor.
    pub distribution: Option<Distribution>,
    /// Real part of the relative index of refraction, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption), per channel.
    pub k: Rgb,
    /// A factor on the reflectance (Mitsuba's `specular_reflectance`; 1 for physical metals).
    pub specular_reflectance: Rgb,
    /// Reflect light from below the surface too, mirrored (Mitsuba's `twosided`).
    pub two_sided: bool,
}

impl RoughConductor {
    fn fresnel(&self, cos: f32) -> Rgb {
        fresnel_conductor(cos, self.eta, self.k) * self.specular_reflectance
    }
}

/// `w` mirrored into the upper hemisphere when `flip`.
#[inline]
fn up(w: Vec3, flip: bool) -> Vec3 {
    if flip {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

impl LocalBsdf for RoughConductor {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let flip = self.two_sided && wo.z < 0.0;
        let (wo, wi) = (up(wo, flip), up(wi, flip));
        let Some(d) = self.distribution else {
            return (Rgb::ZERO, 0.0);
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let m = (wo + wi).normalize();
        let cos_om = wo.dot(m);
        if !m.is_finite() || cos_om <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let dm = d.d(m);
        let f = self.fresnel(cos_om) * (dm * d.g(wo, wi, m) / (4.0 * wo.z * wi.z));
        // dωm/dωi = 1 / (4 wo·m) for reflection.
        let pdf = d.pdf(wo, m) / (4.0 * cos_om);
        (f, pdf)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if self.two_sided && wo.z < 0.0 {
            let one_sided = RoughConductor {
                two_sided: false,
                ..*self
            };
            // One lobe: nothing to choose.
            let s = one_sided.sample(up(wo, true), 0.0, u)?;
            return Some(LocalSample {
                wi: up(s.wi, true),
                ..s
            });
        }
        if wo.z <= 0.0 {
            return None;
        }
        let Some(d) = self.distribution else {
            return Some(LocalSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: self.fresnel(wo.z),
                pdf: 1.0,
                delta: true,
            });
        };
        let m = d.sample(wo, u);
        let wi = reflect(wo, m);
        if wi.z <= 0.0 {
            return None;
        }
        self.sample_toward(wo, wi)
    }
}
