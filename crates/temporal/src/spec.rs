//! Naming a sequence denoiser in one string: `svgf[:key=value...]` for SVGF, any other text a
//! single-frame denoiser spec (`atrous:demodulate=on`) run per frame. Errors are one line naming
//! the denoiser and the option.

use crate::svgf::supersample::ExtraSample;
use crate::svgf::{Svgf, SvgfInput, SvgfParams};
use crate::{PerFrame, TemporalDenoiser, TemporalError, TemporalFrame};
use rt_core::RgbImage;
use rt_denoise::{DenoiseError, DenoiserSpec, Options};
use rt_film::Channel;
use std::fmt;
use std::str::FromStr;

/// A sequence denoiser and its options as given (validated when built).
#[derive(Clone, Debug, PartialEq)]
pub enum TemporalSpec {
    /// SVGF with `key=value` options.
    Svgf(Vec<(String, String)>),
    /// A single-frame denoiser run on every frame.
    PerFrame(DenoiserSpec),
}

impl TemporalSpec {
    /// True for denoisers that keep state between frames.
    pub fn is_temporal(&self) -> bool {
        matches!(self, TemporalSpec::Svgf(_))
    }

    /// The SVGF parameters of an `svgf` spec.
    pub fn svgf_params(options: &[(String, String)]) -> Result<SvgfParams, DenoiseError> {
        let mut o = Options::new("svgf", options);
        let p = SvgfParams::from_options(&mut o)?;
        o.finish()?;
        Ok(p)
    }

    /// Builds the denoiser, validating every option.
    pub fn build(&self) -> Result<Box<dyn TemporalDenoiser>, TemporalError> {
        Ok(match self {
            TemporalSpec::Svgf(options) => Box::new(NamedSvgf {
                name: self.to_string(),
                svgf: Svgf::new(Self::svgf_params(options)?),
            }),
            TemporalSpec::PerFrame(spec) => Box::new(PerFrame(spec.build()?)),
        })
    }
}

impl FromStr for TemporalSpec {
    type Err = DenoiseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut parts = s.trim().split(':');
        let kind = parts.next().unwrap_or_default();
        if !kind.eq_ignore_ascii_case("svgf") {
            return Ok(TemporalSpec::PerFrame(s.parse()?));
        }
        let mut options: Vec<(String, String)> = Vec::new();
        for p in parts {
            let Some((k, v)) = p.split_once('=') else {
                return Err(DenoiseError::Spec(format!(
                    "svgf: option '{p}' is not key=value"
                )));
            };
            let k = k.trim().to_string();
            if options.iter().any(|(o, _)| *o == k) {
                return Err(DenoiseError::Spec(format!(
                    "svgf: option '{k}' given twice"
                )));
            }
            options.push((k, v.trim().to_string()));
        }
        Ok(TemporalSpec::Svgf(options))
    }
}

impl fmt::Display for TemporalSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TemporalSpec::Svgf(options) => {
                f.write_str("svgf")?;
                for (k, v) in options {
                    write!(f, ":{k}={v}")?;
                }
                Ok(())
            }
            TemporalSpec::PerFrame(s) => s.fmt(f),
        }
    }
}

/// SVGF behind the trait, with the name it was asked for by.
struct NamedSvgf {
    name: String,
    svgf: Svgf,
}

const SVGF_NEEDS: [Channel; 3] = [Channel::Direct, Channel::Indirect, Channel::Emission];

impl TemporalDenoiser for NamedSvgf {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[Channel] {
        &SVGF_NEEDS
    }

    fn needs_guides(&self) -> bool {
        true
    }

    fn guide_samples(&self) -> bool {
        true
    }

    fn filter(&mut self, frame: &TemporalFrame<'_>) -> Result<RgbImage, TemporalError> {
        let missing = || TemporalError::MissingGuides {
            denoiser: self.name.clone(),
        };
        let f = frame.frame;
        let input = SvgfInput {
            guides: frame.guides.ok_or_else(missing)?,
            direct: f.direct.as_ref().ok_or_else(missing)?,
            indirect: f.indirect.as_ref().ok_or_else(missing)?,
            emission: f.emission.as_ref().ok_or_else(missing)?,
        };
        // `push` checked every extra sample's channels.
        let extra: Vec<ExtraSample<'_>> = frame
            .extra
            .iter()
            .filter_map(|e| {
                Some(ExtraSample {
                    direct: e.direct.as_ref()?,
                    indirect: e.indirect.as_ref()?,
                    emission: e.emission.as_ref()?,
                    albedo: e.albedo.as_ref()?,
                    normal: e.normal.as_ref()?,
                    position: e.position.as_ref()?,
                })
            })
            .collect();
        Ok(self.svgf.push_supersampled(&input, &extra))
    }

    fn reset(&mut self) {
        self.svgf.reset();
    }
}
