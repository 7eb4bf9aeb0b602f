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

mod blend;
mod conductor;
mod dielectric;
mod diffuse;
mod distribution;
mod fresnel;
pub mod named;
mod plastic;
mod rough_plastic;
mod textured;
mod thin;

pub use blend::{Blend, BlendAt, BlendPart, Blended};
pub use conductor::RoughConductor;
pub use dielectric::RoughDielectric;
pub use diffuse::Diffuse;
pub use distribution::{Distribution, DistributionKind, MIN_ALPHA};
pub use fresnel::fresnel_conductor;
pub use plastic::{fresnel_diffuse_reflectance, Plastic};
pub use rough_plastic::{AlphaTables, RoughPlastic, ALPHA_NODES};
pub use textured::{IorValues, ParamTextures, ParamValues};
pub use thin::ThinDielectric;

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

    /// The non-delta sample of direction `wi` for `wo`: its value and pdf from
    /// [`LocalBsdf::eval_pdf`] and the weight `f·|cos θi| / pdf`; `None` where the pdf is not
    /// a positive finite number. What every `sample` ends with once it has chosen `wi`.
    fn sample_toward(&self, wo: Vec3, wi: Vec3) -> Option<LocalSample> {
        let (f, pdf) = self.eval_pdf(wo, wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(LocalSample {
            wi,
            weight: f * (wi.z.abs() / pdf),
            pdf,
            delta: false,
        })
    }
}

/// The complex index `(η, κ)` of Mitsuba's named conductor `name` ([`named::CONDUCTORS`]).
pub fn named_conductor(name: &str) -> Option<(Rgb, Rgb)> {
    named::CONDUCTORS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|&(_, eta, k)| (eta, k))
}

/// The index of refraction of Mitsuba's named dielectric `name` ([`named::DIELECTRICS`]).
pub fn named_ior(name: &str) -> Option<f32> {
    named::DIELECTRICS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, ior)| ior)
}

/// Mirror reflection of `wo` about unit normal `m`.
#[inline]
pub fn reflect(wo: Vec3, m: Vec3) -> Vec3 {
    2.0 * wo.dot(m) * m - wo
}

/// One BSDF of the family, as a material holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
// Rough plastic carries its 64-entry transmittance table inline: a material holds one, and
// the BSDF a hit builds copies it (a few hundred bytes, no allocation, no indirection).
#[allow(clippy::large_enum_variant)]
pub enum Microfacet {
    /// `conductor`, `roughconductor`.
    Conductor(RoughConductor),
    /// `dielectric`, `roughdielectric`.
    Dielectric(RoughDielectric),
    /// `plastic`.
    Plastic(Plastic),
    /// `roughplastic`.
    RoughPlastic(RoughPlastic),
    /// `thindielectric`.
    ThinDielectric(ThinDielectric),
    /// `diffuse`, as one of a blend's BSDFs ([`Blend`]).
    Diffuse(Diffuse),
}

macro_rules! from_bsdf {
    ($($ty:ident => $variant:ident),*) => {$(
        impl From<$ty> for Microfacet {
            fn from(b: $ty) -> Self {
                Microfacet::$variant(b)
            }
        }
    )*};
}

from_bsdf!(
    RoughConductor => Conductor,
    RoughDielectric => Dielectric,
    Plastic => Plastic,
    RoughPlastic => RoughPlastic,
    ThinDielectric => ThinDielectric,
    Diffuse => Diffuse
);

impl Microfacet {
    /// The surface's normal distribution (`None`: smooth, every lobe a delta).
    pub fn distribution(&self) -> Option<Distribution> {
        match self {
            Microfacet::Conductor(c) => c.distribution,
            Microfacet::Dielectric(d) => d.distribution,
            Microfacet::RoughPlastic(p) => Some(p.distribution),
            Microfacet::Plastic(_) | Microfacet::ThinDielectric(_) | Microfacet::Diffuse(_) => None,
        }
    }

    /// True if some lobe is not a delta (light sampling can contribute).
    pub fn has_non_delta(&self) -> bool {
        matches!(self, Microfacet::Plastic(_) | Microfacet::Diffuse(_))
            || self.distribution().is_some()
    }

