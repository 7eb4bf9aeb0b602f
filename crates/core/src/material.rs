//! The layered material model of Dammertz (2011, §2.3.4) and its BSDF.
//!
//! A material is a weighted stack of layers. Each layer has a colour at normal incidence `C0`, a
//! colour at grazing incidence `C90` (interpolated with Schlick's weight `(1 - cos)^5`), a
//! hardness `κ ∈ [0, 1]` and optionally transmission with an index of refraction. One random
//! number picks the layer and, for a transmitting layer, reflection or refraction by the
//! dielectric Fresnel term.
//!
//! Lobes, by hardness:
//! - `κ = 0`: Lambertian.
//! - `0 < κ < 1`: normalised Blinn–Phong with exponent `k = 1024κ + 1`. The thesis' Eq. 2.1 divides
//!   by `⟨n,ωo⟩` only and normalises with `(k+2)/2`, which reflects more energy than it receives
//!   at grazing angles. We use the reciprocal Ashikhmin–Shirley form
//!   `f = (k+1)/(8π) · cos^k θh / (⟨h,ωo⟩ · max(cos θi, cos θo))`, whose sampling weight is
//!   `cos θi / max(cos θi, cos θo) ≤ 1`: energy conserving at every angle, and converging to the
//!   mirror as κ → 1.
//! - `κ = 1`: a perfect mirror (or, with transmission, smooth glass): a delta lobe.
//! - Transmission with `κ < 1` is rough glass: a microfacet normal is drawn from the Blinn–Phong
//!   distribution, and the exact dielectric Fresnel term at that microfacet chooses reflection or
//!   refraction (Snell's law). Its BSDF is defined by that sampling procedure
//!   (`f·|cos θi| = C · pdf`), which makes every sample's weight exactly the layer colour: no
//!   energy is created, and only directions that the microfacet sends to the wrong side are lost.
//!
//! Layer weights: the layers form a mixture `f = Σ ωᵢ fᵢ` with `Σ ωᵢ ≤ 1`; what is missing to 1
//! is absorbed. A layer marked `coat` (a clear coat, as in the `plastic` preset) takes the
//! Schlick-Fresnel share `F(θo)` of its weight for its ior and passes `1 - F(θo)` of the energy
//! to the layers below it. Like the thesis' Fresnel colour interpolation this is not reciprocal;
//! a path tracer does not need reciprocity.
//!
//! Radiance crossing into a medium of relative index η is scaled by `1/η²` (radiance, not
//! importance, is transported by the camera paths here).
//!
//! Dispersion (thesis §6.6, [`crate::spectral`]): a smooth transmitting layer may have a
//! wavelength-dependent index. When [`Bsdf::sample`] chooses such a layer on a path without a
//! wavelength, it draws λ from the lobe's 2-D number (which a delta lobe does not otherwise use),
//! multiplies the sample weight by the RGB weight of λ and reports λ in
//! [`BsdfSample::wavelength`]; the caller passes it to every later vertex through
//! [`Bsdf::with_wavelength`], where the same λ picks the index and no new weight is applied.
//! Both the Fresnel choice and the refraction use `n(λ)`, so reflection off dispersive glass is a
//! dispersive event too. Dispersion is limited to delta layers: their `eval` is zero, so light
//! connections never need a wavelength the path does not have yet.

use crate::bump::NormalPerturbation;
use crate::microfacet::{
    AlphaTables, Blend, BlendAt, IorValues, LocalSample, Microfacet, ParamTextures, ParamValues,
};
use crate::tint::{TexturesAt, Tint};
use crate::{
    frame::Frame,
    sampling::{blinn_phong_half, blinn_phong_half_pdf, cosine_hemisphere},
    spectral::{sample_wavelength, Dispersion},
    Rgb,
};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Most layers a material may have: the BSDF keeps per-layer weights in a fixed array so that
/// shading never allocates.
pub const MAX_LAYERS: usize = 8;

/// Hardness below which a layer counts as diffuse for path-space partitioning (thesis §2.3.4;
/// the Fig. 6.23 caption's "2" is a misprint).
pub const DIFFUSE_HARDNESS_THRESHOLD: f32 = 0.2;

/// One layer of a material.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Mixture weight in [0, 1].
    pub weight: f32,
    /// Colour at normal incidence, C0.
    pub color: Rgb,
    /// Colour at grazing incidence, C90.
    pub color90: Rgb,
    /// Hardness κ in [0, 1]: 0 Lambertian, 1 perfect mirror or smooth glass.
    pub hardness: f32,
    /// Refracts through the surface instead of only reflecting.
    pub transmission: bool,
    /// Index of refraction inside the surface (the side opposite the front face), for
    /// transmission and for coats.
    pub ior: f32,
    /// A Fresnel-weighted clear coat over the layers after it.
    pub coat: bool,
    /// Wavelength-dependent index for a smooth transmitting layer; `ior` then holds `n_d` (the
    /// index at 587.56 nm), used where no wavelength is known.
    pub dispersion: Option<Dispersion>,
}

impl Layer {
    /// A layer with colour `c` at all angles.
    pub fn new(weight: f32, c: Rgb, hardness: f32) -> Self {
        Self {
            weight,
            color: c,
            color90: c,
            hardness,
            transmission: false,
            ior: 1.5,
            coat: false,
            dispersion: None,
        }
    }

    /// True for the delta lobes (mirror, smooth glass).
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.hardness >= 1.0
    }

    /// True if this layer counts as diffuse (κ < 0.2).
    #[inline]
    pub fn is_diffuse(&self) -> bool {
        self.hardness < DIFFUSE_HARDNESS_THRESHOLD
    }

    #[inline]
    fn exponent(&self) -> f32 {
        1024.0 * self.hardness + 1.0
    }

    #[inline]
    fn color_at(&self, cos: f32, tint: Rgb) -> Rgb {
        let w = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
        let c = self.color + (self.color90 - self.color) * w;
        if self.coat {
            c
        } else {
            c * tint
        }
    }
}

/// Largest emitted or environment radiance a scene may have. A path's sample is at most about
/// the radiance it finds times a throughput of order one, and the film sums squared deviations
/// of up to 2²⁰ samples per pixel (the CLI's limit) in f32: 2²⁰ · (10¹⁵)² ≈ 10³⁶ stays below
/// f32's 3.4·10³⁸, so the variance never overflows. The sun is about 10⁹ in photometric units.
pub const MAX_RADIANCE: f32 = 1e15;

