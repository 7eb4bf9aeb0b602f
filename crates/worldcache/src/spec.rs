//! Naming a cache and its options in one string, the single dispatch point between the point
//! sets: `worldspace[:key=value,...]` (implicit points) or `grid[:key=value,...]` (the fixed
//! grid), in the one option grammar of every spec ([`rt_core::options`]: options separated by
//! `:` or `,`). Every bad option is one [`CacheError`] naming the cache kind and the option; a
//! spec displays itself canonically (the options that differ from the defaults), and that
//! text parses back to the same spec.
//!
//! | option        | meaning                                                  | default |
//! |---------------|----------------------------------------------------------|---------|
//! | `lod`         | level: voxel (cell) edge `s0 / 2^lod`, 0..=20              | worldspace 5, grid 6 (matched density) |
//! | `s0`          | level-0 edge in world units                               | the caller's (e.g. the scene's size) |
//! | `kappa`       | temporal decay κ of the merge, in (0, 1]                  | 0.9 |
//! | `connectivity`| neighbours scanned by the selection: 0, 6, 18, 26          | 26 |
//! | `select`      | `barycentric`, `nearest` or `jitter`                      | barycentric |
//! | `jitter`      | jitter radius in point spacings (implies `select=jitter`) | 1 |
//! | `radius`      | Shepard search distance in point spacings, (0, 4]         | 2 |
//! | `normals`     | normal bin in the key: `true`/`false` (the thesis: false) | true |
//! | `min-samples` | lookups with fewer stored samples are misses              | 0 |
//! | `capacity`    | persistent entries, a power of two                        | 2^18 (6 MiB) |
//! | `pass-capacity` | per-pass accumulator slots, a power of two              | 2^18 (10 MiB) |

use crate::cache::{AnyPoints, CacheParams, WorldCache};
use crate::discretisation::Connectivity;
use crate::select::Selection;
use crate::{FixedGrid, ImplicitPoints};
use rt_core::options::Options;
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// A cache name or option that cannot be used.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CacheError {
    /// An option that breaks the option grammar, is out of range, or that nothing reads.
    #[error(transparent)]
    Options(#[from] rt_core::options::OptionsError),
    /// Not `worldspace` or `grid`.
    #[error("unknown cache `{0}` (known: worldspace, grid)")]
    UnknownKind(String),
    /// An option the cache does not have.
    #[error("{kind}: unknown option `{key}` (known: {KNOWN})")]
    UnknownOption {
        /// Cache kind.
        kind: &'static str,
        /// The option as given.
        key: String,
    },
    /// An option without `=value`.
    #[error("{kind}: option `{key}` needs a value (`{key}=...`)")]
    MissingValue {
        /// Cache kind.
        kind: &'static str,
        /// The option.
        key: String,
    },
    /// A value that does not parse or is out of range.
    #[error("{kind}: option `{key}`: `{value}` is not {expected}")]
    BadValue {
        /// Cache kind.
        kind: &'static str,
        /// The option.
        key: String,
        /// The value as given.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
}

const KNOWN: &str =
    "lod, s0, kappa, connectivity, select, jitter, radius, normals, min-samples, capacity, pass-capacity";

/// Which point set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheKind {
    /// Implicit progressive points (Delaere 2021).
    Worldspace,
    /// Fixed grid (Binder et al. 2019).
    Grid,
}

impl CacheKind {
    /// The name in specs.
    pub fn name(self) -> &'static str {
        match self {
            CacheKind::Worldspace => "worldspace",
            CacheKind::Grid => "grid",
        }
    }
}

/// A parsed, validated cache description.
#[derive(Clone, Debug, PartialEq)]
pub struct CacheSpec {
    /// Point set.
    pub kind: CacheKind,
    /// Level.
    pub lod: u32,
    /// Level-0 edge; `None`: the caller's default.
    pub s0: Option<f32>,
    /// Behaviour.
    pub params: CacheParams,
    /// Persistent entries.
    pub capacity: usize,
    /// Accumulator slots.
    pub pass_capacity: usize,
}

