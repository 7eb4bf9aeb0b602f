//! The microfacet BSDF family, as Mitsuba 3 defines it: the GGX and Beckmann normal
//! distributions (isotropic and anisotropic) with Smith masking, conductors with complex
//! indices of refraction, and rough dielectrics (Walter, Marschner, Li and Torrance, "Microfacet
//! Models for Refraction through Rough Surfaces", EGSR 2007). GGX samples its visible normals
//! (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 2018).
//!
//! Each BSDF works in the local shading frame (`+z` the normal, [`crate::frame::Frame`]) and
//! returns `f` without the cosine, as [`crate::material::Bsdf`] does; the integrators' weight is
//! `f·|cos θi| / pdf`. Depends on nothing but `glam` and the crate's colour type.
//!
//! Deviations from Mitsuba 3: Beckmann samples the whole distribution of normals (`D(m)·cos θm`,
//! Walter 2007) instead of its visible normals, which changes the variance, not the image;
//! masking-shadowing is Mitsuba's separable Smith form `G1(wo)·G1(wi)`.

mod conductor;
mod dielectric;
mod distribution;
mod fresnel;

pub use conductor::RoughConductor;
pub use dielectric::RoughDielectric;
pub use distribution::{Distribution, DistributionKind};
pub use fresnel::fresnel_conductor;

use crate::Rgb;
use glam::{Vec2, Vec3};

/// A sampled direction of a local BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSample {
    /// The incident direction (local frame, unit).
    pub wi: Vec3,
    /// `f·|cos θi| / pdf`.
    pub weight: Rgb,
    /// Solid-angle pdf of `wi`; for a delta lobe, the probability of choosing it.
    pub pdf: f32,
    /// A delta lobe (smooth surface): `f` is a Dirac delta, `eval_pdf` never sees `wi`.
    pub delta: bool,
}

/// A BSDF in the local shading frame.
pub trait LocalBsdf {
    /// `(f, pdf)` for outgoing `wo` and incident `wi` (local, unit): the BSDF value without
    /// the cosine and the solid-angle pdf with which [`LocalBsdf::sample`] produces `wi`.
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32);

    /// Samples `wi` for `wo`; `u_lobe` chooses between lobes (reflection or refraction), `u`
    /// the microfacet normal. `None` where the sample carries nothing.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample>;
}

/// Mirror reflection of `wo` about unit normal `m`.
#[inline]
pub fn reflect(wo: Vec3, m: Vec3) -> Vec3 {
    2.0 * wo.dot(m) * m - wo
}
