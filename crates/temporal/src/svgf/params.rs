//! SVGF's parameters, their defaults and where each comes from, and parsing them from a spec's
//! `key=value` options (`svgf:alpha=0.1:reflections=off`).
//!
//! Shipping SVGF code does not use the paper's values (anchors-denoise.md §2: Falcor runs 4
//! iterations with σ_l = 10 and α = 0.05), so every one is a parameter and the benchmark sweeps
//! them. The defaults are Voorhuis' (seed 001 §1.5, §2.1): σ_z = 1, σ_n = 64, σ_l = 5,
//! α = 0.2 on diffuse and 0.1 on specular pixels, 5 iterations, feedback after the first.

use rt_denoise::{DenoiseError, DenoiserOptions, Options};

/// How pixels whose primary hit is specular (roughness below `specular_limit`) find their
/// history.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reflections {
    /// Voorhuis' extensions: mirrors by a diamond search on the reflected hit's position,
    /// sharp glossy surfaces by one on representative rays (Eq. 5), neighbourhood clipping,
    /// reflected features for edge stopping.
    Reproject,
    /// Baseline SVGF: every pixel by its primary hit's motion ("Base" in the thesis).
    Primary,
    /// No history for specular pixels ("NoSpecReproj" in the thesis).
    Drop,
}

/// Everything SVGF can be told.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgfParams {
    /// Blend weight of the new frame on diffuse pixels (`alpha`).
    pub alpha: f32,
    /// Blend weight on specular pixels (`alpha-specular`).
    pub alpha_specular: f32,
    /// Blend weight of the luminance moments (`alpha-moments`).
    pub alpha_moments: f32,
    /// Longest history counted (`max-history`): the blend never goes below 1/this.
    pub max_history: f32,
    /// À-Trous iterations (`iterations`).
    pub iterations: u32,
    /// The colour history is the output of this many iterations (`feedback`, Falcor's
    /// feedback tap 1; 0 keeps the unfiltered accumulation).
    pub feedback: u32,
    /// Depth edge-stopping bandwidth σ_z (`sigma-z`).
    pub sigma_z: f32,
    /// Normal edge-stopping exponent σ_n (`sigma-n`).
    pub sigma_n: f32,
    /// Luminance edge-stopping bandwidth σ_l in standard deviations (`sigma-l`).
    pub sigma_l: f32,
    /// What specular pixels reproject by (`reflections=reproject|primary|drop`).
    pub reflections: Reflections,
    /// Neighbourhood clipping of specular pixels' history (`clip`, Voorhuis §2.5).
    pub clip: bool,
    /// 3×3 median on diffuse pixels of the displayed image (`median`, Voorhuis §2.7).
    pub median: bool,
    /// σ_l × (8 − min(7, h)) while the history is short (`wide-start`, Voorhuis Eq. 8).
    pub wide_start: bool,
    /// Keep the indirect signal's variance unfiltered across iterations
    /// (`hold-indirect-variance`, Voorhuis §2.7 change 4).
    pub hold_indirect_variance: bool,
    /// Roughness below which a pixel is specular (`specular-limit`, Voorhuis 0.9).
    pub specular_limit: f32,
    /// Roughness below which a glossy pixel is searched by representative rays
    /// (`glossy-limit`, Voorhuis 0.4).
    pub glossy_limit: f32,
    /// World-space footprint scale ω of the glossy spatial bandwidth (`omega`, Eq. 6: 0.5).
    pub omega: f32,
    /// First step of the diamond search (`diamond-step`, Voorhuis 4).
    pub diamond_step: u32,
    /// Sub-pixel refinement of searched motion (`subpixel`, Voorhuis Eq. 2–3).
    pub subpixel: bool,
}

impl Default for SvgfParams {
    fn default() -> Self {
        Self {
            alpha: 0.2,
            alpha_specular: 0.1,
            alpha_moments: 0.2,
            max_history: 32.0,
            iterations: 5,
            feedback: 1,
            sigma_z: 1.0,
            sigma_n: 64.0,
            sigma_l: 5.0,
            reflections: Reflections::Reproject,
            clip: true,
            median: true,
            wide_start: true,
            hold_indirect_variance: true,
            specular_limit: 0.9,
            glossy_limit: 0.4,
            omega: 0.5,
            diamond_step: 4,
            subpixel: true,
        }
    }
}

