//! The one option grammar every spec uses (`AccelSpec`, `IntegratorSpec`, `DenoiserSpec`,
//! `TemporalSpec`, `CacheSpec`, GREE's options): `KIND[:OPTION...]`, each option `key=value`
//! or a bare `flag`, options separated by `:` or `,`, spaces around each piece ignored.
//!
//! [`Options::parse`] splits the text and refuses a key given twice; the spec reads its keys
//! with the typed getters, each refusing a value that does not parse or is out of range; and
//! [`Options::finish`] refuses a key nothing read. Every error is one [`OptionsError`] naming
//! the spec's kind and the option. A spec prints itself back in the same grammar (`:` between
//! options), and what it prints parses to the same spec.
//!
//! ```
//! use rt_core::options::Options;
//! let mut o = Options::parse("qbvh:leaf=8,compact").unwrap();
//! assert_eq!(o.kind(), "qbvh");
//! assert_eq!(o.value_in::<u32>("leaf", "an integer from 1 to 16", |n| (1..=16).contains(n)).unwrap(), Some(8));
//! assert!(o.flag("compact").unwrap());
//! o.finish().unwrap();
//! let e = Options::parse("qbvh:leaf=8:leaf=4").unwrap_err();
//! assert_eq!(e.to_string(), "qbvh: option `leaf` given twice");
//! let o = Options::parse("qbvh:fast").unwrap();
//! assert_eq!(o.finish().unwrap_err().to_string(), "qbvh: unknown option `fast`");
//! ```

use std::str::FromStr;

/// The separators between a spec's kind and its options, and between options.
pub const SEPARATORS: [char; 2] = [':', ','];

/// What is wrong with one option.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Problem {
    /// The same key twice.
    #[error("option `{0}` given twice")]
    Repeated(String),
    /// A key nothing read: the spec has no such option.
    #[error("unknown option `{0}`")]
    Unknown(String),
    /// `key` without `=value` where a value is needed.
    #[error("option `{0}` needs a value (`{0}=...`)")]
    MissingValue(String),
    /// `key=value` where the option is a bare flag.
    #[error("option `{0}` takes no value")]
    UnexpectedValue(String),
    /// A value that does not parse or is out of range.
    #[error("{key}: `{value}` is not {expected}")]
    BadValue {
        /// The option.
        key: String,
        /// The value as given.
        value: String,
        /// What it must be.
        expected: String,
    },
    /// A piece of the text that is neither `key=value` nor a flag (`=3`).
    #[error("`{0}` is not an option (key=value or a flag)")]
    Malformed(String),
}

/// An option error, naming the spec's kind (`qbvh`, `nlm`, `gree`, ...).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{spec}: {problem}")]
pub struct OptionsError {
    /// The spec's kind.
    pub spec: String,
    /// What is wrong (boxed: errors that carry this one stay small).
    pub problem: Box<Problem>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
struct Entry {
    key: String,
    value: Option<String>,
    used: bool,
}

/// A spec's kind and options, as given; see the module documentation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    kind: String,
    entries: Vec<Entry>,
}

impl Options {
    /// Splits `KIND[:OPTION...]`; refuses a repeated key and a malformed piece.
    pub fn parse(text: &str) -> Result<Options, OptionsError> {
        let text = text.trim();
        let (kind, rest) = match text.find(SEPARATORS) {
            Some(i) => (&text[..i], &text[i + 1..]),
            None => (text, ""),
        };
        Options::of(kind.trim(), rest)
    }

    /// The options `text` of a spec of kind `kind` that has no kind in its text (GREE's
    /// `fraction=0.9:kappa=0.5`).
    pub fn of(kind: &str, text: &str) -> Result<Options, OptionsError> {
        let mut o = Options {
            kind: kind.to_string(),
            entries: Vec::new(),
        };
        for piece in text
            .split(SEPARATORS)
            .map(str::trim)
            .filter(|p| !p.is_empty())
        {
            let (key, value) = match piece.split_once('=') {
                Some((k, v)) => (k.trim(), Some(v.trim().to_string())),
                None => (piece, None),
            };
            if key.is_empty() {
                return Err(o.error(Problem::Malformed(piece.to_string())));
            }
            if o.entries.iter().any(|e| e.key == key) {
                return Err(o.error(Problem::Repeated(key.to_string())));
            }
            o.entries.push(Entry {
                key: key.to_string(),
                value,
                used: false,
            });
        }
        Ok(o)
    }

    /// The spec's kind (the text before the first separator).
    pub fn kind(&self) -> &str {
        &self.kind
    }

    /// The options in the order given, as `(key, value)`.
    pub fn entries(&self) -> impl Iterator<Item = (&str, Option<&str>)> {
        self.entries
            .iter()
            .map(|e| (e.key.as_str(), e.value.as_deref()))
    }

    /// True if no option was given.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// An error about this spec.
    pub fn error(&self, problem: Problem) -> OptionsError {
        OptionsError {
            spec: self.kind.clone(),
            problem: Box::new(problem),
        }
    }

    /// A bad-value error for `key`.
    pub fn bad(&self, key: &str, value: &str, expected: &str) -> OptionsError {
        self.error(Problem::BadValue {
            key: key.to_string(),
            value: value.to_string(),
            expected: expected.to_string(),
        })
    }

