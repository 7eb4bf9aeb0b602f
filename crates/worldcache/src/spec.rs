//! Naming a cache and its options in one string, the single dispatch point between the point
//! sets: `worldspace[:key=value,...]` (implicit points) or `grid[:key=value,...]` (the fixed
//! grid). Options are separated by `,` or `:`. Every bad option is one [`CacheError`] naming
//! the cache kind and the option.
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
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// A cache name or option that cannot be used.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CacheError {
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
    text: String,
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

impl fmt::Display for CacheSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl FromStr for CacheSpec {
    type Err = CacheError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        let (name, rest) = s.split_once(':').unwrap_or((s, ""));
        let kind = match name {
            "worldspace" => CacheKind::Worldspace,
            "grid" => CacheKind::Grid,
            other => return Err(CacheError::UnknownKind(other.to_string())),
        };
        let k = kind.name();
        let mut spec = CacheSpec {
            kind,
            lod: match kind {
                CacheKind::Worldspace => 5,
                CacheKind::Grid => 6,
            },
            s0: None,
            params: CacheParams::default(),
            capacity: 1 << 18,
            pass_capacity: 1 << 18,
            text: s.to_string(),
        };
        for opt in rest
            .split([',', ':'])
            .map(str::trim)
            .filter(|o| !o.is_empty())
        {
            let Some((key, value)) = opt.split_once('=') else {
                return Err(CacheError::MissingValue {
                    kind: k,
                    key: opt.to_string(),
                });
            };
            let (key, value) = (key.trim(), value.trim());
            let bad = |expected: &'static str| CacheError::BadValue {
                kind: k,
                key: key.to_string(),
                value: value.to_string(),
                expected,
            };
            let p = &mut spec.params;
            match key {
                "lod" => {
                    spec.lod = value
                        .parse()
                        .ok()
                        .filter(|l| *l <= 20)
                        .ok_or_else(|| bad("an integer in 0..=20"))?
                }
                "s0" => {
                    spec.s0 = Some(
                        value
                            .parse::<f32>()
                            .ok()
                            .filter(|v| v.is_finite() && *v > 0.0)
                            .ok_or_else(|| bad("a positive number"))?,
                    )
                }
                "kappa" => {
                    p.kappa = value
                        .parse::<f32>()
                        .ok()
                        .filter(|v| *v > 0.0 && *v <= 1.0)
                        .ok_or_else(|| bad("a number in (0, 1]"))?
                }
                "connectivity" => {
                    p.connectivity = value
                        .parse()
                        .ok()
                        .and_then(Connectivity::from_neighbours)
                        .ok_or_else(|| bad("one of 0, 6, 18, 26"))?
                }
                "select" => {
                    p.selection = match value {
                        "barycentric" => Selection::Barycentric,
                        "nearest" => Selection::Nearest,
                        "jitter" => Selection::Jitter { radius: 1.0 },
                        _ => return Err(bad("one of barycentric, nearest, jitter")),
                    }
                }
                "jitter" => {
                    let radius = value
                        .parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite() && *v >= 0.0)
                        .ok_or_else(|| bad("a non-negative number"))?;
                    p.selection = Selection::Jitter { radius };
                }
                "radius" => {
                    p.radius = value
                        .parse::<f32>()
                        .ok()
                        .filter(|v| *v > 0.0 && *v <= 4.0)
                        .ok_or_else(|| bad("a number in (0, 4]"))?
                }
                "normals" => {
                    p.normals = value.parse().map_err(|_| bad("true or false"))?;
                }
                "min-samples" => {
                    p.min_samples = value
                        .parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite() && *v >= 0.0)
                        .ok_or_else(|| bad("a non-negative number"))?
                }
                "capacity" | "pass-capacity" => {
                    let c = value
                        .parse::<usize>()
                        .ok()
                        .filter(|c| c.is_power_of_two() && (2..=1 << 28).contains(c))
                        .ok_or_else(|| bad("a power of two in 2..=2^28"))?;
                    if key == "capacity" {
                        spec.capacity = c;
                    } else {
                        spec.pass_capacity = c;
                    }
                }
                _ => {
                    return Err(CacheError::UnknownOption {
                        kind: k,
                        key: key.to_string(),
                    })
                }
            }
        }
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
    fn bad_options_name_the_option() {
        let e = |s: &str| s.parse::<CacheSpec>().unwrap_err().to_string();
        assert_eq!(
            e("octree"),
            "unknown cache `octree` (known: worldspace, grid)"
        );
        assert!(e("worldspace:lod=x").contains("option `lod`: `x` is not an integer"));
        assert!(e("grid:capacity=1000").contains("`capacity`: `1000` is not a power of two"));
        assert!(e("worldspace:kappa=0").contains("`kappa`"));
        assert!(e("worldspace:connectivity=5").contains("one of 0, 6, 18, 26"));
        assert!(e("worldspace:foo=1").starts_with("worldspace: unknown option `foo`"));
        assert!(e("worldspace:lod").contains("option `lod` needs a value"));
        for msg in [e("worldspace:radius=9"), e("grid:s0=-1")] {
            assert!(!msg.contains('\n'));
        }
    }
}