impl CacheSpec {
    /// Builds the cache; `default_s0` is used when the spec gives no `s0` (e.g. the largest
    /// extent of the scene's bounds).
    pub fn build(&self, default_s0: f32) -> Result<WorldCache<AnyPoints>, CacheError> {
        let s0 = self.s0.unwrap_or(default_s0);
        if !(s0.is_finite() && s0 > 0.0) {
            return Err(CacheError::BadValue {
                kind: self.kind.name(),
                key: "s0".into(),
                value: s0.to_string(),
                expected: "a positive number",
            });
        }
        let points = match self.kind {
            CacheKind::Worldspace => AnyPoints::Implicit(ImplicitPoints::new(s0, self.lod)),
            CacheKind::Grid => AnyPoints::Grid(FixedGrid::new(s0, self.lod)),
        };
        // Capacities were checked when parsing.
        WorldCache::new(points, self.params, self.capacity, self.pass_capacity).map_err(|e| {
            CacheError::BadValue {
                kind: self.kind.name(),
                key: "capacity".into(),
                value: e.0.to_string(),
                expected: "a power of two",
            }
        })
    }
}

/// Entries of either table when nothing says (2^18: 6 MiB persistent, 10 MiB per pass).
const DEFAULT_CAPACITY: usize = 1 << 18;

impl CacheSpec {
    /// The default spec of `kind`: level 5 (`worldspace`) or 6 (`grid`, the matched density).
    pub fn new(kind: CacheKind) -> Self {
        Self {
            kind,
            lod: match kind {
                CacheKind::Worldspace => 5,
                CacheKind::Grid => 6,
            },
            s0: None,
            params: CacheParams::default(),
            capacity: DEFAULT_CAPACITY,
            pass_capacity: DEFAULT_CAPACITY,
        }
    }
}

impl fmt::Display for CacheSpec {
    /// The kind, then every option that differs from the kind's default.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = CacheSpec::new(self.kind);
        let (p, dp) = (&self.params, &d.params);
        f.write_str(self.kind.name())?;
        if self.lod != d.lod {
            write!(f, ":lod={}", self.lod)?;
        }
        if let Some(s0) = self.s0 {
            write!(f, ":s0={s0}")?;
        }
        if p.kappa != dp.kappa {
            write!(f, ":kappa={}", p.kappa)?;
        }
        if p.connectivity != dp.connectivity {
            write!(f, ":connectivity={}", p.connectivity.neighbours())?;
        }
        match p.selection {
            Selection::Barycentric => {}
            Selection::Nearest => f.write_str(":select=nearest")?,
            Selection::Jitter { radius } => write!(f, ":jitter={radius}")?,
        }
        if p.radius != dp.radius {
            write!(f, ":radius={}", p.radius)?;
        }
        if p.normals != dp.normals {
            write!(f, ":normals={}", p.normals)?;
        }
        if p.min_samples != dp.min_samples {
            write!(f, ":min-samples={}", p.min_samples)?;
        }
        if self.capacity != d.capacity {
            write!(f, ":capacity={}", self.capacity)?;
        }
        if self.pass_capacity != d.pass_capacity {
            write!(f, ":pass-capacity={}", self.pass_capacity)?;
        }
        Ok(())
    }
}