/// A material: a layer stack plus emission.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name from the scene.
    pub name: String,
    /// Layers, top first.
    pub layers: Vec<Layer>,
    /// Emitted radiance (zero for non-emitters).
    pub emission: Rgb,
    /// Emit from both faces instead of the front (counter-clockwise) face only.
    pub two_sided: bool,
    /// Texture (index into `Scene::textures`) that modulates every non-coat layer's colours.
    pub texture: Option<u32>,
    /// A BSDF of Mitsuba's microfacet family in place of the layer stack (`layers` is then
    /// empty): [`crate::microfacet`].
    pub microfacet: Option<Microfacet>,
    /// A bump or normal map bending the shading normal ([`crate::bump`]), applied where the
    /// scene builds a hit ([`crate::scene::Scene::surface`]).
    pub perturbation: Option<NormalPerturbation>,
    /// Textures on the microfacet BSDF's parameters ([`crate::microfacet::ParamTextures`]).
    pub param_textures: ParamTextures,
    /// A rough plastic's coating tables over the range of its textured `alpha`.
    pub alpha_tables: Option<AlphaTables>,
    /// Mitsuba's `blendbsdf` in place of the layer stack and of `microfacet` (both then
    /// empty): [`crate::microfacet::Blend`].
    pub blend: Option<Box<Blend>>,
    /// Mitsuba's `mask`: the probability in [0, 1] that light meets the surface (`None`:
    /// opaque); otherwise it passes straight through ([`Bsdf`]). Its texture is
    /// `param_textures.opacity`.
    pub opacity: Option<f32>,
}

/// A material parameter outside its valid range.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum MaterialError {
    /// More layers than [`MAX_LAYERS`].
    #[error("has {0} layers; at most {MAX_LAYERS} are supported")]
    TooManyLayers(usize),
    /// A value outside its range.
    #[error("layer {layer}: {what}")]
    Layer {
        /// Index of the layer.
        layer: usize,
        /// What is wrong.
        what: String,
    },
    /// Non-coat weights sum to more than one.
    #[error(
        "layer weights (excluding coats) sum to {0}, more than 1: the material would create energy"
    )]
    WeightSum(f32),
    /// Bad emission.
    #[error("emission must be finite, non-negative and at most {MAX_RADIANCE:e}, got {0:?}")]
    Emission([f32; 3]),
    /// A microfacet BSDF's parameter out of range.
    #[error("{0}")]
    Microfacet(String),
    /// A mask's opacity outside [0, 1].
    #[error("opacity must be in [0, 1], got {0}")]
    Opacity(f32),
}

fn check_color(c: Rgb, what: &str, layer: usize) -> Result<(), MaterialError> {
    if !c.is_finite() || c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(MaterialError::Layer {
            layer,
            what: format!(
                "{what} must be in [0, 1] (a reflectance), got {:?}",
                c.to_array()
            ),
        });
    }
    Ok(())
}

impl Material {
    fn with_layers(name: &str, layers: Vec<Layer>) -> Self {
        Self {
            name: name.to_string(),
            layers,
            emission: Rgb::ZERO,
            two_sided: false,
            texture: None,
            microfacet: None,
            perturbation: None,
            param_textures: ParamTextures::default(),
            alpha_tables: None,
            blend: None,
            opacity: None,
        }
    }

    /// A material of the microfacet family ([`crate::microfacet`]).
    pub fn microfacet(name: &str, bsdf: Microfacet) -> Self {
        let mut m = Self::with_layers(name, Vec::new());
        m.microfacet = Some(bsdf);
        m
    }

    /// Mitsuba's `blendbsdf` of two BSDFs of the microfacet family
    /// ([`crate::microfacet::Blend`]).
    pub fn blend(name: &str, blend: Blend) -> Self {
        let mut m = Self::with_layers(name, Vec::new());
        m.blend = Some(Box::new(blend));
        m
    }

    /// Lambertian reflector.
    pub fn diffuse(name: &str, color: Rgb) -> Self {
        Self::with_layers(name, vec![Layer::new(1.0, color, 0.0)])
    }

    /// Perfect mirror.
    pub fn mirror(name: &str, color: Rgb) -> Self {
        Self::with_layers(name, vec![Layer::new(1.0, color, 1.0)])
    }

    /// Glass: smooth for `hardness = 1`, frosted below.
    pub fn glass(name: &str, color: Rgb, ior: f32, hardness: f32) -> Self {
        let mut l = Layer::new(1.0, color, hardness);
        l.transmission = true;
        l.ior = ior;
        Self::with_layers(name, vec![l])
    }

    /// A single glossy Blinn–Phong layer.
    pub fn glossy(name: &str, color: Rgb, hardness: f32) -> Self {
        Self::with_layers(name, vec![Layer::new(1.0, color, hardness)])
    }

    /// Metal: glossy layer whose colour goes to white at grazing angles (Schlick's approximation
    /// of conductor Fresnel with `C0 = color`).
    pub fn metal(name: &str, color: Rgb, hardness: f32) -> Self {
        let mut l = Layer::new(1.0, color, hardness);
        l.color90 = Rgb::ONE;
        Self::with_layers(name, vec![l])
    }

    /// Plastic: a white Fresnel clear coat of the given hardness and ior over a Lambertian base.
    pub fn plastic(name: &str, color: Rgb, hardness: f32, ior: f32) -> Self {
        let mut coat = Layer::new(1.0, Rgb::ONE, hardness);
        coat.coat = true;
        coat.ior = ior;
        Self::with_layers(name, vec![coat, Layer::new(1.0, color, 0.0)])
    }

    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), MaterialError> {
        if self.layers.len() > MAX_LAYERS {
            return Err(MaterialError::TooManyLayers(self.layers.len()));
        }
        let e = self.emission;
        if !e.is_finite() || e.min_element() < 0.0 || e.max_element() > MAX_RADIANCE {
            return Err(MaterialError::Emission(e.to_array()));
        }
        if let Some(m) = &self.microfacet {
            m.validate().map_err(MaterialError::Microfacet)?;
        }
        if let Some(b) = &self.blend {
            b.validate().map_err(MaterialError::Microfacet)?;
        }
        if let Some(o) = self.opacity {
            if !(0.0..=1.0).contains(&o) {
                return Err(MaterialError::Opacity(o));
            }
        }
        let mut sum = 0.0;
        for (i, l) in self.layers.iter().enumerate() {
            let bad = |what: String| Err(MaterialError::Layer { layer: i, what });
            if !(0.0..=1.0).contains(&l.weight) {
                return bad(format!("weight must be in [0, 1], got {}", l.weight));
            }
            if !(0.0..=1.0).contains(&l.hardness) {
                return bad(format!("hardness must be in [0, 1], got {}", l.hardness));
            }
            if !(l.ior.is_finite() && l.ior > 0.0) {
                return bad(format!("ior must be a positive number, got {}", l.ior));
            }
            if l.coat && l.transmission {
                return bad("a layer cannot be both a coat and transmissive".into());
            }
            if let Some(d) = &l.dispersion {
                if !(l.transmission && l.is_delta()) {
                    return bad(
                        "dispersion applies to smooth transmitting layers only (transmission \
                         with hardness 1)"
                            .into(),
                    );
                }
                if let Err(e) = d.validate() {
                    return bad(format!("dispersion: {e}"));
                }
            }
            check_color(l.color, "color", i)?;
            check_color(l.color90, "color90", i)?;
            if !l.coat {
                sum += l.weight;
            }
        }
        if sum > 1.0 + 1e-4 {
            return Err(MaterialError::WeightSum(sum));
        }
        Ok(())
    }

    /// True if the material emits.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Radiance emitted towards `wo` from a surface with front-facing geometric normal `ng`.
    #[inline]
    pub fn emitted(&self, ng: Vec3, wo: Vec3) -> Rgb {
        if self.two_sided || ng.dot(wo) > 0.0 {
            self.emission
        } else {
            Rgb::ZERO
        }
    }

    /// `colour · tint · weight / π` for a material that is one plain Lambertian layer (one
    /// colour at all angles, no coat, no transmission) of positive weight: its BSDF value at
    /// every pair of directions on one side, the same bits [`Bsdf`] uses. `None` for any other
    /// material. Shading kernels that handle only this case ask here.
    #[inline]
    pub fn plain_lambert(&self, tint: Rgb) -> Option<Rgb> {
        if self.opacity.is_some() || self.param_textures.opacity.is_some() {
            return None;
        }
        match self.layers.as_slice() {
            [l] if is_plain_lambert(l) && l.weight > 0.0 => {
                Some(l.color * tint * FRAC_1_PI * l.weight)
            }
            _ => None,
        }
    }

    /// Number of faces that emit (for light power).
    pub fn emitting_faces(&self) -> f32 {
        if self.two_sided {
            2.0
        } else {
            1.0
        }
    }
}

