//! What a material's textures read at one surface point: the `texture` colour that multiplies
//! its diffuse colours, and the values of its textured parameters
//! ([`crate::microfacet::ParamValues`]). [`crate::Scene::tint`] looks them up; a
//! [`crate::material::Bsdf`] is built from them.

use crate::microfacet::{ParamValues, PartTint};
use crate::Rgb;

/// A material's texture values at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tint {
    /// The `texture` colour (white without one).
    pub color: Rgb,
    /// The textured parameters (all `None` without textured parameters).
    pub params: ParamValues,
    /// A blend's two BSDFs' texture values ([`crate::microfacet::Blend`]; its weight is
    /// `params.weight`).
    pub blend: [PartTint; 2],
}

impl Tint {
    /// No texture: white, every parameter its constant.
    pub const NONE: Tint = Tint {
        color: Rgb::ONE,
        params: ParamValues::NONE,
        blend: [PartTint::NONE; 2],
    };
}

impl From<Rgb> for Tint {
    /// A colour texture alone.
    fn from(color: Rgb) -> Self {
        Tint {
            color,
            ..Tint::NONE
        }
    }
}