    /// Reflectance at normal incidence, for the albedo AOV.
    pub fn albedo(&self) -> Rgb {
        match self {
            Microfacet::Conductor(c) => fresnel_conductor(1.0, c.eta, c.k) * c.specular_reflectance,
            Microfacet::Dielectric(d) => d.transmittance,
            Microfacet::Plastic(p) => p.diffuse,
            Microfacet::RoughPlastic(p) => p.diffuse,
            Microfacet::ThinDielectric(t) => t.transmittance,
            Microfacet::Diffuse(d) => d.reflectance,
        }
    }

    /// The BSDF with a texture's `tint` multiplying the diffuse base of the plastics, the
    /// diffuse's reflectance and a conductor's `specular_reflectance` (glTF's base colour
    /// texture on its metal; Mitsuba's loader gives conductors no such texture); the
    /// dielectrics take none. `None` when the tint changes nothing.
    fn tinted(&self, tint: Rgb) -> Option<Self> {
        if tint == Rgb::ONE {
            return None;
        }
        match *self {
            Microfacet::Plastic(mut p) => {
                p.diffuse *= tint;
                Some(Microfacet::Plastic(p))
            }
            Microfacet::RoughPlastic(mut p) => {
                p.diffuse *= tint;
                Some(Microfacet::RoughPlastic(p))
            }
            Microfacet::Diffuse(mut d) => {
                d.reflectance *= tint;
                Some(Microfacet::Diffuse(d))
            }
            Microfacet::Conductor(mut c) => {
                c.specular_reflectance *= tint;
                Some(Microfacet::Conductor(c))
            }
            _ => None,
        }
    }

    /// [`LocalBsdf::eval_pdf`] under a texture's `tint` (a copy of the BSDF only for a
    /// textured plastic).
    pub fn eval_pdf_tinted(&self, tint: Rgb, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        match self.tinted(tint) {
            Some(t) => t.eval_pdf(wo, wi),
            None => self.eval_pdf(wo, wi),
        }
    }

    /// What a transmitted value is multiplied by in importance transport
    /// ([`crate::material::Bsdf::adjoint`]): `η(wo)²` for a dielectric interface, whose
    /// refraction scales radiance by `1/η²`; 1 for a thin sheet, which does not.
    pub fn adjoint_scale(&self, wo: Vec3) -> f32 {
        match self {
            Microfacet::Dielectric(d) => d.eta_from(wo).powi(2),
            _ => 1.0,
        }
    }

    /// [`LocalBsdf::sample`] under a texture's `tint`.
    pub fn sample_tinted(&self, tint: Rgb, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        match self.tinted(tint) {
            Some(t) => t.sample(wo, u_lobe, u),
            None => self.sample(wo, u_lobe, u),
        }
    }

    /// [`Microfacet::albedo`] under a texture's `tint`.
    pub fn albedo_tinted(&self, tint: Rgb) -> Rgb {
        self.tinted(tint)
            .map_or_else(|| self.albedo(), |t| t.albedo())
    }