    /// Marks `key` read and returns it: `None` if absent, `Some(None)` for a bare flag.
    pub fn take(&mut self, key: &str) -> Option<Option<&str>> {
        let e = self.entries.iter_mut().find(|e| e.key == key)?;
        e.used = true;
        Some(e.value.as_deref())
    }

    /// The text of `key=value` (`None` if absent); a bare `key` is refused.
    pub fn text(&mut self, key: &str) -> Result<Option<String>, OptionsError> {
        match self.take(key) {
            None => Ok(None),
            Some(Some(v)) => Ok(Some(v.to_string())),
            Some(None) => Err(self.error(Problem::MissingValue(key.to_string()))),
        }
    }

    /// `key=value` parsed as a `T` (`None` if absent); `expected` says what it must be.
    pub fn value<T: FromStr>(
        &mut self,
        key: &str,
        expected: &str,
    ) -> Result<Option<T>, OptionsError> {
        self.value_in(key, expected, |_| true)
    }

    /// [`Options::value`], also refusing a value for which `ok` is false.
    pub fn value_in<T: FromStr>(
        &mut self,
        key: &str,
        expected: &str,
        ok: impl Fn(&T) -> bool,
    ) -> Result<Option<T>, OptionsError> {
        let Some(text) = self.text(key)? else {
            return Ok(None);
        };
        match text.parse::<T>() {
            Ok(v) if ok(&v) => Ok(Some(v)),
            _ => Err(self.bad(key, &text, expected)),
        }
    }

    /// A bare flag: true if given; `key=value` is refused.
    pub fn flag(&mut self, key: &str) -> Result<bool, OptionsError> {
        match self.take(key) {
            None => Ok(false),
            Some(None) => Ok(true),
            Some(Some(_)) => Err(self.error(Problem::UnexpectedValue(key.to_string()))),
        }
    }

    /// `key=on|off` (also `true`/`false`, `1`/`0`).
    pub fn switch(&mut self, key: &str) -> Result<Option<bool>, OptionsError> {
        let Some(text) = self.text(key)? else {
            return Ok(None);
        };
        match text.as_str() {
            "on" | "true" | "1" => Ok(Some(true)),
            "off" | "false" | "0" => Ok(Some(false)),
            _ => Err(self.bad(key, &text, "on or off")),
        }
    }

    /// `key=` one of `choices`.
    pub fn choice(
        &mut self,
        key: &str,
        choices: &[&'static str],
    ) -> Result<Option<&'static str>, OptionsError> {
        let Some(text) = self.text(key)? else {
            return Ok(None);
        };
        match choices.iter().find(|c| **c == text) {
            Some(c) => Ok(Some(c)),
            None => Err(self.bad(key, &text, &format!("one of {}", choices.join(", ")))),
        }
    }

    /// The first key nothing read, if any.
    pub fn unread(&self) -> Option<&str> {
        self.entries
            .iter()
            .find(|e| !e.used)
            .map(|e| e.key.as_str())
    }

    /// Refuses a key nothing read.
    pub fn finish(self) -> Result<(), OptionsError> {
        match self.unread() {
            Some(key) => Err(self.error(Problem::Unknown(key.to_string()))),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_separators_flags_and_values() {
        let mut o = Options::parse(" worldspace : lod=7, kappa = 0.5:normals").unwrap();
        assert_eq!(o.kind(), "worldspace");
        assert_eq!(o.value::<u32>("lod", "an integer").unwrap(), Some(7));
        assert_eq!(o.value::<f32>("kappa", "a number").unwrap(), Some(0.5));
        assert!(o.flag("normals").unwrap());
        assert_eq!(o.value::<u32>("absent", "x").unwrap(), None);
        o.finish().unwrap();
        let o = Options::parse("bvh8").unwrap();
        assert!(o.is_empty() && o.kind() == "bvh8");
        let o = Options::of("gree", "").unwrap();
        assert!(o.is_empty());
    }

    #[test]
    fn each_refusal_is_one_line_naming_the_spec() {
        let e = |r: Result<(), OptionsError>| r.unwrap_err().to_string();
        assert_eq!(
            e(Options::parse("nlm:k=1,k=2").map(|_| ())),
            "nlm: option `k` given twice"
        );
        assert_eq!(
            e(Options::parse("nlm:k=1:size=3").and_then(|mut o| {
                o.value::<f32>("k", "a number")?;
                o.finish()
            })),
            "nlm: unknown option `size`"
        );
        assert_eq!(
            e(Options::parse("box:radius").and_then(|mut o| o.text("radius").map(|_| ()))),
            "box: option `radius` needs a value (`radius=...`)"
        );
        assert_eq!(
            e(Options::parse("qbvh:lazy=1").and_then(|mut o| o.flag("lazy").map(|_| ()))),
            "qbvh: option `lazy` takes no value"
        );
        assert_eq!(
            e(Options::parse("box:radius=x").and_then(|mut o| {
                o.value::<u32>("radius", "a non-negative integer")
                    .map(|_| ())
            })),
            "box: radius: `x` is not a non-negative integer"
        );
        assert_eq!(
            e(Options::parse("m:f=a").and_then(|mut o| o.choice("f", &["b", "c"]).map(|_| ()))),
            "m: f: `a` is not one of b, c"
        );
        assert_eq!(
            e(Options::parse("m:=3").map(|_| ())),
            "m: `=3` is not an option (key=value or a flag)"
        );
    }
}