/// The two kinds of layer the path-space partition tells apart (Dammertz 2011, §2.3.4 and
/// §6.3): diffuse (`κ <` [`DIFFUSE_HARDNESS_THRESHOLD`]) and specular (everything else:
/// glossy, mirrors, glass).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerClass {
    /// Hardness below the threshold.
    Diffuse,
    /// Hardness at or above the threshold.
    Specular,
}

impl LayerClass {
    /// True if layer `l` is of this class.
    #[inline]
    pub fn contains(self, l: &Layer) -> bool {
        l.is_diffuse() == (self == LayerClass::Diffuse)
    }
}

/// Result of sampling a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Sampled incident direction (world space, unit).
    pub wi: Vec3,
    /// `f · |cos θi| / pdf`: what the path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle pdf of `wi` for non-delta samples (for MIS); for delta samples, the
    /// discrete probability of the chosen lobe.
    pub pdf: f32,
    /// The sample came from a delta lobe (mirror, smooth glass).
    pub delta: bool,
    /// The direction crossed the surface.
    pub transmitted: bool,
    /// The path's wavelength in nm after this sample: the BSDF's own
    /// ([`Bsdf::with_wavelength`]), or the one drawn here at a dispersive event of a path that
    /// had none (its RGB weight is then in `weight`). `None` for an RGB path. Pass it to the
    /// next vertex's BSDF.
    pub wavelength: Option<f32>,
}

/// A material evaluated at one surface point for one outgoing direction.
///
/// Built per path vertex; holds the per-layer weights for `wo` in a fixed array, so building
/// and using it never allocates.
#[derive(Clone)]
pub struct Bsdf<'a> {
    /// The material: its layers, or the microfacet BSDF or blend that replaces them (the
    /// texture's tint applies to a microfacet BSDF through [`Microfacet::eval_pdf_tinted`] and
    /// [`Microfacet::sample_tinted`], the textured parameters `params` through
    /// [`Bsdf::with_micro`]).
    material: &'a Material,
    tint: Rgb,
    frame: Frame,
    ng: Vec3,
    wo: Vec3,
    wo_local: Vec3,
    weights: [f32; MAX_LAYERS],
    total: f32,
    has_non_delta: bool,
    /// `Some(colour · tint · weight / π)` for a material that is one Lambertian layer of one
    /// colour at all angles (most surfaces of most scenes): its value and pdf, here and inside
    /// [`Bsdf::sample`], need no layer loop. The arithmetic is the general path's, operation
    /// for operation, so both give the same bits.
    lambert: Option<Rgb>,
    /// Where a blend's textures and a textured index of refraction are read ([`Tint::at`]).
    /// They are read each time the BSDF is evaluated ([`BlendAt::blended`],
    /// [`ParamTextures::ior_at`]): their values, or the blended BSDFs (650 bytes), held here
    /// would make every `Bsdf` that much larger to build and copy.
    at: Option<TexturesAt<'a>>,
    /// The textured parameters' values at this point (all `None` for most materials).
    params: ParamValues,
    /// The path's wavelength, nm (`None`: an RGB path).
    wavelength: Option<f32>,
    /// Mitsuba's `mask` (Mitsuba 3, `mask.cpp`): the probability that light meets the surface
    /// (1 without a mask). The rest passes straight through: a delta transmission lobe along
    /// `−wo` of weight one, sampled with probability `1 − opacity`; the other lobes' values
    /// and pdfs are scaled by `opacity`.
    opacity: f32,
    /// The pass-through lobe is part of this BSDF (false for its diffuse part,
    /// [`Bsdf::restricted`]: the pass-through is specular).
    pass_through: bool,
    /// Dispersive layers use their wavelength-dependent index (false: `ior` = `n_d`, as an RGB
    /// renderer would; for tests that compare against the renderer without spectral code).
    spectral: bool,
    /// The BSDF of importance transport ([`Bsdf::adjoint`]).
    adjoint: bool,
}

impl<'a> Bsdf<'a> {
    /// Builds the BSDF of `material` with texture values `tint` (a colour alone, or what
    /// [`crate::Scene::tint`] reads) at a point with unit shading normal `ns` and unit geometric
    /// normal `ng` (both on the front side), for outgoing direction `wo` (unit, pointing away
    /// from the surface).
    pub fn new(
        material: &'a Material,
        tint: impl Into<Tint<'a>>,
        ns: Vec3,
        ng: Vec3,
        wo: Vec3,
    ) -> Self {
        let Tint {
            color: tint,
            params,
            at,
        } = tint.into();
        let frame = Frame::from_normal(ns);
        let wo_local = frame.to_local(wo);
        let mut weights = [0.0f32; MAX_LAYERS];
        let mut passed = 1.0f32;
        let cos_o = wo_local.z.abs();
        let mut has_non_delta = false;
        for (w, l) in weights.iter_mut().zip(&material.layers) {
            if l.coat {
                let f0 = ((l.ior - 1.0) / (l.ior + 1.0)).powi(2);
                let f = f0 + (1.0 - f0) * (1.0 - cos_o).powi(5);
                *w = passed * l.weight * f;
                passed *= 1.0 - f;
            } else {
                *w = passed * l.weight;
            }
            has_non_delta |= *w > 0.0 && !l.is_delta();
        }
        let total = match (&material.microfacet, &material.blend) {
            // One "layer" of weight one: the checks of `total` below hold as for layers.
            (Some(m), _) => {
                has_non_delta = m.has_non_delta();
                1.0
            }
            (None, Some(blend)) => {
                has_non_delta = BlendAt { blend, at }.has_non_delta();
                1.0
            }
            (None, None) => weights.iter().sum(),
        };
        // `color_at` of a plain Lambertian layer is `color · tint` at every angle, and its
        // one weight is `1 · weight`.
        let lambert = material.plain_lambert(tint);
        let opacity = params
            .opacity
            .or(material.opacity)
            .map_or(1.0, |o| o.clamp(0.0, 1.0));
        Self {
            material,
            tint,
            frame,
            ng,
            wo,
            wo_local,
            weights,
            total,
            lambert,
            at,
            params,
            wavelength: None,
            opacity,
            pass_through: true,
            has_non_delta: has_non_delta && opacity > 0.0,
            spectral: true,
            adjoint: false,
        }
    }

