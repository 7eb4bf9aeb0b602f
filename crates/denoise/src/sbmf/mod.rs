//! SBMF, sample-based manifold filtering for global illumination and depth of field (Bauszat's
//! thesis ch. 4; Bauszat, Eisemann, Eisemann & Magnor, "Sample-Based Manifold Filtering for
//! Interactive Global Illumination and Depth of Field", CGF 2015). It filters *samples*, not
//! pixels: the input is [`SampleRecords`] (per sample radiance, first-hit normal, position,
//! albedo and signed circle of confusion), which a [`NoisyFrame`](crate::NoisyFrame) carries
//! in memory when its film kept them (the `samples` channel; never in a file). As a
//! [`Denoiser`](crate::Denoiser) (`sbmf` in specs) it needs that channel; the sample-level
//! entry point is [`Sbmf::filter_samples`].
//!
//! Two steps, in sequence, because the lighting integral is nested inside the lens integral:
//!
//! - **Step A** (GI reconstruction, §4.2): sample-based adaptive manifolds. Guides
//!   (`guides`) → manifold tree (`manifolds`) → splat and edge-aware blur (`splat`,
//!   `domain_transform`) → slice with the under-represented-sample fallback (`slice`,
//!   `fallback`). Every sample gets a filtered colour; samples are never merged per pixel.
//! - **Step B** (depth of field, §4.3): the fast sweep-blur (`sweep`, `layers`, `sat`)
//!   redistributes those colours over the image by their CoC, at a cost independent of it.
//!
//! Deviations are listed in each step's module. The sample colour is not a guide (as in the
//! thesis). Parameters are global (no per-pixel adaptivity, as in the thesis).

mod domain_transform;
mod fallback;
mod guides;
mod layers;
mod manifolds;
mod sat;
mod slice;
mod splat;
mod sweep;
#[cfg(test)]
mod tests;

pub use sweep::SweepStats;

use crate::{DenoiseError, DenoiserOptions, Options};
use layers::Layers;
use rt_core::{Rgb, RgbImage};
use rt_film::SampleRecords;

/// SBMF's parameters; [`Sbmf::new`] validates them.
#[derive(Clone, Debug, PartialEq)]
pub struct SbmfParams {
    /// Adaptive manifolds of step A, `2^h − 1` for tree height `h`: 1, 3, 7, 15 (the thesis'
    /// sweet spot, the default), 31 or 63.
    pub manifolds: usize,
    /// Spatial standard deviation in pixels of step A's blur and of the manifolds' low-pass
    /// (default 8; on `scenes/dof.toml` 4–8 gave the lowest MSE at both 256x192 and 512x384,
    /// while 16 and more flatten the shading of curved surfaces, the colour not being a guide).
    pub sigma_spatial: f32,
    /// Standard deviation of the normal guide (unit normals).
    pub sigma_normal: f32,
    /// Standard deviation of the position guide in pixel footprints (the median world
    /// distance between neighbouring pixels' hit positions).
    pub sigma_position: f32,
    /// Standard deviation of the albedo guide.
    pub sigma_albedo: f32,
    /// Slice denominators below this take the fallback colour.
    pub min_weight: f32,
    /// Box radius in pixels of the fallback image (the thesis uses 4–8).
    pub fallback_radius: usize,
    /// Layers of step B: 3 or 7 (the only counts the thesis supports; 7 by default).
    pub layers: usize,
    /// CoC in pixels of the outermost layers (`τ`); 0 uses the samples' largest `|CoC|`.
    pub max_coc: f32,
}

impl Default for SbmfParams {
    fn default() -> Self {
        Self {
            manifolds: 15,
            sigma_spatial: 8.0,
            sigma_normal: 0.25,
            sigma_position: 16.0,
            sigma_albedo: 0.1,
            min_weight: 1e-3,
            fallback_radius: 6,
            layers: 7,
            max_coc: 0.0,
        }
    }
}

/// The SBMF filter (see the module documentation).
#[derive(Clone, Debug)]
pub struct Sbmf {
    params: SbmfParams,
    name: String,
}

/// What [`Sbmf::step_a`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepAStats {
    /// Samples whose slice denominator was below `min_weight` (they took the fallback).
    pub fallbacks: usize,
}

const NAME: &str = "sbmf";

fn param(name: &'static str, message: String) -> DenoiseError {
    DenoiseError::Param {
        denoiser: NAME,
        name,
        message,
    }
}

impl Sbmf {
    /// Largest spatial σ and fallback radius accepted (beyond, almost certainly a mistake).
    pub const MAX_SIGMA_SPATIAL: f32 = 256.0;
    /// Largest fallback radius accepted.
    pub const MAX_FALLBACK_RADIUS: usize = 64;

