//! Naming a denoiser and its options in one string, and building it: the one dispatch point
//! for denoisers, as `rt_accel::AccelSpec` is for acceleration structures.
//!
//! `render denoise --denoiser`, GREE's bank files and experiment methods all take the same
//! text: a kind followed by `:`-separated `key=value` options, e.g. `box:radius=2`. Unknown
//! kinds, unknown keys, values that do not parse and values out of range are each one error
//! naming the denoiser and the key.

#[cfg(feature = "oidn")]
use crate::Oidn;
use crate::{
    Atrous, BoxBlur, DenoiseError, Denoiser, Gaussian, GuidedFilter, JointBilateral, Nlm, Sbmf,
};
use std::fmt;
use std::str::FromStr;

/// The denoisers this crate builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DenoiserKind {
    /// [`BoxBlur`].
    Box,
    /// [`Gaussian`].
    Gaussian,
    /// [`JointBilateral`].
    Bilateral,
    /// [`Nlm`].
    Nlm,
    /// [`GuidedFilter`].
    Guided,
    /// [`Atrous`].
    Atrous,
    /// [`Sbmf`] (needs the frame's sample records).
    Sbmf,
    /// `Oidn` (Open Image Denoise; only in builds with the `oidn` feature).
    #[cfg(feature = "oidn")]
    Oidn,
}

impl DenoiserKind {
    /// Every kind, in the order help texts list them.
    pub const ALL: &'static [DenoiserKind] = &[
        DenoiserKind::Box,
        DenoiserKind::Gaussian,
        DenoiserKind::Bilateral,
        DenoiserKind::Nlm,
        DenoiserKind::Guided,
        DenoiserKind::Atrous,
        DenoiserKind::Sbmf,
        #[cfg(feature = "oidn")]
        DenoiserKind::Oidn,
    ];

    /// The name used in specs.
    pub fn name(self) -> &'static str {
        match self {
            DenoiserKind::Box => "box",
            DenoiserKind::Gaussian => "gaussian",
            DenoiserKind::Bilateral => "bilateral",
            DenoiserKind::Nlm => "nlm",
            DenoiserKind::Guided => "guided",
            DenoiserKind::Atrous => "atrous",
            DenoiserKind::Sbmf => "sbmf",
            #[cfg(feature = "oidn")]
            DenoiserKind::Oidn => "oidn",
        }
    }

    fn names() -> String {
        Self::ALL
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl fmt::Display for DenoiserKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A denoiser kind and its options as given (validated when built).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DenoiserSpec {
    /// Which denoiser.
    pub kind: DenoiserKind,
    /// `key=value` options in the order given.
    pub options: Vec<(String, String)>,
}

impl DenoiserSpec {
    /// Builds the denoiser, validating every option.
    pub fn build(&self) -> Result<Box<dyn Denoiser>, DenoiseError> {
        let mut o = Options::new(self.kind.name(), &self.options);
        let d: Box<dyn Denoiser> = match self.kind {
            DenoiserKind::Box => Box::new(BoxBlur::from_options(&mut o)?),
            DenoiserKind::Gaussian => Box::new(Gaussian::from_options(&mut o)?),
            DenoiserKind::Bilateral => Box::new(JointBilateral::from_options(&mut o)?),
            DenoiserKind::Nlm => Box::new(Nlm::from_options(&mut o)?),
            DenoiserKind::Guided => Box::new(GuidedFilter::from_options(&mut o)?),
            DenoiserKind::Atrous => Box::new(Atrous::from_options(&mut o)?),
            DenoiserKind::Sbmf => Box::new(Sbmf::from_options(&mut o)?),
            #[cfg(feature = "oidn")]
            DenoiserKind::Oidn => Box::new(Oidn::from_options(&mut o)?),
        };
        o.finish()?;
        Ok(d)
    }
}

impl FromStr for DenoiserSpec {
    type Err = DenoiseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut parts = s.trim().split(':');
        let kind_name = parts.next().unwrap_or_default();
        let kind = DenoiserKind::ALL
            .iter()
            .copied()
            .find(|k| k.name().eq_ignore_ascii_case(kind_name))
            .ok_or_else(|| {
                if cfg!(not(feature = "oidn")) && kind_name.eq_ignore_ascii_case("oidn") {
                    return DenoiseError::Spec(
                        "denoiser 'oidn' is not in this build: rebuild with the 'oidn' feature \
                         of rt-denoise (cargo build --features rt-denoise/oidn)"
                            .into(),
                    );
                }
                DenoiseError::Spec(format!(
                    "unknown denoiser '{kind_name}' (expected one of: {})",
                    DenoiserKind::names()
                ))
            })?;
        let mut options = Vec::new();
        for p in parts {
            let Some((k, v)) = p.split_once('=') else {
                return Err(DenoiseError::Spec(format!(
                    "{kind}: option '{p}' is not key=value"
                )));
            };
            let k = k.trim().to_string();
            if options.iter().any(|(o, _)| *o == k) {
                return Err(DenoiseError::Spec(format!(
                    "{kind}: option '{k}' given twice"
                )));
            }
            options.push((k, v.trim().to_string()));
        }
        Ok(Self { kind, options })
    }
}