    /// The adjoint BSDF, for paths that carry importance from the lights (light tracing, BDPT's
    /// light subpaths), where `wo` points to the light side: `f*(wo, wi) = f(wi, wo)`. It
    /// differs from `f` only where refraction scales radiance by `1/η²` (Veach 1997, §5.2:
    /// `f(wo→wi)/η_o² = f(wi→wo)/η_i²`), so a transmitted value here is `f · η(wo)²`, `η(wo)`
    /// the index beyond the surface relative to `wo`'s side; pdfs are unchanged. With
    /// radiance's BSDF on light paths, light through one interface (an open sheet of rough
    /// glass) came out `η²` off: `bad/flipped-normals` was 0.5 % darker under BDPT than under
    /// the path tracer (z 4 to 6).
    #[inline]
    pub fn adjoint(mut self) -> Self {
        self.adjoint = true;
        self
    }

    /// The BSDF for a path that already carries wavelength `lambda` nm (from an earlier
    /// dispersive event, [`BsdfSample::wavelength`]); `None` leaves the path RGB.
    #[inline]
    pub fn with_wavelength(mut self, lambda: Option<f32>) -> Self {
        self.wavelength = lambda;
        self
    }

    /// The wavelength the path carries (see [`Bsdf::with_wavelength`]).
    #[inline]
    pub fn wavelength(&self) -> Option<f32> {
        self.wavelength
    }

    /// Treats dispersive layers as plain glass of index `n_d`: the renderer as if it had no
    /// spectral code. For tests.
    #[doc(hidden)]
    pub fn without_dispersion(mut self) -> Self {
        self.spectral = false;
        self
    }

    /// True if some non-delta lobe has weight, i.e. light sampling can contribute.
    #[inline]
    pub fn has_non_delta(&self) -> bool {
        self.has_non_delta
    }

    /// The probability with which [`Bsdf::sample`] picks a layer of `class`: the class's share
    /// of the layer weights (0 for a BSDF that reflects nothing).
    pub fn share(&self, class: LayerClass) -> f32 {
        let inner = self.share_opaque(class);
        if !self.pass_through || self.opacity >= 1.0 {
            return inner;
        }
        match class {
            LayerClass::Diffuse => self.opacity * inner,
            LayerClass::Specular => 1.0 - self.opacity * (1.0 - inner),
        }
    }

    /// [`Bsdf::share`] among the lobes a mask lets light meet.
    fn share_opaque(&self, class: LayerClass) -> f32 {
        if self.total <= 0.0 {
            return 0.0;
        }
        if self.replaces_layers() {
            // The microfacet family counts as glossy or specular throughout (its diffuse, in
            // a blend, too: it is then path traced, which is unbiased).
            return (class == LayerClass::Specular) as u8 as f32;
        }
        let kept: f32 = self
            .material
            .layers
            .iter()
            .zip(&self.weights)
            .filter(|(l, _)| class.contains(l))
            .map(|(_, &w)| w)
            .sum();
        (kept / self.total).min(1.0)
    }

    /// The part of this BSDF made of the layers of `class`, with their weights unchanged:
    /// `f = Σ_class wᵢ fᵢ`, and sampling chooses among those layers only. The two classes'
    /// parts sum to the whole, which is how the path-space partition (Dammertz 2011, §6.3)
    /// splits a vertex into its diffuse and its specular part.
    pub fn restricted(&self, class: LayerClass) -> Self {
        let mut b = self.restricted_layers(class);
        b.pass_through &= class == LayerClass::Specular;
        b
    }

    /// [`Bsdf::restricted`] of the layers (or the microfacet BSDF).
    fn restricted_layers(&self, class: LayerClass) -> Self {
        let mut b = self.clone();
        if b.replaces_layers() {
            if class != LayerClass::Specular {
                // Nothing: `total` 0 is a BSDF that reflects nothing.
                b.total = 0.0;
                b.has_non_delta = false;
            }
            return b;
        }
        let mut has_non_delta = false;
        for (w, l) in b.weights.iter_mut().zip(&b.material.layers) {
            if !class.contains(l) {
                *w = 0.0;
            }
            has_non_delta |= *w > 0.0 && !l.is_delta();
        }
        b.total = b.weights.iter().sum();
        b.has_non_delta = has_non_delta;
        if b.total <= 0.0 {
            b.lambert = None;
        }
        b
    }

    /// Reflectance at normal incidence summed over layers: the albedo AOV.
    pub fn albedo(&self) -> Rgb {
        self.albedo_opaque() * self.opacity
    }

    fn albedo_opaque(&self) -> Rgb {
        if self.total <= 0.0 {
            return Rgb::ZERO;
        }
        if let Some(a) = self.with_micro(|m| m.albedo_tinted(self.tint)) {
            return a;
        }
        if let Some(b) = self.blend() {
            return b.blended().albedo();
        }
        self.material
            .layers
            .iter()
            .zip(&self.weights)
            .map(|(l, &w)| l.color_at(1.0, self.tint) * w)
            .sum()
    }

    /// True if `wi` is geometrically consistent with `wo` for reflection (same side of both the
    /// geometric and the shading surface) or transmission (opposite sides). Checking both normals
    /// stops interpolated normals from leaking light through the surface.
    #[inline]
    fn sides(&self, wi: Vec3, wi_local: Vec3) -> Option<bool> {
        let geo_same = (wi.dot(self.ng) > 0.0) == (self.wo.dot(self.ng) > 0.0);
        let sh_same = (wi_local.z > 0.0) == (self.wo_local.z > 0.0);
        if wi_local.z == 0.0 || geo_same != sh_same {
            return None;
        }
        Some(geo_same)
    }

    /// BSDF value `f(wo, wi)` summed over the non-delta layers (world-space unit `wi`).
    pub fn eval(&self, wi: Vec3) -> Rgb {
        self.eval_pdf(wi).0
    }

    /// Solid-angle pdf with which [`Bsdf::sample`] produces `wi` (non-delta lobes only).
    pub fn pdf(&self, wi: Vec3) -> f32 {
        self.eval_pdf(wi).1
    }