    /// Checks every parameter's range; the message names the parameter.
    pub fn validate(&self) -> Result<(), String> {
        let colour = |c: Rgb, what: &str| {
            if !c.is_finite() || c.min_element() < 0.0 || c.max_element() > 1.0 {
                Err(format!("{what} must be in [0, 1], got {:?}", c.to_array()))
            } else {
                Ok(())
            }
        };
        if let Some(d) = self.distribution() {
            for (a, what) in [(d.alpha_x, "alpha_u"), (d.alpha_y, "alpha_v")] {
                if !(a.is_finite() && a > 0.0) {
                    return Err(format!("{what} must be a positive number, got {a}"));
                }
            }
        }
        match self {
            Microfacet::Conductor(c) => {
                for (v, what) in [(c.eta, "eta"), (c.k, "k")] {
                    if !v.is_finite() || v.min_element() < 0.0 {
                        return Err(format!(
                            "{what} must be finite and non-negative, got {:?}",
                            v.to_array()
                        ));
                    }
                }
                colour(c.specular_reflectance, "specular_reflectance")
            }
            Microfacet::Dielectric(d) => {
                if !(d.eta.is_finite() && d.eta > 0.0) || d.eta == 1.0 {
                    return Err(format!(
                        "int_ior / ext_ior must be a positive number other than 1, got {}",
                        d.eta
                    ));
                }
                colour(d.reflectance, "specular_reflectance")?;
                colour(d.transmittance, "specular_transmittance")
            }
            Microfacet::Plastic(p) => {
                if !(p.eta.is_finite() && p.eta > 0.0) || p.eta == 1.0 {
                    return Err(format!(
                        "int_ior / ext_ior must be a positive number other than 1, got {}",
                        p.eta
                    ));
                }
                colour(p.diffuse, "diffuse_reflectance")?;
                colour(p.specular, "specular_reflectance")
            }
            Microfacet::RoughPlastic(p) => {
                if !(p.eta.is_finite() && p.eta > 0.0) || p.eta == 1.0 {
                    return Err(format!(
                        "int_ior / ext_ior must be a positive number other than 1, got {}",
                        p.eta
                    ));
                }
                if p.distribution.alpha_x != p.distribution.alpha_y {
                    return Err(
                        "roughplastic is isotropic: give alpha, not alpha_u and alpha_v".into(),
                    );
                }
                colour(p.diffuse, "diffuse_reflectance")?;
                colour(p.specular, "specular_reflectance")
            }
            Microfacet::ThinDielectric(t) => {
                if !(t.eta.is_finite() && t.eta > 0.0) {
                    return Err(format!(
                        "int_ior / ext_ior must be a positive number, got {}",
                        t.eta
                    ));
                }
                colour(t.reflectance, "specular_reflectance")?;
                colour(t.transmittance, "specular_transmittance")
            }
            Microfacet::Diffuse(d) => colour(d.reflectance, "reflectance"),
        }
    }
}

/// `w` mirrored through the surface.
#[inline]
fn mirrored(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl Microfacet {
    /// True if `wo` sees a two-sided plastic from below, which reflects as its front does with
    /// both directions mirrored (the conductor mirrors itself).
    #[inline]
    fn seen_from_below(&self, wo: Vec3) -> bool {
        let two_sided = match self {
            Microfacet::Plastic(p) => p.two_sided,
            Microfacet::RoughPlastic(p) => p.two_sided,
            _ => false,
        };
        two_sided && wo.z < 0.0
    }

    fn front_eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        match self {
            Microfacet::Conductor(c) => c.eval_pdf(wo, wi),
            Microfacet::Dielectric(d) => d.eval_pdf(wo, wi),
            Microfacet::Plastic(p) => p.eval_pdf(wo, wi),
            Microfacet::RoughPlastic(p) => p.eval_pdf(wo, wi),
            Microfacet::ThinDielectric(t) => t.eval_pdf(wo, wi),
            Microfacet::Diffuse(d) => d.eval_pdf(wo, wi),
        }
    }

    fn front_sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        match self {
            Microfacet::Conductor(c) => c.sample(wo, u_lobe, u),
            Microfacet::Dielectric(d) => d.sample(wo, u_lobe, u),
            Microfacet::Plastic(p) => p.sample(wo, u_lobe, u),
            Microfacet::RoughPlastic(p) => p.sample(wo, u_lobe, u),
            Microfacet::ThinDielectric(t) => t.sample(wo, u_lobe, u),
            Microfacet::Diffuse(d) => d.sample(wo, u_lobe, u),
        }
    }
}

impl LocalBsdf for Microfacet {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if self.seen_from_below(wo) {
            return self.front_eval_pdf(mirrored(wo), mirrored(wi));
        }
        self.front_eval_pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if self.seen_from_below(wo) {
            let s = self.front_sample(mirrored(wo), u_lobe, u)?;
            return Some(LocalSample {
                wi: mirrored(s.wi),
                ..s
            });
        }
        self.front_sample(wo, u_lobe, u)
    }
}

impl crate::content_hash::ContentHash for Microfacet {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        // The Debug form names every field and prints floats exactly (shortest round-trip).
        format!("{self:?}").content_hash(out);
    }
}
