//! Textures on the microfacet family's parameters, as Mitsuba 3 allows them: `alpha`,
//! `alpha_u` and `alpha_v` of `roughconductor` and `roughdielectric`, the conductors'
//! `specular_reflectance`, the dielectrics' `specular_reflectance` and
//! `specular_transmittance` (and the plastics' `specular_reflectance`). A material names the
//! textures ([`ParamTextures`]); the scene looks them up at a hit ([`ParamValues`]) and the
//! BSDF of that hit is the material's with those values in place ([`Microfacet::with_params`]).
//!
//! A colour parameter reads the texture's colour; a scalar one (a roughness) its luminance,
//! as Mitsuba's `eval_1` does on an RGB bitmap. Texels are clamped to [0, 1] by
//! [`crate::texture::Texture::lookup`]; a roughness texel of 0 becomes
//! [`super::MIN_ALPHA`], as a constant 0 does.
//!
//! A conductor's `eta` and `k` take textures too. They are not reflectances: they are read
//! unclamped ([`Texture::lookup_unbounded`]), and where the BSDF is evaluated
//! ([`ParamTextures::ior_at`]) rather than into [`ParamValues`], which every
//! [`crate::material::Bsdf`] carries (see [`crate::tint`]).
//!
//! `roughplastic`'s `alpha` takes a texture too, which Mitsuba 3 refuses: its coating's
//! tables come from [`AlphaTables`], computed over the texture's range when the scene loads.

use super::{AlphaTables, Distribution, Microfacet};
use crate::texture::{luminance, Texture};
use crate::tint::TexturesAt;
use crate::Rgb;
use glam::Vec2;

/// Indices (into the scene's textures) of the textures on a material's parameters; `None`
/// where the parameter is constant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ParamTextures {
    /// Roughness along the tangent (`alpha`, or `alpha_u`).
    pub alpha_u: Option<u32>,
    /// Roughness along the bitangent (`alpha`, or `alpha_v`).
    pub alpha_v: Option<u32>,
    /// `specular_reflectance`.
    pub specular_reflectance: Option<u32>,
    /// `specular_transmittance`.
    pub specular_transmittance: Option<u32>,
    /// A mask's opacity ([`crate::Material::opacity`]; any material type).
    pub opacity: Option<u32>,
    /// A conductor's `eta` (real part of its index of refraction, per channel).
    pub eta: Option<u32>,
    /// A conductor's `k` (imaginary part).
    pub k: Option<u32>,
}

/// The textured parameters' values at one surface point (`None`: the material's constant).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ParamValues {
    /// See [`ParamTextures::alpha_u`].
    pub alpha_u: Option<f32>,
    /// See [`ParamTextures::alpha_v`].
    pub alpha_v: Option<f32>,
    /// See [`ParamTextures::specular_reflectance`].
    pub specular_reflectance: Option<Rgb>,
    /// See [`ParamTextures::specular_transmittance`].
    pub specular_transmittance: Option<Rgb>,
    /// See [`ParamTextures::opacity`].
    pub opacity: Option<f32>,
}

/// A conductor's textured index of refraction at one point (`None`: the constant).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IorValues {
    /// See [`ParamTextures::eta`].
    pub eta: Option<Rgb>,
    /// See [`ParamTextures::k`].
    pub k: Option<Rgb>,
}

impl IorValues {
    /// Both parts their constants.
    pub const NONE: IorValues = IorValues { eta: None, k: None };
}

impl ParamTextures {
    /// True when no parameter is textured.
    #[inline]
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// The text a material's content hash reads: the derived `Debug` form the struct had
    /// before `eta` and `k`, which follow only when textured, so that scenes keep their hashes.
    pub fn hash_text(&self) -> String {
        let ParamTextures {
            alpha_u,
            alpha_v,
            specular_reflectance,
            specular_transmittance,
            opacity,
            eta,
            k,
        } = self;
        let mut text = format!(
            "ParamTextures {{ alpha_u: {alpha_u:?}, alpha_v: {alpha_v:?}, \
             specular_reflectance: {specular_reflectance:?}, \
             specular_transmittance: {specular_transmittance:?}, opacity: {opacity:?} }}"
        );
        if self.has_ior() {
            text += &format!(" eta: {eta:?}, k: {k:?}");
        }
        text
    }

    /// True when `eta` or `k` is textured: the BSDF reads them where it is evaluated
    /// ([`ParamTextures::ior_at`]), so the scene hands it where to ([`crate::tint::Tint::at`]).
    #[inline]
    pub fn has_ior(&self) -> bool {
        self.eta.is_some() || self.k.is_some()
    }