    /// `(f, pdf)` in one pass.
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3) -> (Rgb, f32) {
        let (f, pdf) = self.eval_pdf_opaque(wi);
        if self.opacity >= 1.0 {
            return (f, pdf);
        }
        (f * self.opacity, pdf * self.selection())
    }

    /// The probability that [`Bsdf::sample`] samples the lobes other than a mask's
    /// pass-through.
    #[inline]
    fn selection(&self) -> f32 {
        if self.pass_through {
            self.opacity
        } else {
            1.0
        }
    }

    /// [`Bsdf::eval_pdf`] of the lobes a mask lets light meet.
    fn eval_pdf_opaque(&self, wi: Vec3) -> (Rgb, f32) {
        if self.total <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let wi_local = self.frame.to_local(wi);
        let Some(reflect) = self.sides(wi, wi_local) else {
            return (Rgb::ZERO, 0.0);
        };
        if let Some(f) = self.lambert {
            return lambert_eval_pdf(f, wi_local, reflect);
        }
        if let Some(r) = self.with_micro(|m| self.micro_eval_pdf(m, self.tint, wi_local, reflect)) {
            return r;
        }
        if let Some(b) = self.blend() {
            return self.eval_pdf_blend(b, wi_local, reflect);
        }
        let mut f = Rgb::ZERO;
        let mut pdf = 0.0;
        for (l, &w) in self.material.layers.iter().zip(&self.weights) {
            if w <= 0.0 || l.is_delta() {
                continue;
            }
            let (fl, pl) = eval_layer(l, self.tint, self.wo_local, wi_local, reflect);
            let fl = if self.adjoint && !reflect && l.transmission {
                fl * relative_eta(l, self.wo_local).powi(2)
            } else {
                fl
            };
            f += fl * w;
            pdf += pl * (w / self.total);
        }
        (f, pdf)
    }

    /// Samples an incident direction. `u_layer` picks the layer and (reused after rescaling) the
    /// reflection/refraction branch; `u` samples the lobe.
    pub fn sample(&self, u_layer: f32, u: Vec2) -> Option<BsdfSample> {
        if self.opacity >= 1.0 {
            return self.sample_opaque(u_layer, u);
        }
        let mut u_layer = u_layer;
        if self.pass_through {
            if u_layer >= self.opacity {
                // Through the mask: the light continues as if the surface were not there.
                return Some(BsdfSample {
                    wi: -self.wo,
                    weight: Rgb::ONE,
                    pdf: 1.0 - self.opacity,
                    delta: true,
                    transmitted: true,
                    wavelength: self.wavelength,
                });
            }
            u_layer = (u_layer / self.opacity).min(0.999_999_94);
        }
        let sel = self.selection();
        let mut s = self.sample_opaque(u_layer, u)?;
        s.pdf *= sel;
        s.weight *= self.opacity / sel;
        Some(s)
    }

    /// [`Bsdf::sample`] of the lobes a mask lets light meet.
    fn sample_opaque(&self, u_layer: f32, u: Vec2) -> Option<BsdfSample> {
        if self.total <= 0.0 {
            return None;
        }
        if let Some(s) = self.with_micro(|m| self.sample_microfacet(m, u_layer, u)) {
            return s;
        }
        if let Some(b) = self.blend() {
            return self.sample_blend(b, u_layer, u);
        }
        // Pick a layer in proportion to its weight; rounding past the end lands on the last
        // layer with weight.
        let mut target = u_layer * self.total;
        let mut chosen = None;
        let layers = &self.material.layers;
        for (i, &w) in self.weights.iter().enumerate().take(layers.len()) {
            if w <= 0.0 {
                continue;
            }
            chosen = Some((i, (target / w).clamp(0.0, 0.999_999_94)));
            if target < w {
                break;
            }
            target -= w;
        }
        let (i, u_rest) = chosen?;
        let l = &layers[i];
        let wo = self.wo_local;
        let mut wavelength = self.wavelength;
        let mut spectral_share = Rgb::ONE;
        let (wi_local, delta_weight) = if let (Some(d), true) = (&l.dispersion, self.spectral) {
            // A dispersive event. A delta lobe leaves `u` unused, so a new wavelength comes
            // from `u.x`: no sampler dimension is added, and non-dispersive paths are untouched.
            let (lambda, spectral_weight) = match self.wavelength {
                Some(lambda) => (lambda, Rgb::ONE),
                None => {
                    let s = sample_wavelength(u.x);
                    (s.lambda, s.weight)
                }
            };
            wavelength = Some(lambda);
            spectral_share = spectral_weight;
            let (wi, scale) = sample_delta_eta(l, d.ior(lambda), wo, u_rest)?;
            (
                wi,
                Some(l.color_at(wo.z.abs(), self.tint) * spectral_weight * (self.total * scale)),
            )
        } else if l.is_delta() {
            let (wi, scale) = sample_delta(l, wo, u_rest)?;
            (
                wi,
                Some(l.color_at(wo.z.abs(), self.tint) * (self.total * scale)),
            )
        } else {
            (sample_lobe(l, wo, u_rest, u)?, None)
        };
        let wi = self.frame.to_world(wi_local).normalize();
        let reflect = self.sides(wi, wi_local)?;
        if let Some(weight) = delta_weight {
            // Refraction's `1/η²` is radiance's; importance crosses without it.
            let weight = if self.adjoint && !reflect && l.transmission {
                l.color_at(wo.z.abs(), self.tint) * spectral_share * self.total
            } else {
                weight
            };
            return Some(BsdfSample {
                wi,
                weight,
                pdf: self.weights[i] / self.total,
                delta: true,
                transmitted: !reflect,
                wavelength,
            });
        }
        let (f, pdf) = self.eval_pdf_opaque(wi);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: f * (wi_local.z.abs() / pdf),
            pdf,
            delta: false,
            transmitted: !reflect,
            wavelength,
        })
    }
}

impl<'a> Bsdf<'a> {
    /// True for a microfacet BSDF or a blend, which replace the layers.
    #[inline]
    fn replaces_layers(&self) -> bool {
        self.material.microfacet.is_some() || self.material.blend.is_some()
    }

