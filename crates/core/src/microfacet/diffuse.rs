//! Mitsuba's `diffuse` as a BSDF of the family, for the BSDFs a `blendbsdf` blends
//! ([`super::Blend`]); a material that is diffuse alone stays a layer of the layered model.
//!
//! Deviation from Mitsuba 3, as for the layered model's diffuse: both faces reflect (Mitsuba's
//! `diffuse` is black from behind).

use super::{LocalBsdf, LocalSample};
use crate::sampling::cosine_hemisphere;
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// A Lambertian reflector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// The albedo (Mitsuba's `reflectance`, default 0.5).
    pub reflectance: Rgb,
}

impl LocalBsdf for Diffuse {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z * wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        (self.reflectance * FRAC_1_PI, wi.z.abs() * FRAC_1_PI)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let d = cosine_hemisphere(u);
        self.sample_toward(wo, Vec3::new(d.x, d.y, d.z.copysign(wo.z)))
    }
}