impl SvgfParams {
    /// Schied et al.'s SVGF without Voorhuis' changes: primary motion everywhere, no clipping,
    /// no median, no wide start, both variances filtered, α = 0.2 and σ_n = 128, σ_l = 4.
    pub fn schied() -> Self {
        Self {
            alpha_specular: 0.2,
            sigma_n: 128.0,
            sigma_l: 4.0,
            reflections: Reflections::Primary,
            clip: false,
            median: false,
            wide_start: false,
            hold_indirect_variance: false,
            ..Self::default()
        }
    }

    /// Reads the options of an `svgf` spec; `preset=voorhuis|schied` picks the defaults the
    /// other options change.
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let base = match o.pick("preset", &["voorhuis", "schied"], "voorhuis")? {
            "schied" => Self::schied(),
            _ => Self::default(),
        };
        let unit = |o: &mut Options, key: &'static str, d: f32| -> Result<f32, DenoiseError> {
            let v = o.f32(key, d)?;
            if !(v > 0.0 && v <= 1.0) {
                return Err(o.param_error(key, format!("must be in (0, 1], got {v}")));
            }
            Ok(v)
        };
        let positive = |o: &mut Options, key: &'static str, d: f32| -> Result<f32, DenoiseError> {
            let v = o.f32(key, d)?;
            if v <= 0.0 {
                return Err(o.param_error(key, format!("must be positive, got {v}")));
            }
            Ok(v)
        };
        let reflections = match o.pick(
            "reflections",
            &["reproject", "primary", "drop"],
            match base.reflections {
                Reflections::Reproject => "reproject",
                Reflections::Primary => "primary",
                Reflections::Drop => "drop",
            },
        )? {
            "primary" => Reflections::Primary,
            "drop" => Reflections::Drop,
            _ => Reflections::Reproject,
        };
        let p = Self {
            alpha: unit(o, "alpha", base.alpha)?,
            alpha_specular: unit(o, "alpha-specular", base.alpha_specular)?,
            alpha_moments: unit(o, "alpha-moments", base.alpha_moments)?,
            max_history: {
                let v = positive(o, "max-history", base.max_history)?;
                if v < 1.0 {
                    return Err(
                        o.param_error("max-history", format!("must be at least 1, got {v}"))
                    );
                }
                v
            },
            iterations: {
                let v = o.usize("iterations", base.iterations as usize)?;
                if v > 10 {
                    return Err(o.param_error("iterations", format!("must be at most 10, got {v}")));
                }
                v as u32
            },
            feedback: o.usize("feedback", base.feedback as usize)? as u32,
            sigma_z: positive(o, "sigma-z", base.sigma_z)?,
            sigma_n: {
                let v = o.f32("sigma-n", base.sigma_n)?;
                if v < 0.0 {
                    return Err(o.param_error("sigma-n", format!("must be >= 0, got {v}")));
                }
                v
            },
            sigma_l: positive(o, "sigma-l", base.sigma_l)?,
            reflections,
            clip: o.on_off("clip", base.clip)?,
            median: o.on_off("median", base.median)?,
            wide_start: o.on_off("wide-start", base.wide_start)?,
            hold_indirect_variance: o
                .on_off("hold-indirect-variance", base.hold_indirect_variance)?,
            specular_limit: unit(o, "specular-limit", base.specular_limit)?,
            glossy_limit: unit(o, "glossy-limit", base.glossy_limit)?,
            omega: positive(o, "omega", base.omega)?,
            diamond_step: {
                let v = o.usize("diamond-step", base.diamond_step as usize)?;
                if !(1..=64).contains(&v) {
                    return Err(
                        o.param_error("diamond-step", format!("must be in 1..=64, got {v}"))
                    );
                }
                v as u32
            },
            subpixel: o.on_off("subpixel", base.subpixel)?,
        };
        if p.feedback > p.iterations {
            return Err(o.param_error(
                "feedback",
                format!(
                    "must be at most iterations ({}), got {}",
                    p.iterations, p.feedback
                ),
            ));
        }
        if p.glossy_limit > p.specular_limit {
            return Err(o.param_error(
                "glossy-limit",
                format!(
                    "must not exceed specular-limit ({}), got {}",
                    p.specular_limit, p.glossy_limit
                ),
            ));
        }
        Ok(p)
    }
}