    /// The material's blend at this point, if it is one.
    #[inline]
    fn blend(&self) -> Option<BlendAt<'a>> {
        let blend = self.material.blend.as_deref()?;
        Some(BlendAt { blend, at: self.at })
    }

    /// `f` of the microfacet BSDF with the textured parameters in place (a copy of it only for
    /// a material with textured parameters); `None` for a layered material.
    #[inline]
    fn with_micro<R>(&self, f: impl FnOnce(&Microfacet) -> R) -> Option<R> {
        let m = self.material.microfacet.as_ref()?;
        let tables = self.material.alpha_tables.as_ref();
        // A textured index of refraction is read here, not carried (`crate::tint`).
        let ior = match &self.at {
            Some(at) if self.material.param_textures.has_ior() => {
                self.material.param_textures.ior_at(at)
            }
            _ => IorValues::NONE,
        };
        Some(match m.with_params(&self.params, &ior, tables) {
            Some(textured) => f(&textured),
            None => f(m),
        })
    }

    /// [`Bsdf::sample`] for a microfacet material: the local sample in world space, kept only
    /// where it is consistent with the geometric normal too.
    fn sample_microfacet(&self, m: &Microfacet, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let s = m.sample_tinted(self.tint, self.wo_local, u_lobe, u)?;
        self.world_sample(s, m)
    }

    /// `(f, pdf)` of microfacet BSDF `m` under a texture's `tint`, `f` the adjoint's in
    /// importance transport.
    #[inline]
    fn micro_eval_pdf(
        &self,
        m: &Microfacet,
        tint: Rgb,
        wi_local: Vec3,
        reflect: bool,
    ) -> (Rgb, f32) {
        let (f, pdf) = m.eval_pdf_tinted(tint, self.wo_local, wi_local);
        if self.adjoint && !reflect {
            (f * m.adjoint_scale(self.wo_local), pdf)
        } else {
            (f, pdf)
        }
    }

    /// [`Bsdf::eval_pdf`] of a blend (out of line, as [`Bsdf::sample_blend`]).
    #[inline(never)]
    fn eval_pdf_blend(&self, b: BlendAt, wi_local: Vec3, reflect: bool) -> (Rgb, f32) {
        let b = b.blended();
        b.mix(|m| self.micro_eval_pdf(m, Rgb::ONE, wi_local, reflect))
    }

    /// [`Bsdf::sample`] for a blend: its local sample in world space. Importance transported
    /// through a non-delta refraction gets the value of the blend's adjoint, whose two BSDFs
    /// may scale it differently. Out of line: inlined, its blended BSDFs made the layers'
    /// [`Bsdf::sample`] too large to inline its own lobe sampling.
    #[inline(never)]
    fn sample_blend(&self, b: BlendAt, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let b = b.blended();
        let (i, s) = b.sample_part(self.wo_local, u_lobe, u)?;
        let mut out = self.world_sample(s, &b.bsdfs[i])?;
        if self.adjoint && out.transmitted && !out.delta {
            let (f, _) = self.eval_pdf_opaque(out.wi);
            out.weight = f * (s.wi.z.abs() / s.pdf);
        }
        Some(out)
    }

    /// Local sample `s` of microfacet BSDF `m` in world space, kept only where it is
    /// consistent with the geometric normal too.
    fn world_sample(&self, s: LocalSample, m: &Microfacet) -> Option<BsdfSample> {
        let wi = self.frame.to_world(s.wi).normalize();
        let reflect = self.sides(wi, s.wi)?;
        let weight = if self.adjoint && !reflect {
            s.weight * m.adjoint_scale(self.wo_local)
        } else {
            s.weight
        };
        Some(BsdfSample {
            wi,
            weight,
            pdf: s.pdf,
            delta: s.delta,
            transmitted: !reflect,
            wavelength: self.wavelength,
        })
    }
}

/// A single layer that is Lambertian with one colour at every angle: `color_at` is then
/// `color · tint` whatever the cosine.
#[inline]
fn is_plain_lambert(l: &Layer) -> bool {
    l.hardness <= 0.0 && !l.transmission && !l.coat && l.color == l.color90
}

/// `(f, pdf)` of a plain Lambertian layer whose `f` is already known, as [`eval_layer`] and the
/// layer sum in [`Bsdf::eval_pdf`] compute them (the pdf's layer share `w / total` is exactly 1).
#[inline]
fn lambert_eval_pdf(f: Rgb, wi_local: Vec3, reflect: bool) -> (Rgb, f32) {
    if !reflect {
        return (Rgb::ZERO, 0.0);
    }
    (f, wi_local.z.abs() * FRAC_1_PI)
}

/// Dielectric Fresnel reflectance for cosine `cos_i ≥ 0` on the incident side and relative index
/// `eta = η_transmitted / η_incident`.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_par * r_par + r_perp * r_perp)
}

/// Refracts `wo` (pointing away from the surface, on the side of unit normal `n`, `wo·n > 0`)
/// with relative index `eta`; `None` on total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-wo / eta + n * (cos_i / eta - cos_t))
}

/// Relative index `η_transmitted / η_incident` for light leaving towards `wo_local`.
#[inline]
fn relative_eta(l: &Layer, wo_local: Vec3) -> f32 {
    if wo_local.z > 0.0 {
        l.ior
    } else {
        1.0 / l.ior
    }
}

/// Samples a delta lobe; returns the local direction and the weight factor besides the colour
/// (Fresnel branch probabilities cancel; refraction carries `1/η²`).
fn sample_delta(l: &Layer, wo: Vec3, u: f32) -> Option<(Vec3, f32)> {
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    if !l.transmission {
        return Some((mirror, 1.0));
    }
    let eta = relative_eta(l, wo);
    delta_dielectric(wo, eta, u)
}

/// [`sample_delta`] of a transmitting layer whose index is `ior` (a dispersive layer's `n(λ)`).
fn sample_delta_eta(l: &Layer, ior: f32, wo: Vec3, u: f32) -> Option<(Vec3, f32)> {
    debug_assert!(l.transmission);
    let eta = if wo.z > 0.0 { ior } else { 1.0 / ior };
    delta_dielectric(wo, eta, u)
}

/// Smooth dielectric interface of relative index `eta`: Fresnel chooses with `u`.
#[inline]
fn delta_dielectric(wo: Vec3, eta: f32, u: f32) -> Option<(Vec3, f32)> {
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let f = fresnel_dielectric(wo.z.abs(), eta);
    if u < f {
        return Some((mirror, 1.0));
    }
    let n = Vec3::new(0.0, 0.0, wo.z.signum());
    let wi = refract(wo, n, eta)?;
    Some((wi.normalize(), 1.0 / (eta * eta)))
}

/// Samples a non-delta lobe (local space).
fn sample_lobe(l: &Layer, wo: Vec3, u_branch: f32, u: Vec2) -> Option<Vec3> {
    let side = if wo.z >= 0.0 { 1.0 } else { -1.0 };
    if l.hardness <= 0.0 && !l.transmission {
        let d = cosine_hemisphere(u);
        return Some(Vec3::new(d.x, d.y, d.z * side));
    }
    let h = blinn_phong_half(u, l.exponent());
    let h = Vec3::new(h.x, h.y, h.z * side);
    let cos_oh = wo.dot(h);
    if cos_oh <= 0.0 {
        return None;
    }
    let reflected = 2.0 * cos_oh * h - wo;
    if !l.transmission {
        return (reflected.z * side > 0.0).then_some(reflected);
    }
    let eta = relative_eta(l, wo);
    if u_branch < fresnel_dielectric(cos_oh, eta) {
        return (reflected.z * side > 0.0).then_some(reflected);
    }
    let wi = refract(wo, h, eta)?;
    (wi.z * side < 0.0).then(|| wi.normalize())
}