impl FromStr for CacheSpec {
    type Err = CacheError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut o = Options::parse(s)?;
        let kind = match o.kind() {
            "worldspace" => CacheKind::Worldspace,
            "grid" => CacheKind::Grid,
            other => return Err(CacheError::UnknownKind(other.to_string())),
        };
        let mut spec = CacheSpec::new(kind);
        let positive = |v: &f32| v.is_finite() && *v > 0.0;
        let capacity = |c: &usize| c.is_power_of_two() && (2..=1 << 28).contains(c);
        let p = &mut spec.params;
        spec.lod = o
            .value_in("lod", "an integer in 0..=20", |l: &u32| *l <= 20)?
            .unwrap_or(spec.lod);
        spec.s0 = o.value_in("s0", "a positive number", positive)?;
        p.kappa = o
            .value_in("kappa", "a number in (0, 1]", |v: &f32| {
                *v > 0.0 && *v <= 1.0
            })?
            .unwrap_or(p.kappa);
        if let Some(n) = o.value_in("connectivity", "one of 0, 6, 18, 26", |n: &u32| {
            Connectivity::from_neighbours(*n).is_some()
        })? {
            p.connectivity = Connectivity::from_neighbours(n).expect("checked");
        }
        p.selection = match o.choice("select", &["barycentric", "nearest", "jitter"])? {
            Some("nearest") => Selection::Nearest,
            Some("jitter") => Selection::Jitter { radius: 1.0 },
            _ => p.selection,
        };
        let jitter = |v: &f32| v.is_finite() && *v >= 0.0;
        if let Some(radius) = o.value_in("jitter", "a non-negative number", jitter)? {
            p.selection = Selection::Jitter { radius };
        }
        p.radius = o
            .value_in("radius", "a number in (0, 4]", |v: &f32| {
                *v > 0.0 && *v <= 4.0
            })?
            .unwrap_or(p.radius);
        p.normals = o.switch("normals")?.unwrap_or(p.normals);
        p.min_samples = o
            .value_in("min-samples", "a non-negative number", jitter)?
            .unwrap_or(p.min_samples);
        let pow2 = "a power of two in 2..=2^28";
        spec.capacity = o
            .value_in("capacity", pow2, capacity)?
            .unwrap_or(spec.capacity);
        spec.pass_capacity = o
            .value_in("pass-capacity", pow2, capacity)?
            .unwrap_or(spec.pass_capacity);
        o.finish()?;
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_options_with_either_separator() {
        let s: CacheSpec = "worldspace:lod=7,kappa=0.5:connectivity=6,normals=true"
            .parse()
            .unwrap();
        assert_eq!(s.lod, 7);
        assert_eq!(s.params.kappa, 0.5);
        assert_eq!(s.params.connectivity, Connectivity::C6);
        assert!(s.params.normals);
        let g: CacheSpec = "grid:jitter=3".parse().unwrap();
        assert_eq!(g.kind, CacheKind::Grid);
        assert_eq!(g.params.selection, Selection::Jitter { radius: 3.0 });
    }

    #[test]
    fn every_spec_displays_a_text_that_parses_back_to_it() {
        for text in [
            "worldspace",
            "grid",
            "worldspace:lod=7:kappa=0.5:connectivity=6",
            "grid:s0=2.5:select=nearest:radius=1.5:normals=false:min-samples=4",
            "worldspace:jitter=3:capacity=1024:pass-capacity=2048",
        ] {
            let s: CacheSpec = text.parse().unwrap();
            assert_eq!(s.to_string(), text);
            assert_eq!(s.to_string().parse::<CacheSpec>(), Ok(s));
        }
        let s: CacheSpec = "worldspace:kappa=0.5,lod=7,select=jitter".parse().unwrap();
        assert_eq!(s.to_string(), "worldspace:lod=7:kappa=0.5:jitter=1");
    }

    #[test]
    fn bad_options_name_the_option() {
        let e = |s: &str| s.parse::<CacheSpec>().unwrap_err().to_string();
        assert_eq!(
            e("octree"),
            "unknown cache `octree` (known: worldspace, grid)"
        );
        assert_eq!(
            e("worldspace:lod=x"),
            "worldspace: lod: `x` is not an integer in 0..=20"
        );
        assert!(e("grid:capacity=1000").contains("capacity: `1000` is not a power of two"));
        assert!(e("worldspace:kappa=0").contains("kappa"));
        assert!(e("worldspace:connectivity=5").contains("one of 0, 6, 18, 26"));
        assert_eq!(e("worldspace:foo=1"), "worldspace: unknown option `foo`");
        assert!(e("worldspace:lod").contains("option `lod` needs a value"));
        assert_eq!(
            e("worldspace:lod=3,lod=4"),
            "worldspace: option `lod` given twice"
        );
        for msg in [e("worldspace:radius=9"), e("grid:s0=-1")] {
            assert!(!msg.contains('\n'));
        }
    }
}