impl fmt::Display for DenoiserSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        for (k, v) in &self.options {
            write!(f, ":{k}={v}")?;
        }
        Ok(())
    }
}

/// The options of one spec, read by a denoiser's `from_options`; [`Options::finish`] refuses
/// any key nobody read.
#[derive(Debug)]
pub struct Options<'a> {
    denoiser: &'static str,
    given: &'a [(String, String)],
    used: Vec<bool>,
}

impl<'a> Options<'a> {
    /// The options `given` to denoiser kind `denoiser`.
    pub fn new(denoiser: &'static str, given: &'a [(String, String)]) -> Self {
        Self {
            denoiser,
            given,
            used: vec![false; given.len()],
        }
    }

    /// The denoiser these options are for.
    pub fn denoiser(&self) -> &'static str {
        self.denoiser
    }

    fn raw(&mut self, key: &str) -> Option<&'a str> {
        let i = self.given.iter().position(|(k, _)| k == key)?;
        self.used[i] = true;
        Some(self.given[i].1.as_str())
    }

    fn parse<T: FromStr>(
        &mut self,
        key: &'static str,
        default: T,
        what: &str,
    ) -> Result<T, DenoiseError> {
        match self.raw(key) {
            None => Ok(default),
            Some(v) => v.parse().map_err(|_| DenoiseError::Param {
                denoiser: self.denoiser,
                name: key,
                message: format!("'{v}' is not {what}"),
            }),
        }
    }

    /// A finite number (`default` if absent).
    pub fn f32(&mut self, key: &'static str, default: f32) -> Result<f32, DenoiseError> {
        let v = self.parse(key, default, "a number")?;
        if !v.is_finite() {
            return Err(self.error(key, format!("must be finite, got {v}")));
        }
        Ok(v)
    }

    /// A non-negative integer.
    pub fn usize(&mut self, key: &'static str, default: usize) -> Result<usize, DenoiseError> {
        self.parse(key, default, "a non-negative integer")
    }

    /// `on`/`off` (also `true`/`false`, `1`/`0`).
    pub fn flag(&mut self, key: &'static str, default: bool) -> Result<bool, DenoiseError> {
        match self.raw(key) {
            None => Ok(default),
            Some("on" | "true" | "1") => Ok(true),
            Some("off" | "false" | "0") => Ok(false),
            Some(v) => Err(self.error(key, format!("'{v}' is not on or off"))),
        }
    }

    /// One of `choices` (`default` if absent).
    pub fn choice(
        &mut self,
        key: &'static str,
        choices: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, DenoiseError> {
        match self.raw(key) {
            None => Ok(default),
            Some(v) => choices.iter().copied().find(|c| *c == v).ok_or_else(|| {
                self.error(key, format!("'{v}' is not one of {}", choices.join(", ")))
            }),
        }
    }

    /// A parameter error for `key`.
    pub fn error(&self, key: &'static str, message: String) -> DenoiseError {
        DenoiseError::Param {
            denoiser: self.denoiser,
            name: key,
            message,
        }
    }

    /// Refuses keys nobody read.
    pub fn finish(self) -> Result<(), DenoiseError> {
        match self.used.iter().position(|u| !u) {
            Some(i) => Err(DenoiseError::Spec(format!(
                "{}: unknown option '{}'",
                self.denoiser, self.given[i].0
            ))),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_print_and_refuse_bad_input_with_one_line() {
        let s: DenoiserSpec = "box:radius=3".parse().unwrap();
        assert_eq!(s.to_string(), "box:radius=3");
        assert_eq!(s.build().unwrap().name(), "box:radius=3");
        let err = |t: &str| match t.parse::<DenoiserSpec>() {
            Err(e) => e.to_string(),
            Ok(s) => s.build().err().map(|e| e.to_string()).unwrap_or_default(),
        };
        assert!(err("fancy").contains("unknown denoiser 'fancy'"));
        assert_eq!(
            err("box:radius=x"),
            "box: radius: 'x' is not a non-negative integer"
        );
        assert_eq!(
            err("box:radius=100"),
            "box: radius: must be at most 64, got 100"
        );
        assert_eq!(err("box:size=2"), "box: unknown option 'size'");
        assert_eq!(err("box:radius"), "box: option 'radius' is not key=value");
        assert!(err("box:radius=1:radius=2").contains("given twice"));
    }

    #[cfg(not(feature = "oidn"))]
    #[test]
    fn oidn_in_a_build_without_the_feature_is_one_clear_error() {
        let e = "oidn:quality=high".parse::<DenoiserSpec>().unwrap_err();
        assert!(
            e.to_string()
                .starts_with("denoiser 'oidn' is not in this build")
                && e.to_string().contains("--features rt-denoise/oidn"),
            "{e}"
        );
        assert!(!DenoiserKind::names().contains("oidn"));
    }
}
