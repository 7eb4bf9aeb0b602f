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
//! `roughplastic`'s `alpha` takes a texture too, which Mitsuba 3 refuses: its coating's
//! tables come from [`AlphaTables`], computed over the texture's range when the scene loads.

use super::{AlphaTables, Distribution, Microfacet};
use crate::texture::{luminance, Texture};
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

impl ParamTextures {
    /// True when no parameter is textured.
    #[inline]
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
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
    /// The BSDF with the textured parameters `v` in place of its constants; `None` when `v`
    /// changes nothing. A parameter the type does not have is ignored (the loaders refuse
    /// such textures). A rough plastic's textured roughness takes its coating's tables from
    /// `tables` (without them, only its distribution changes).
    pub fn with_params(&self, v: &ParamValues, tables: Option<&AlphaTables>) -> Option<Self> {
        let v = ParamValues {
            opacity: None,
            ..*v
        };
        if v.is_empty() {
            return None;
        }
        let mut out = *self;
        match &mut out {
            Microfacet::Conductor(c) => {
                c.distribution = c.distribution.map(|d| v.distribution(d));
                if let Some(r) = v.specular_reflectance {
                    c.specular_reflectance = r;
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
