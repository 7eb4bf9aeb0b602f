//! Mitsuba 3's `blendbsdf`: `(1 − w)·f₀ + w·f₁` for a weight `w` in [0, 1] (a constant, or a
//! texture's luminance, [`Blend::weight_texture`]) and two BSDFs of the family.
//!
//! Sampling picks BSDF 1 with probability `w` and BSDF 0 otherwise, as Mitsuba does. A
//! non-delta sample then carries the blend's value and the blend of both pdfs (the mixture's
//! density, [`LocalBsdf::eval_pdf`] of the blend), where Mitsuba reports the chosen BSDF's own
//! value and pdf: the same expectation, and MIS sees the density the sampler really has. A
//! delta sample keeps its weight and has its probability scaled by the pick's.
//!
//! Each BSDF keeps its own textured parameters and colour texture ([`BlendPart`]). They are
//! read where the blend is evaluated ([`BlendAt::blended`]), not when its
//! [`crate::material::Bsdf`] is built, so that a `Bsdf` holds no blend by value (see
//! [`crate::tint`]). A blend inside a blend is not represented: the loaders refuse it.

use super::rough_plastic::AlphaTables;
use super::{IorValues, LocalBsdf, LocalSample, Microfacet, ParamTextures, ParamValues};
use crate::texture::luminance;
use crate::tint::TexturesAt;
use crate::Rgb;
use glam::{Vec2, Vec3};

/// One of the two BSDFs of a blend, with its textures.
#[derive(Clone, Debug, PartialEq)]
pub struct BlendPart {
    /// The BSDF (any type of the family; not a blend).
    pub bsdf: Microfacet,
    /// Textures on its parameters (their `opacity` is not used).
    pub textures: ParamTextures,
    /// A colour texture multiplying its diffuse colour (a diffuse's or a plastic's base).
    pub texture: Option<u32>,
    /// A rough plastic's tables over the range of its textured `alpha`.
    pub alpha_tables: Option<AlphaTables>,
}

impl BlendPart {
    /// A BSDF without textures.
    pub fn new(bsdf: Microfacet) -> Self {
        Self {
            bsdf,
            textures: ParamTextures::default(),
            texture: None,
            alpha_tables: None,
        }
    }
}

/// What one BSDF of a blend reads from its textures at a point.
struct PartTint {
    /// Its colour texture's value (white without one).
    color: Rgb,
    /// Its textured parameters.
    params: ParamValues,
    /// A conductor's textured index of refraction.
    ior: IorValues,
}

impl PartTint {
    /// No texture.
    const NONE: PartTint = PartTint {
        color: Rgb::ONE,
        params: ParamValues::NONE,
        ior: IorValues::NONE,
    };
}

/// Mitsuba's `blendbsdf`, as a material holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct Blend {
    /// `w`, the weight of `parts[1]`, in [0, 1] (`weight_texture` replaces it).
    pub weight: f32,
    /// A texture whose luminance is the weight (an index into the scene's textures).
    pub weight_texture: Option<u32>,
    /// BSDF 0 (weight `1 − w`) and BSDF 1 (weight `w`).
    pub parts: [BlendPart; 2],
}

/// A material's blend at one surface point, its textures not read yet.
#[derive(Clone, Copy, Debug)]
pub struct BlendAt<'a> {
    /// The material's blend.
    pub blend: &'a Blend,
    /// Where its textures are read (`None`: each reads as its constant).
    pub at: Option<TexturesAt<'a>>,
}

impl BlendAt<'_> {
    /// The blend with its textures' values at this point in place.
    pub fn blended(&self) -> Blended {
        let b = self.blend;
        let Some(at) = self.at else {
            return b.at(None, &[PartTint::NONE, PartTint::NONE]);
        };
        let tint = |p: &BlendPart| PartTint {
            color: p.texture.map_or(Rgb::ONE, |i| at.color(i)),
            params: p.textures.lookup(&at.scene.textures, at.uv),
            ior: p.textures.ior_at(&at),
        };
        let weight = b.weight_texture.map(|i| luminance(at.color(i)));
        b.at(weight, &[tint(&b.parts[0]), tint(&b.parts[1])])
    }

    /// True if some BSDF of positive weight here has a non-delta lobe.
    #[inline(never)]
    pub fn has_non_delta(&self) -> bool {
        self.blended().has_non_delta()
    }
}