    /// Validates `params`.
    pub fn new(params: SbmfParams) -> Result<Self, DenoiseError> {
        let p = &params;
        if !(1..=63).contains(&p.manifolds) || !(p.manifolds + 1).is_power_of_two() {
            return Err(param(
                "manifolds",
                format!(
                    "must be 2^h - 1 (1, 3, 7, 15, 31 or 63), got {}",
                    p.manifolds
                ),
            ));
        }
        if !(p.sigma_spatial > 0.0 && p.sigma_spatial <= Self::MAX_SIGMA_SPATIAL) {
            return Err(param(
                "sigma_spatial",
                format!(
                    "must be in (0, {}], got {}",
                    Self::MAX_SIGMA_SPATIAL,
                    p.sigma_spatial
                ),
            ));
        }
        for (name, v) in [
            ("sigma_normal", p.sigma_normal),
            ("sigma_position", p.sigma_position),
            ("sigma_albedo", p.sigma_albedo),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(param(name, format!("must be positive and finite, got {v}")));
            }
        }
        if !(p.min_weight >= 0.0 && p.min_weight.is_finite()) {
            return Err(param(
                "min_weight",
                format!("must be finite and not negative, got {}", p.min_weight),
            ));
        }
        if p.fallback_radius > Self::MAX_FALLBACK_RADIUS {
            return Err(param(
                "fallback_radius",
                format!(
                    "must be at most {}, got {}",
                    Self::MAX_FALLBACK_RADIUS,
                    p.fallback_radius
                ),
            ));
        }
        if p.layers != 3 && p.layers != 7 {
            return Err(param("layers", format!("must be 3 or 7, got {}", p.layers)));
        }
        if !(p.max_coc >= 0.0 && p.max_coc.is_finite()) {
            return Err(param(
                "max_coc",
                format!(
                    "must be finite and not negative (0: automatic), got {}",
                    p.max_coc
                ),
            ));
        }
        let name = format!(
            "sbmf:manifolds={}:sigma_spatial={}:sigma_normal={}:sigma_position={}:\
             sigma_albedo={}:min_weight={}:fallback_radius={}:layers={}:max_coc={}",
            p.manifolds,
            p.sigma_spatial,
            p.sigma_normal,
            p.sigma_position,
            p.sigma_albedo,
            p.min_weight,
            p.fallback_radius,
            p.layers,
            p.max_coc
        );
        Ok(Self { params, name })
    }

    /// From spec-style options (`sbmf:manifolds=7:layers=3`, parsed by
    /// [`DenoiserSpec`](crate::DenoiserSpec)'s syntax), defaults from [`SbmfParams::default`].
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let d = SbmfParams::default();
        Self::new(SbmfParams {
            manifolds: o.usize("manifolds", d.manifolds)?,
            sigma_spatial: o.f32("sigma_spatial", d.sigma_spatial)?,
            sigma_normal: o.f32("sigma_normal", d.sigma_normal)?,
            sigma_position: o.f32("sigma_position", d.sigma_position)?,
            sigma_albedo: o.f32("sigma_albedo", d.sigma_albedo)?,
            min_weight: o.f32("min_weight", d.min_weight)?,
            fallback_radius: o.usize("fallback_radius", d.fallback_radius)?,
            layers: o.usize("layers", d.layers)?,
            max_coc: o.f32("max_coc", d.max_coc)?,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &SbmfParams {
        &self.params
    }

    /// Name with every parameter, for reports.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl crate::Denoiser for Sbmf {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[crate::Channel] {
        &[crate::Channel::Samples]
    }

    fn filter(&self, frame: &crate::NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        // `denoise` checked that the records are there and of the frame's size.
        frame
            .samples
            .as_ref()
            .and_then(|r| self.filter_samples(r, w, h).ok())
            .unwrap_or_else(|| frame.colour.clone())
    }
}

impl Sbmf {
    fn check(records: &SampleRecords, width: usize, height: usize) -> Result<(), DenoiseError> {
        if (records.width() as usize, records.height() as usize) != (width, height) {
            return Err(DenoiseError::Spec(format!(
                "{NAME}: sample records are {}x{}, the image {width}x{height}",
                records.width(),
                records.height()
            )));
        }
        Ok(())
    }

    /// Filters the samples of a `width × height` image: step A, then step B. The result has no
    /// NaN or infinity.
    pub fn filter_samples(
        &self,
        records: &SampleRecords,
        width: usize,
        height: usize,
    ) -> Result<RgbImage, DenoiseError> {
        let (colour, _) = self.step_a(records, width, height)?;
        Ok(self.step_b(records, &colour, width, height)?.0)
    }

    /// Step A alone: the filtered colour of every sample (record order).
    pub fn step_a(
        &self,
        records: &SampleRecords,
        width: usize,
        height: usize,
    ) -> Result<(Vec<Rgb>, StepAStats), DenoiseError> {
        Self::check(records, width, height)?;
        if records.is_empty() {
            return Ok((Vec::new(), StepAStats::default()));
        }
        let p = &self.params;
        let g = guides::guides(records, p.sigma_normal, p.sigma_position, p.sigma_albedo);
        let eta = manifolds::build(records, &g, width, p.manifolds, p.sigma_spatial);
        let blurred = splat::splat_and_blur(records, &g, &eta, width, p.sigma_spatial);
        let fb = fallback::box_blurred_pixels(records, width, height, p.fallback_radius);
        let (mut colour, fallbacks) = slice::slice(records, &g, &eta, &blurred, &fb, p.min_weight);
        for c in &mut colour {
            if !c.is_finite() {
                *c = Rgb::ZERO;
            }
        }
        Ok((colour, StepAStats { fallbacks }))
    }

    /// Step B alone: sweeps per-sample colours `colour` (one per record, e.g. step A's) into
    /// the image by the records' circles of confusion. Refuses a colour count that is not the
    /// record count.
    pub fn step_b(
        &self,
        records: &SampleRecords,
        colour: &[Rgb],
        width: usize,
        height: usize,
    ) -> Result<(RgbImage, SweepStats), DenoiseError> {
        Self::check(records, width, height)?;
        if colour.len() != records.len() {
            return Err(DenoiseError::Spec(format!(
                "{NAME}: {} colours for {} samples",
                colour.len(),
                records.len()
            )));
        }
        let tau = if self.params.max_coc > 0.0 {
            self.params.max_coc
        } else {
            records.coc().iter().fold(0.0f32, |m, c| m.max(c.abs()))
        };
        let layers = Layers {
            n_f: self.params.layers / 2,
            tau,
        };
        let (mut img, stats) = sweep::sweep(records, colour, width, height, layers);
        for p in img.pixels_mut() {
            if !p.is_finite() {
                *p = Rgb::ZERO;
            }
        }
        Ok((img, stats))
    }
}