/// `(f, pdf)` of one non-delta layer for local directions, given whether they are on the same
/// side (`reflect`).
fn eval_layer(l: &Layer, tint: Rgb, wo: Vec3, wi: Vec3, reflect: bool) -> (Rgb, f32) {
    let (co, ci) = (wo.z.abs(), wi.z.abs());
    if l.hardness <= 0.0 && !l.transmission {
        if !reflect {
            return (Rgb::ZERO, 0.0);
        }
        return (l.color_at(co, tint) * FRAC_1_PI, ci * FRAC_1_PI);
    }
    let k = l.exponent();
    let side = if wo.z >= 0.0 { 1.0 } else { -1.0 };
    if reflect {
        let h = (wo + wi).normalize();
        let h = if h.z * side < 0.0 { -h } else { h };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let pdf_h = blinn_phong_half_pdf(h.z.abs(), k);
        let pdf = pdf_h / (4.0 * cos_oh);
        let c = l.color_at(cos_oh, tint);
        if !l.transmission {
            let f = (k + 1.0) / (8.0 * PI) * h.z.abs().powf(k) / (cos_oh * co.max(ci));
            return (c * f, pdf);
        }
        let fr = fresnel_dielectric(cos_oh, relative_eta(l, wo));
        return (c * (fr * pdf / ci), fr * pdf);
    }
    if !l.transmission {
        return (Rgb::ZERO, 0.0);
    }
    let eta = relative_eta(l, wo);
    let h = (wo + wi * eta).normalize();
    let h = if h.z * side < 0.0 { -h } else { h };
    let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
    if cos_oh <= 0.0 || cos_ih >= 0.0 {
        return (Rgb::ZERO, 0.0);
    }
    let denom = cos_oh + eta * cos_ih;
    if denom == 0.0 {
        return (Rgb::ZERO, 0.0);
    }
    let jacobian = eta * eta * cos_ih.abs() / (denom * denom);
    let ft = 1.0 - fresnel_dielectric(cos_oh, eta);
    let pdf = ft * blinn_phong_half_pdf(h.z.abs(), k) * jacobian;
    let c = l.color_at(cos_oh, tint);
    (c * (pdf / (ci * eta * eta)), pdf)
}

impl crate::content_hash::ContentHash for Layer {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Layer {
            weight,
            color,
            color90,
            hardness,
            transmission,
            ior,
            coat,
            dispersion,
        } = self;
        weight.content_hash(out);
        color.content_hash(out);
        color90.content_hash(out);
        hardness.content_hash(out);
        transmission.content_hash(out);
        ior.content_hash(out);
        coat.content_hash(out);
        // Only when present, so that every non-dispersive scene keeps the hash (and the cached
        // experiment results) it had before dispersion existed.
        if let Some(d) = dispersion {
            d.content_hash(out);
        }
    }
}

impl crate::content_hash::ContentHash for Material {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Material {
            name,
            layers,
            emission,
            two_sided,
            texture,
            microfacet,
            perturbation,
            param_textures,
            alpha_tables,
            blend,
            opacity,
        } = self;
        name.content_hash(out);
        layers.content_hash(out);
        emission.content_hash(out);
        two_sided.content_hash(out);
        texture.content_hash(out);
        if let Some(m) = microfacet {
            m.content_hash(out);
        }
        // Only when present, as the microfacet BSDF: older scenes keep their hashes.
        if let Some(p) = perturbation {
            format!("{p:?}").content_hash(out);
        }
        if !param_textures.is_empty() {
            param_textures.hash_text().content_hash(out);
        }
        if let Some(o) = opacity {
            o.content_hash(out);
        }
        // The tables follow from the BSDF and the roughnesses they are computed at.
        if let Some(t) = alpha_tables {
            format!("{:?}", t.alphas()).content_hash(out);
        }
        if let Some(b) = blend {
            b.weight.content_hash(out);
            format!("{:?}", b.weight_texture).content_hash(out);
            for p in &b.parts {
                p.bsdf.content_hash(out);
                format!("{} {:?}", p.textures.hash_text(), p.texture).content_hash(out);
                if let Some(t) = &p.alpha_tables {
                    format!("{:?}", t.alphas()).content_hash(out);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_bad_values_are_rejected() {
        for m in [
            Material::diffuse("d", Rgb::splat(0.5)),
            Material::mirror("m", Rgb::ONE),
            Material::glass("g", Rgb::ONE, 1.5, 1.0),
            Material::glossy("y", Rgb::ONE, 0.6),
            Material::metal("t", Rgb::splat(0.9), 0.8),
            Material::plastic("p", Rgb::splat(0.5), 0.9, 1.5),
        ] {
            assert_eq!(m.validate(), Ok(()), "{}", m.name);
        }
        let mut m = Material::diffuse("d", Rgb::splat(0.5));
        m.layers[0].hardness = 1.5;
        assert!(m.validate().is_err());
        let mut m = Material::diffuse("d", Rgb::new(f32::NAN, 0.0, 0.0));
        assert!(m.validate().is_err());
        m.layers = vec![
            Layer::new(0.7, Rgb::ONE, 0.0),
            Layer::new(0.7, Rgb::ONE, 0.5),
        ];
        assert!(matches!(m.validate(), Err(MaterialError::WeightSum(_))));
    }

    #[test]
    fn fresnel_limits() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.1, 1.0 / 1.5), 1.0);
    }

    #[test]
    fn lambertian_sample_weight_is_the_colour() {
        let m = Material::diffuse("d", Rgb::new(0.2, 0.5, 0.8));
        let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
        let b = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        let s = b.sample(0.3, Vec2::new(0.4, 0.7)).unwrap();
        assert!((s.weight - Rgb::new(0.2, 0.5, 0.8)).length() < 1e-5);
        assert!(!s.delta && s.wi.z > 0.0);
    }

    #[test]
    fn smooth_glass_refracts_by_snell() {
        let m = Material::glass("g", Rgb::ONE, 1.5, 1.0);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let b = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        let s = b.sample(0.99, Vec2::ZERO).unwrap();
        assert!(s.transmitted && s.delta);
        // sin θt = sin θi / 1.5
        assert!((s.wi.x.abs() - 0.6 / 1.5).abs() < 1e-5 && s.wi.z < 0.0);
        assert!((s.weight.x - 1.0 / 2.25).abs() < 1e-5);
    }

    fn flint() -> Material {
        let d = Dispersion::preset("sf11").unwrap();
        let mut m = Material::glass("g", Rgb::ONE, d.ior(crate::spectral::LAMBDA_D), 1.0);
        m.layers[0].dispersion = Some(d);
        m
    }

