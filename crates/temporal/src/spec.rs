//! Naming a sequence denoiser in one string, in the one option grammar of every spec
//! ([`rt_core::options`]): `svgf[:key=value...]` for SVGF, any other text a single-frame
//! denoiser spec (`atrous:demodulate=on`) run per frame. Errors are one line naming the
//! denoiser and the option.

use crate::svgf::supersample::ExtraSample;
use crate::svgf::{Svgf, SvgfInput, SvgfParams};
use crate::{PerFrame, TemporalDenoiser, TemporalError, TemporalFrame};
use rt_core::options::SEPARATORS;
use rt_core::RgbImage;
use rt_denoise::{DenoiseError, DenoiserSpec, Options};
use rt_film::Channel;
use std::fmt;
use std::str::FromStr;

/// A sequence denoiser and its options as given (validated when built).
#[derive(Clone, Debug, PartialEq)]
pub enum TemporalSpec {
    /// SVGF with `key=value` options.
    Svgf(Options),
    /// A single-frame denoiser run on every frame.
    PerFrame(DenoiserSpec),
}

impl TemporalSpec {
    /// True for denoisers that keep state between frames.
    pub fn is_temporal(&self) -> bool {
        matches!(self, TemporalSpec::Svgf(_))
    }

    /// The SVGF parameters of an `svgf` spec.
    pub fn svgf_params(options: &Options) -> Result<SvgfParams, DenoiseError> {
        let mut o = options.clone();
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
        let given = Options::parse(s)?;
        if !given.kind().eq_ignore_ascii_case("svgf") {
            return Ok(TemporalSpec::PerFrame(s.parse()?));
        }
        let rest = s.trim();
        let rest = &rest[rest.find(SEPARATORS).map_or(rest.len(), |i| i + 1)..];
        Ok(TemporalSpec::Svgf(Options::of("svgf", rest)?))
    }
}

impl fmt::Display for TemporalSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TemporalSpec::Svgf(options) => {
                f.write_str("svgf")?;
                rt_denoise::spec::write_options(f, options)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_display_what_parses_back_and_refuse_bad_options_naming_them() {
        for text in [
            "svgf",
            "svgf:alpha=0.1:iterations=3",
            "atrous:iterations=2",
            "box",
        ] {
            let s: TemporalSpec = text.parse().unwrap();
            assert_eq!(s.to_string(), text);
            assert_eq!(s.to_string().parse::<TemporalSpec>().unwrap(), s);
            s.build().unwrap();
        }
        assert_eq!(
            "SVGF:alpha=0.1,clip=off"
                .parse::<TemporalSpec>()
                .unwrap()
                .to_string(),
            "svgf:alpha=0.1:clip=off"
        );
        let err = |t: &str| match t.parse::<TemporalSpec>() {
            Err(e) => e.to_string(),
            Ok(s) => s.build().err().map(|e| e.to_string()).unwrap_or_default(),
        };
        assert_eq!(
            err("svgf:alpha=0.1:alpha=0.2"),
            "svgf: option `alpha` given twice"
        );
        assert_eq!(err("svgf:sigma-q=1"), "svgf: unknown option `sigma-q`");
        assert_eq!(err("svgf:alpha=3"), "svgf: alpha: must be in (0, 1], got 3");
    }
}
