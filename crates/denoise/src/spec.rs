//! Naming a denoiser and its options in one string, and building it: the one dispatch point
//! for denoisers, as `rt_accel::AccelSpec` is for acceleration structures.
//!
//! `render denoise --denoiser`, GREE's bank files and experiment methods all take the same
//! text, in the one option grammar of every spec ([`rt_core::options`]): a kind followed by
//! `key=value` options separated by `:` or `,`, e.g. `box:radius=2`. Unknown kinds, repeated
//! keys, keys nothing reads, values that do not parse and values out of range are each one
//! error naming the denoiser and the key.

#[cfg(feature = "oidn")]
use crate::Oidn;
use crate::{
    Atrous, BoxBlur, DenoiseError, Denoiser, Gaussian, GuidedFilter, JointBilateral, Nlm, Sbmf,
};
pub use rt_core::options::Options;
use rt_core::options::{OptionsError, Problem, SEPARATORS};
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

/// A denoiser kind and its options as given (validated when built, where a key nothing
/// reads is refused), in the one option grammar ([`rt_core::options`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DenoiserSpec {
    /// Which denoiser.
    pub kind: DenoiserKind,
    /// The options in the order given.
    pub options: Options,
}

impl DenoiserSpec {
    /// Builds the denoiser, validating every option.
    pub fn build(&self) -> Result<Box<dyn Denoiser>, DenoiseError> {
        let mut o = self.options.clone();
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
        let given = Options::parse(s)?;
        let kind_name = given.kind();
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
        // The kind as this crate names it, for errors and the printed spec.
        let options = Options::of(
            kind.name(),
            &s[s.find(SEPARATORS).map_or(s.len(), |i| i + 1)..],
        )?;
        Ok(Self { kind, options })
    }
}

impl fmt::Display for DenoiserSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        write_options(f, &self.options)
    }
}

/// `:key=value` (or `:flag`) for every option, in the order given.
pub fn write_options(f: &mut fmt::Formatter<'_>, options: &Options) -> fmt::Result {
    for (k, v) in options.entries() {
        match v {
            Some(v) => write!(f, ":{k}={v}")?,
            None => write!(f, ":{k}")?,
        }
    }
    Ok(())
}

/// The typed getters denoisers read their options with, over the one option type
/// ([`Options`]): each takes a default and returns a [`DenoiseError`] naming the denoiser and
/// the key.
pub trait DenoiserOptions {
    /// A finite number (`default` if absent).
    fn f32(&mut self, key: &'static str, default: f32) -> Result<f32, DenoiseError>;
    /// A non-negative integer.
    fn usize(&mut self, key: &'static str, default: usize) -> Result<usize, DenoiseError>;
    /// `on`/`off` (also `true`/`false`, `1`/`0`).
    fn on_off(&mut self, key: &'static str, default: bool) -> Result<bool, DenoiseError>;
    /// One of `choices` (`default` if absent).
    fn pick(
        &mut self,
        key: &'static str,
        choices: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, DenoiseError>;
    /// A parameter error for `key`.
    fn param_error(&self, key: &'static str, message: String) -> DenoiseError;
}

/// The denoiser's name as a `'static` string, for [`DenoiseError::Param`].
fn static_kind(kind: &str) -> &'static str {
    DenoiserKind::ALL
        .iter()
        .map(|k| k.name())
        .chain(["svgf"])
        .find(|n| n.eq_ignore_ascii_case(kind))
        .unwrap_or("denoiser")
}

/// A value out of range is a parameter error naming the key; the rest are spec errors.
fn value_error(o: &Options, key: &'static str, e: OptionsError) -> DenoiseError {
    match *e.problem {
        Problem::BadValue {
            value, expected, ..
        } => o.param_error(key, format!("`{value}` is not {expected}")),
        _ => e.into(),
    }
}

impl DenoiserOptions for Options {
    fn f32(&mut self, key: &'static str, default: f32) -> Result<f32, DenoiseError> {
        let v = self.value_in(key, "a finite number", |v: &f32| v.is_finite());
        Ok(v.map_err(|e| value_error(self, key, e))?.unwrap_or(default))
    }

    fn usize(&mut self, key: &'static str, default: usize) -> Result<usize, DenoiseError> {
        let v = self.value(key, "a non-negative integer");
        Ok(v.map_err(|e| value_error(self, key, e))?.unwrap_or(default))
    }

    fn on_off(&mut self, key: &'static str, default: bool) -> Result<bool, DenoiseError> {
        let v = self.switch(key);
        Ok(v.map_err(|e| value_error(self, key, e))?.unwrap_or(default))
    }

    fn pick(
        &mut self,
        key: &'static str,
        choices: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, DenoiseError> {
        let v = self.choice(key, choices);
        Ok(v.map_err(|e| value_error(self, key, e))?.unwrap_or(default))
    }

    fn param_error(&self, key: &'static str, message: String) -> DenoiseError {
        DenoiseError::Param {
            denoiser: static_kind(self.kind()),
            name: key,
            message,
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
            "box: radius: `x` is not a non-negative integer"
        );
        assert_eq!(
            err("box:radius=100"),
            "box: radius: must be at most 64, got 100"
        );
        assert_eq!(err("box:size=2"), "box: unknown option `size`");
        assert_eq!(
            err("box:radius"),
            "box: option `radius` needs a value (`radius=...`)"
        );
        assert_eq!(
            err("box:radius=1,radius=2"),
            "box: option `radius` given twice"
        );
        assert_eq!(err("BOX:radius=1"), "", "the kind in any case");
        assert_eq!(err("nlm:k=inf"), "nlm: k: `inf` is not a finite number");
    }

    #[test]
    fn every_kind_displays_a_spec_that_parses_back_to_it() {
        for text in [
            "box:radius=3",
            "gaussian:sigma=4",
            "bilateral:sigma=3:normal=0.5:variances=off",
            "nlm:radius=5:patch=2:k=0.3",
            "guided:radius=4:eps=0.02:guide=normal",
            "atrous:iterations=3:colour=off:scale=absolute",
            "sbmf:manifolds=3:layers=3",
            "atrous",
        ] {
            let s: DenoiserSpec = text.parse().unwrap();
            assert_eq!(s.to_string(), text);
            assert_eq!(s.to_string().parse::<DenoiserSpec>().unwrap(), s);
            s.build().unwrap();
        }
        // Either separator, any case of the kind; printed canonically.
        let s: DenoiserSpec = "NLM:radius=5,k=0.3".parse().unwrap();
        assert_eq!(s.to_string(), "nlm:radius=5:k=0.3");
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