    /// A path without a wavelength gets one from `u.x` at a dispersive event, with its RGB
    /// weight; a path with one refracts by `n(λ)` and gets no new weight.
    #[test]
    fn dispersive_glass_draws_a_wavelength_once_and_refracts_by_it() {
        let m = flint();
        assert_eq!(m.validate(), Ok(()));
        let d = m.layers[0].dispersion.unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let b = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        for u in [0.1, 0.5, 0.9] {
            let s = b.sample(0.99, Vec2::new(u, 0.3)).unwrap();
            let w = crate::spectral::sample_wavelength(u);
            assert_eq!(s.wavelength, Some(w.lambda));
            let n = d.ior(w.lambda);
            assert!(s.transmitted && s.delta);
            assert!(
                (s.wi.x.abs() - 0.6 / n).abs() < 1e-5,
                "Snell at n({})",
                w.lambda
            );
            assert!((s.weight - w.weight / (n * n)).length() < 1e-5);
            // The same λ given by an earlier event: same direction, no spectral weight.
            let fixed =
                Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo).with_wavelength(Some(w.lambda));
            let t = fixed.sample(0.99, Vec2::new(0.77, 0.3)).unwrap();
            assert_eq!(t.wavelength, Some(w.lambda));
            assert!((t.wi - s.wi).length() < 1e-6);
            assert!((t.weight - Rgb::splat(1.0 / (n * n))).length() < 1e-5);
        }
        // Blue bends more than red.
        let at = |lambda| {
            Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo)
                .with_wavelength(Some(lambda))
                .sample(0.99, Vec2::ZERO)
                .unwrap()
                .wi
                .x
                .abs()
        };
        assert!(at(420.0) < at(680.0) - 1e-3);
        // Reflection off dispersive glass is a dispersive event too (Fresnel depends on n(λ)).
        let r = b.sample(0.0, Vec2::new(0.5, 0.0)).unwrap();
        assert!(!r.transmitted && r.wavelength.is_some());
        // A non-dispersive material leaves the path's wavelength as it was.
        let plain = Material::diffuse("d", Rgb::ONE);
        let p = Bsdf::new(&plain, Rgb::ONE, Vec3::Z, Vec3::Z, wo).with_wavelength(Some(500.0));
        assert_eq!(
            p.sample(0.5, Vec2::new(0.3, 0.3)).unwrap().wavelength,
            Some(500.0)
        );
        let p = Bsdf::new(&plain, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        assert_eq!(p.sample(0.5, Vec2::new(0.3, 0.3)).unwrap().wavelength, None);
        // Without dispersion, the layer is glass of index n_d.
        let off = b
            .without_dispersion()
            .sample(0.99, Vec2::new(0.1, 0.3))
            .unwrap();
        assert_eq!(off.wavelength, None);
        assert!((off.wi.x.abs() - 0.6 / m.layers[0].ior).abs() < 1e-6);
    }

    #[test]
    fn dispersion_needs_smooth_glass_and_valid_coefficients() {
        let mut m = flint();
        m.layers[0].hardness = 0.7;
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("smooth transmitting layers only"), "{e}");
        let mut m = flint();
        m.layers[0].dispersion = Some(Dispersion::Cauchy {
            a: 0.5,
            b: 0.0,
            c: 0.0,
        });
        let e = m.validate().unwrap_err().to_string();
        assert!(
            e.contains("layer 0: dispersion: index of refraction must be in (1, 4]"),
            "{e}"
        );
    }

    /// Every vertex of every path builds a `Bsdf` from a `Tint` and moves both: with a blend's
    /// two BSDFs held by value (650 bytes) the path tracer ran 7 % more instructions on the
    /// Cornell box (858 M to 921 M, callgrind, 4 spp at 128x128). Both hold pointers to a blend
    /// only; the `Bsdf` stays within 256 bytes, past which glibc's `memcpy` of it takes twice
    /// the instructions (docs/benchmarks.md, "Issue 31: `blendbsdf` back").
    #[test]
    fn bsdf_and_tint_hold_no_blend_by_value() {
        let (bsdf, tint) = (size_of::<Bsdf>(), size_of::<Tint>());
        assert!(bsdf <= 256, "Bsdf is {bsdf} bytes");
        assert!(tint <= 96, "Tint is {tint} bytes");
    }

    /// A blend material's `Bsdf` is the local blend of its BSDFs in the shading frame: value,
    /// pdf and samples; its adjoint scales only the dielectric's refraction by η².
    #[test]
    fn a_blend_material_shades_as_its_local_blend() {
        use crate::microfacet::{
            BlendPart, Diffuse, Distribution, DistributionKind, LocalBsdf, RoughDielectric,
        };
        let glass = Microfacet::Dielectric(RoughDielectric {
            distribution: Some(Distribution::new(DistributionKind::Ggx, 0.3, 0.3)),
            eta: 1.5,
            reflectance: Rgb::ONE,
            transmittance: Rgb::ONE,
        });
        let diffuse = Microfacet::Diffuse(Diffuse {
            reflectance: Rgb::new(0.2, 0.5, 0.7),
        });
        let blend = Blend::new(0.35, [BlendPart::new(glass), BlendPart::new(diffuse)]);
        let m = Material::blend("b", blend.clone());
        assert_eq!(m.validate(), Ok(()));
        let local = BlendAt {
            blend: &blend,
            at: None,
        }
        .blended();
        let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
        let b = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo);
        let adjoint = Bsdf::new(&m, Rgb::ONE, Vec3::Z, Vec3::Z, wo).adjoint();
        let mut refracted = 0;
        for i in 0..64 {
            let (u0, u) = (
                (i as f32 + 0.5) / 64.0,
                Vec2::new(0.37, (i % 8) as f32 / 8.0 + 0.05),
            );
            let (want, got) = (local.sample(wo, u0, u), b.sample(u0, u));
            assert_eq!(want.is_some(), got.is_some());
            let (Some(w), Some(s)) = (want, got) else {
                continue;
            };
            // The frame of +z is the identity; normalising may move the last bit.
            assert!((w.wi - s.wi).length() < 1e-6 && w.pdf == s.pdf && w.delta == s.delta);
            let (f, pdf) = local.eval_pdf(wo, s.wi);
            let (fb, pb) = b.eval_pdf(s.wi);
            assert!((f - fb).length() <= 1e-5 * f.length() && (pdf - pb).abs() <= 1e-5 * pdf);
            if s.wi.z < 0.0 {
                refracted += 1;
                let (fa, _) = adjoint.eval_pdf(s.wi);
                assert!(
                    (fa - f * 2.25).length() < 1e-5 * fa.length(),
                    "{fa:?} vs {f:?}"
                );
            }
        }
        assert!(refracted > 5, "{refracted}");
        let bad = Blend {
            weight: 1.5,
            ..blend
        };
        assert_eq!(
            Material::blend("b", bad)
                .validate()
                .unwrap_err()
                .to_string(),
            "blendbsdf weight must be in [0, 1], got 1.5"
        );
    }
}