/// A blend at one point: its weight and both BSDFs with their textures' values in place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blended {
    /// `w`, the weight of `bsdfs[1]`.
    pub weight: f32,
    /// The two BSDFs.
    pub bsdfs: [Microfacet; 2],
}

impl Blend {
    /// A blend of constant weight `weight` of `parts`.
    pub fn new(weight: f32, parts: [BlendPart; 2]) -> Self {
        Self {
            weight,
            weight_texture: None,
            parts,
        }
    }

    /// Checks the weight and both BSDFs; the message names what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..=1.0).contains(&self.weight) {
            return Err(format!(
                "blendbsdf weight must be in [0, 1], got {}",
                self.weight
            ));
        }
        for (i, p) in self.parts.iter().enumerate() {
            p.bsdf
                .validate()
                .map_err(|e| format!("blendbsdf's BSDF {i}: {e}"))?;
        }
        Ok(())
    }

    /// The blend with the texture values `weight` (its textured weight) and `tints` in place.
    fn at(&self, weight: Option<f32>, tints: &[PartTint; 2]) -> Blended {
        let part = |p: &BlendPart, t: &PartTint| {
            let m = p
                .bsdf
                .with_params(&t.params, &t.ior, p.alpha_tables.as_ref());
            let m = m.unwrap_or(p.bsdf);
            m.tinted(t.color).unwrap_or(m)
        };
        Blended {
            weight: weight.unwrap_or(self.weight).clamp(0.0, 1.0),
            bsdfs: [
                part(&self.parts[0], &tints[0]),
                part(&self.parts[1], &tints[1]),
            ],
        }
    }
}

impl Blended {
    /// The two BSDFs' weights, `[1 − w, w]`.
    #[inline]
    pub fn weights(&self) -> [f32; 2] {
        [1.0 - self.weight, self.weight]
    }

    /// The blend of `each` over the two BSDFs: `Σ wᵢ·each(bsdfᵢ)` for both values (an
    /// `(f, pdf)` pair); a BSDF of weight zero is not evaluated.
    pub fn mix(&self, each: impl Fn(&Microfacet) -> (Rgb, f32)) -> (Rgb, f32) {
        let (mut f, mut pdf) = (Rgb::ZERO, 0.0);
        for (m, w) in self.bsdfs.iter().zip(self.weights()) {
            if w > 0.0 {
                let (fm, pm) = each(m);
                f += fm * w;
                pdf += pm * w;
            }
        }
        (f, pdf)
    }

    /// True if some BSDF of positive weight has a non-delta lobe.
    pub fn has_non_delta(&self) -> bool {
        self.bsdfs
            .iter()
            .zip(self.weights())
            .any(|(m, w)| w > 0.0 && m.has_non_delta())
    }

    /// Reflectance at normal incidence, for the albedo AOV.
    pub fn albedo(&self) -> Rgb {
        self.mix(|m| (m.albedo(), 0.0)).0
    }

    /// Samples BSDF 1 when `u_lobe < w`, BSDF 0 otherwise (the number rescaled for it); the
    /// index of the BSDF sampled and the blend's sample (see the module docs).
    pub fn sample_part(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<(usize, LocalSample)> {
        let w = self.weight;
        let (i, share, u_lobe) = if u_lobe < w {
            (1, w, u_lobe / w)
        } else {
            (0, 1.0 - w, (u_lobe - w) / (1.0 - w))
        };
        let s = self.bsdfs[i].sample(wo, u_lobe.min(0.999_999_94), u)?;
        if s.delta {
            return Some((
                i,
                LocalSample {
                    pdf: s.pdf * share,
                    ..s
                },
            ));
        }
        Some((i, self.sample_toward(wo, s.wi)?))
    }
}

impl LocalBsdf for Blended {
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        self.mix(|m| m.eval_pdf(wo, wi))
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        self.sample_part(wo, u_lobe, u).map(|(_, s)| s)
    }
}
