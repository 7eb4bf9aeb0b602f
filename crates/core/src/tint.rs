//! What a material's textures read at one surface point: the `texture` colour that multiplies
//! its diffuse colours, and the values of its textured parameters
//! ([`crate::microfacet::ParamValues`]). [`crate::Scene::tint`] looks them up; a
//! [`crate::material::Bsdf`] is built from them.
//!
//! A blend's textures ([`crate::microfacet::Blend`]) are not read here but where its BSDF is
//! evaluated ([`crate::microfacet::BlendAt`]): their values, two BSDFs' worth, would make every
//! `Tint` and every [`crate::material::Bsdf`] larger, and the path tracer copies both at every
//! vertex of every material. A `Tint` carries what that reading needs instead
//! ([`TexturesAt`]). So does a conductor's textured index of refraction
//! ([`crate::microfacet::ParamTextures::ior_at`]), the one other parameter read that way.

use crate::microfacet::ParamValues;
use crate::{Rgb, Scene};
use glam::Vec2;

/// A material's texture values at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tint<'a> {
    /// The `texture` colour (white without one).
    pub color: Rgb,
    /// The textured parameters (all `None` without textured parameters).
    pub params: ParamValues,
    /// Where a blend's textures or a textured `eta` or `k` are read (`None` for the other
    /// materials, and for a blend whose textures read as their constants).
    pub at: Option<TexturesAt<'a>>,
}

/// The scene and a point's uv: what a lookup of the scene's textures at that point needs.
#[derive(Clone, Copy)]
pub struct TexturesAt<'a> {
    /// The scene, whose textures materials index (a thin pointer: the path tracer copies
    /// this in every [`crate::material::Bsdf`]).
    pub scene: &'a Scene,
    /// The point's texture coordinates.
    pub uv: Vec2,
}

impl std::fmt::Debug for TexturesAt<'_> {
    /// The point (not the whole scene).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TexturesAt")
            .field("uv", &self.uv)
            .finish_non_exhaustive()
    }
}

impl PartialEq for TexturesAt<'_> {
    /// The same point of the same textures.
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.scene, other.scene) && self.uv == other.uv
    }
}

impl TexturesAt<'_> {
    /// Texture `i`'s colour here.
    #[inline]
    pub fn color(&self, i: u32) -> Rgb {
        self.scene.textures[i as usize].lookup(self.uv)
    }
}

impl Tint<'_> {
    /// No texture: white, every parameter its constant.
    pub const NONE: Tint<'static> = Tint {
        color: Rgb::ONE,
        params: ParamValues::NONE,
        at: None,
    };
}

impl From<Rgb> for Tint<'_> {
    /// A colour texture alone.
    fn from(color: Rgb) -> Self {
        Tint {
            color,
            ..Tint::NONE
        }
    }
}
