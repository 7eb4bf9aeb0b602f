//! Mitsuba's `plastic`: a diffuse base under a smooth dielectric coating. Light either reflects
//! off the coating (a delta lobe with the Fresnel reflectance) or enters, scatters diffusely in
//! the base, possibly many times between base and coating (the `1 / (1 − F_dr)` series), and
//! leaves through the coating (Weidlich and Wilkie 2007's layered model as Mitsuba implements
//! it). One-sided. Uses the internal diffuse Fresnel reflectance fit of d'Eon and Irving
//! (2011), as Mitsuba's `fresnel_diffuse_reflectance` does.

use super::{LocalBsdf, LocalSample};
use crate::material::fresnel_dielectric;
use crate::sampling::cosine_hemisphere;
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Smooth plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The base's albedo (Mitsuba's `diffuse_reflectance`, default 0.5).
    pub diffuse: Rgb,
    /// A factor on the coating's reflection (Mitsuba's `specular_reflectance`, default 1).
    pub specular: Rgb,
    /// Interior over exterior index of refraction of the coating.
    pub eta: f32,
    /// Account for the colour shift of repeated internal scattering (Mitsuba's `nonlinear`).
    pub nonlinear: bool,
    /// Reflect alike from below, mirrored (Mitsuba's `twosided`); applied by
    /// [`super::Microfacet`], which mirrors both directions to the front.
    pub two_sided: bool,
}

/// The hemispherical average of the Fresnel reflectance for relative index `eta` (d'Eon and
/// Irving 2011's polynomial fits).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let i = 1.0 / eta;
        let (i2, i3) = (i * i, i * i * i);
        0.919317 - 3.4793 * i + 6.75335 * i2 - 7.80989 * i3 + 4.98554 * i2 * i2 - 1.36881 * i2 * i3
    }
}

impl Plastic {
    fn mean(c: Rgb) -> f32 {
        (c.x + c.y + c.z) / 3.0
    }

    /// The probability of sampling the coating's reflection for `wo` (Fresnel-weighted split
    /// between the two lobes' mean albedos, as Mitsuba's).
    fn specular_probability(&self, f_o: f32) -> f32 {
        let (s, d) = (Self::mean(self.specular), Self::mean(self.diffuse));
        let w = s / (s + d);
        let ps = f_o * w;
        let pd = (1.0 - f_o) * (1.0 - w);
        ps / (ps + pd)
    }

    /// The diffuse lobe's value for Fresnel transmittances `t_o`, `t_i`.
    fn diffuse_value(&self, f_o: f32, f_i: f32) -> Rgb {
        let fdr_int = fresnel_diffuse_reflectance(1.0 / self.eta);
        let denom = if self.nonlinear {
            Rgb::ONE - self.diffuse * fdr_int
        } else {
            Rgb::splat(1.0 - fdr_int)
        };
        self.diffuse / denom * ((1.0 - f_o) * (1.0 - f_i) / (self.eta * self.eta) * FRAC_1_PI)
    }
}

impl LocalBsdf for Plastic {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let f_i = fresnel_dielectric(wi.z, self.eta);
        let pdf = (1.0 - self.specular_probability(f_o)) * wi.z * FRAC_1_PI;
        (self.diffuse_value(f_o, f_i), pdf)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta);
        let ps = self.specular_probability(f_o);
        if u_lobe < ps {
            return Some(LocalSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: self.specular * (f_o / ps),
                pdf: ps,
                delta: true,
            });
        }
        let wi = cosine_hemisphere(u);
        self.sample_toward(wo, wi)
    }
}