    /// `eta` and `k` at `at`, unclamped.
    #[inline]
    pub fn ior_at(&self, at: &TexturesAt) -> IorValues {
        let read =
            |t: Option<u32>| t.map(|i| at.scene.textures[i as usize].lookup_unbounded(at.uv));
        IorValues {
            eta: read(self.eta),
            k: read(self.k),
        }
    }

    /// The values at `uv` of the textures in `textures`.
    #[inline]
    pub fn lookup(&self, textures: &[Texture], uv: Vec2) -> ParamValues {
        if self.is_empty() {
            return ParamValues::default();
        }
        let colour = |t: Option<u32>| t.map(|i| textures[i as usize].lookup(uv));
        let scalar = |t: Option<u32>| colour(t).map(luminance);
        ParamValues {
            alpha_u: scalar(self.alpha_u),
            alpha_v: scalar(self.alpha_v),
            specular_reflectance: colour(self.specular_reflectance),
            specular_transmittance: colour(self.specular_transmittance),
            opacity: scalar(self.opacity),
        }
    }
}

impl ParamValues {
    /// Every parameter its constant.
    pub const NONE: ParamValues = ParamValues {
        alpha_u: None,
        alpha_v: None,
        specular_reflectance: None,
        specular_transmittance: None,
        opacity: None,
    };

    /// True when every parameter keeps its constant.
    #[inline]
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// `d` with the textured roughness in place.
    fn distribution(&self, d: Distribution) -> Distribution {
        Distribution::new(
            d.kind,
            self.alpha_u.unwrap_or(d.alpha_x),
            self.alpha_v.unwrap_or(d.alpha_y),
        )
    }
}

impl Microfacet {
    /// The BSDF with the textured parameters `v` and index of refraction `ior` in place of
    /// its constants; `None` when they change nothing. A parameter the type does not have is
    /// ignored (the loaders refuse such textures). A rough plastic's textured roughness takes
    /// its coating's tables from `tables` (without them, only its distribution changes).
    pub fn with_params(
        &self,
        v: &ParamValues,
        ior: &IorValues,
        tables: Option<&AlphaTables>,
    ) -> Option<Self> {
        let v = ParamValues {
            opacity: None,
            ..*v
        };
        if v.is_empty() && *ior == IorValues::NONE {
            return None;
        }
        let mut out = *self;
        match &mut out {
            Microfacet::Conductor(c) => {
                c.distribution = c.distribution.map(|d| v.distribution(d));
                if let Some(r) = v.specular_reflectance {
                    c.specular_reflectance = r;
                }
                if let Some(eta) = ior.eta {
                    c.eta = eta;
                }
                if let Some(k) = ior.k {
                    c.k = k;
                }
            }
            Microfacet::Dielectric(d) => {
                d.distribution = d.distribution.map(|x| v.distribution(x));
                if let Some(r) = v.specular_reflectance {
                    d.reflectance = r;
                }
                if let Some(t) = v.specular_transmittance {
                    d.transmittance = t;
                }
            }
            Microfacet::ThinDielectric(d) => {
                if let Some(r) = v.specular_reflectance {
                    d.reflectance = r;
                }
                if let Some(t) = v.specular_transmittance {
                    d.transmittance = t;
                }
            }
            Microfacet::Plastic(p) => {
                if let Some(r) = v.specular_reflectance {
                    p.specular = r;
                }
            }
            Microfacet::RoughPlastic(p) => {
                if let Some(a) = v.alpha_u {
                    *p = match tables {
                        Some(t) => p.with_alpha(a, t),
                        None => {
                            let mut q = *p;
                            q.distribution = v.distribution(p.distribution);
                            q
                        }
                    };
                }
                if let Some(r) = v.specular_reflectance {
                    p.specular = r;
                }
            }
            Microfacet::Diffuse(_) => {}
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hash text of textures without `eta` and `k` is the derived `Debug` form the
    /// struct had before them.
    #[test]
    fn hash_text_is_the_old_debug_form() {
        let t = ParamTextures {
            alpha_u: Some(3),
            opacity: Some(1),
            ..ParamTextures::default()
        };
        let old = "ParamTextures { alpha_u: Some(3), alpha_v: None, specular_reflectance: None, \
                   specular_transmittance: None, opacity: Some(1) }";
        assert_eq!(t.hash_text(), old);
        let eta = ParamTextures { eta: Some(2), ..t };
        assert_eq!(eta.hash_text(), format!("{old} eta: Some(2), k: None"));
    }
}
