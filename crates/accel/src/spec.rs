//! Naming a structure and its options in one string, and building it.
//!
//! The CLI's `--accel`, the scene's `[render] accel` and `render bench-accel --accel` all take
//! the same text, in the one option grammar of every spec ([`rt_core::options`]): a kind
//! followed by options separated by `:` or `,`, e.g. `qbvh`, `bvh`,
//! `qbvh:order=distance:tstack`, `qbvh:evh=14:compact`, `qbvh:isect=hybrid`, `qbvh:lazy`.
//! [`AccelSpec`] parses it ([`std::str::FromStr`]), prints it back in a canonical form
//! ([`std::fmt::Display`]) and [`AccelSpec::build`] makes the structure, so a program that
//! depends only on this crate can offer the same choice.
//!
//! | option | kinds | meaning |
//! |---|---|---|
//! | `leaf=N` | bvh, qbvh, bvh8, two-level | largest leaf (default 4 for bvh, 16 for qbvh and bvh8) |
//! | `bins=N` | bvh, qbvh, bvh8 | SAH bins per axis |
//! | `icost=F` | bvh, qbvh, bvh8 | SAH cost of a triangle test relative to a node visit (default 1 for bvh, 0.2 for the wide ones) |
//! | `evh=T` / `bbah=T` | bvh, qbvh, bvh8 | triangle splitting with threshold exponent T |
//! | `compact` | bvh, qbvh, bvh8 | remove duplicate references per leaf |
//! | `order=unsorted\|distance\|split` | qbvh, bvh8, two-level | child order (default `split`) |
//! | `tstack` / `no-tstack` | qbvh, bvh8 | keep entry distances on the stack and skip stale entries, or not (default: on for bvh8, off for qbvh) |
//! | `shadow-cache` | qbvh, bvh8 | start occlusion queries at the last occluder's node |
//! | `isect=watertight\|subdivision\|hybrid` | qbvh, bvh8 | triangle test (default watertight) |
//! | `lazy` | qbvh | build subtrees the first time a ray reaches them |
//! | `lambda=F` | grid | Cleary's density: about F·N cells for N triangles (default 3) |
//! | `depth=N` | irregular-grid | deepest second-level subdivision, 2^N cells per axis in a top cell (default 3) |
//! | `t=T` | clusters | entry points are object nodes smaller than the scene's size over T (default 8) |
//! | `top=rebuild\|refit` | two-level | per frame, rebuild the top level over the instances' boxes or refit it (default `rebuild`) |
//!
//! `iosp0`, `iosp4` and `iosp2` take no options. They live in the triangle order: built over
//! [`BuildInput::SceneToReorder`] they reorder the scene to match (nothing stored beyond the
//! triangles); over a slice or a `&Scene` they map hits back through an index map, and so
//! does a scene with instances (each frame rewrites an instance's world copy in its own
//! contiguous range, which a reordering would scatter).
//!
//! `two-level` takes the bvh8 options for its object BVHs; built over a scene it follows
//! moving instances by [`Accel::update`].

use crate::build_input::BuildInput;
use crate::wide::{Order, TriangleTest, WideOptions};
use crate::{BruteForce, BuildParams, Bvh2, Bvh8, Qbvh, Split};
use glam::Vec3;
use rt_core::options::Options;
use rt_core::Accel;
use std::fmt;
use std::str::FromStr;

/// The structure `render` uses when neither `--accel` nor `[render] accel` names one, as spec
/// text ([`AccelSpec::default`] parses it).
pub const DEFAULT_ACCEL: &str = "bvh8";

/// Clustering's default threshold `t`: the best of the thesis' car (Fig. 4.16, seconds per
/// frame 0.454 at t = 8 against 0.656 with one entry per object).
pub const DEFAULT_CLUSTER_T: f32 = 8.0;

/// The structures this crate builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum AccelKind {
    /// [`Bvh2`].
    Bvh,
    /// [`Qbvh`].
    Qbvh,
    /// [`Bvh8`].
    Bvh8,
    /// [`BruteForce`].
    BruteForce,
    /// [`TwoLevel`](crate::TwoLevel): per-object BVH8s under a top level over the placements.
    TwoLevel,
    /// [`TwoLevel`](crate::TwoLevel) with rigid-body entry-point clustering.
    Clusters,
    /// [`UniformGrid`](crate::UniformGrid).
    Grid,
    /// [`IrregularGrid`](crate::IrregularGrid).
    IrregularGrid,
    /// [`Iosp0`](crate::Iosp0): the implicit BVH in the triangle order, 0 bytes.
    Iosp0,
    /// [`Iosp4`](crate::Iosp4): 4 bytes per node.
    Iosp4,
    /// [`Iosp2`](crate::Iosp2): a SAH top over IOSP-0 heaps.
    Iosp2,
}

impl AccelKind {
    /// Every kind, in the order reports list them.
    pub const ALL: [AccelKind; 11] = [
        AccelKind::Qbvh,
        AccelKind::Bvh8,
        AccelKind::Bvh,
        AccelKind::BruteForce,
        AccelKind::TwoLevel,
        AccelKind::Clusters,
        AccelKind::Grid,
        AccelKind::IrregularGrid,
        AccelKind::Iosp0,
        AccelKind::Iosp4,
        AccelKind::Iosp2,
    ];

    /// True for the structures that reorder the triangles (IOSP).
    pub fn permutes(self) -> bool {
        matches!(self, AccelKind::Iosp0 | AccelKind::Iosp4 | AccelKind::Iosp2)
    }

    /// True for the two-level kinds, whose object BVHs are BVH8s.
    pub fn is_two_level(self) -> bool {
        matches!(self, AccelKind::TwoLevel | AccelKind::Clusters)
    }

    /// True for the wide BVHs collapsed from a binary one (QBVH and BVH8).
    pub fn is_wide(self) -> bool {
        matches!(self, AccelKind::Qbvh | AccelKind::Bvh8)
    }

    /// An upper bound on the bytes a structure of this kind over `triangles` triangles needs
    /// while it is built and after: its triangle copies, nodes and the builder's temporary
    /// arrays. The per-triangle figures are about twice the largest held size measured
    /// (`render --stats` on the shipped scenes and Sponza, 66k triangles: BVH 69 B/triangle,
    /// QBVH 56, BVH8 55, two-level 55, clusters 57, uniform grid 65, irregular grid 320,
    /// IOSP-0/4/2 36/37/74), which covers the builders' reference arrays; 64 KiB covers the
    /// fixed parts of small scenes. `crates/accel/tests/memory_bound.rs` checks the held size
    /// against it. For refusing renders that cannot fit (`render --max-memory`), not for
    /// accounting.
    pub fn memory_bound(self, triangles: usize) -> u64 {
        let per_triangle: u64 = match self {
            AccelKind::BruteForce | AccelKind::Iosp0 => 80,
            AccelKind::Iosp4 => 96,
            AccelKind::Bvh
            | AccelKind::Qbvh
            | AccelKind::Bvh8
            | AccelKind::Grid
            | AccelKind::Iosp2 => 160,
            AccelKind::TwoLevel | AccelKind::Clusters => 192,
            AccelKind::IrregularGrid => 1024,
        };
        (triangles as u64)
            .saturating_mul(per_triangle)
            .saturating_add(64 << 10)
    }

    /// The name used in specs and reports.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Bvh => "bvh",
            AccelKind::Qbvh => "qbvh",
            AccelKind::Bvh8 => "bvh8",
            AccelKind::BruteForce => "brute-force",
            AccelKind::TwoLevel => "two-level",
            AccelKind::Clusters => "clusters",
            AccelKind::Grid => "grid",
            AccelKind::IrregularGrid => "irregular-grid",
            AccelKind::Iosp0 => "iosp0",
            AccelKind::Iosp4 => "iosp4",
            AccelKind::Iosp2 => "iosp2",
        }
    }
}

/// A structure and all its build and traversal options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelSpec {
    /// Which structure.
    pub kind: AccelKind,
    /// Build parameters of the binary BVH (the QBVH is collapsed from one).
    pub build: BuildParams,
    /// Traversal options of the wide BVHs (QBVH and BVH8).
    pub wide: WideOptions,
    /// Build subtrees on demand (QBVH only).
    pub lazy: bool,
    /// How a two-level structure's top level follows moving instances.
    pub top: crate::TopLevel,
    /// Clustering's threshold `t`: entry points are nodes smaller than the scene over `t`.
    pub cluster_t: f32,
    /// The uniform grid's parameters.
    pub grid: crate::UniformGridParams,
    /// The irregular grid's parameters.
    pub irregular: crate::IrregularGridParams,
}

/// Why a structure could not be built over the given triangles or scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// A grid's limits.
    #[error(transparent)]
    Grid(#[from] crate::GridError),
    /// An IOSP structure's limits.
    #[error(transparent)]
    Iosp(#[from] crate::IospError),
    /// The scene cannot be reordered.
    #[error(transparent)]
    Permute(#[from] rt_core::scene::PermuteError),
}

/// Why an accel spec was rejected.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SpecError {
    /// The text before the first `:` is not a structure.
    #[error(
        "unknown acceleration structure `{0}` (expected qbvh, bvh8, bvh, brute-force, two-level, clusters, grid, irregular-grid, iosp0, iosp4 or iosp2)"
    )]
    UnknownKind(String),
    /// An option this crate does not know.
    #[error("unknown option `{option}` of `{kind}` (see the options table in rt_accel::spec)")]
    UnknownOption {
        /// The structure.
        kind: &'static str,
        /// The option as written.
        option: String,
    },
    /// An option that does not apply to the structure.
    #[error("option `{option}` does not apply to `{kind}`")]
    NotApplicable {
        /// The structure.
        kind: &'static str,
        /// The option as written.
        option: String,
    },
    /// The text breaks the option grammar (a key given twice, a piece that is no option).
    #[error(transparent)]
    Options(#[from] rt_core::options::OptionsError),
    /// An option value that does not parse or is out of range.
    #[error("bad value in `{option}`: {reason}")]
    BadValue {
        /// The option as written.
        option: String,
        /// What is wrong with it.
        reason: &'static str,
    },
}

impl Default for AccelSpec {
    /// [`DEFAULT_ACCEL`], the structure `render` uses unless told otherwise.
    fn default() -> Self {
        DEFAULT_ACCEL.parse().expect("DEFAULT_ACCEL parses")
    }
}

impl AccelSpec {
    /// The structure for `scene` when the user names none: [`DEFAULT_ACCEL`], or `clusters`
    /// when instances move, since clustering only rebuilds its top level per frame (1.6–2.1×
    /// faster per frame than a `bvh8` rebuilt, `docs/benchmarks.md`) and places moving
    /// instances per ray for motion blur. Chosen by the scene, not by the frames rendered,
    /// so a frame rendered alone has the bytes it has in a sequence.
    pub fn default_for_scene(scene: &rt_core::Scene) -> Self {
        if scene.instances.iter().any(|i| i.is_animated()) {
            Self::new(AccelKind::Clusters)
        } else {
            Self::default()
        }
    }

    /// The default spec of `kind`.
    pub fn new(kind: AccelKind) -> Self {
        let mut build = BuildParams::default();
        if kind.is_wide() || kind.is_two_level() {
            build.max_leaf_size = crate::wide::DEFAULT_LEAF_SIZE;
            build.intersection_cost = crate::wide::DEFAULT_INTERSECTION_COST;
        }
        Self {
            kind,
            build,
            wide: match kind {
                // Two-level kinds' object BVHs are BVH8s: traversed like the flat one.
                AccelKind::Bvh8 | AccelKind::TwoLevel | AccelKind::Clusters => {
                    WideOptions::defaults_for::<crate::Node8>()
                }
                _ => WideOptions::default(),
            },
            lazy: false,
            top: crate::TopLevel::default(),
            cluster_t: DEFAULT_CLUSTER_T,
            grid: crate::UniformGridParams::default(),
            irregular: crate::IrregularGridParams::default(),
        }
    }

    /// Builds the structure over `input`: a scene (`&Scene`), a scene it may reorder
    /// ([`BuildInput::SceneToReorder`]) or bare triangles (`&[[Vec3; 3]]`); see
    /// [`BuildInput`] for what each means to the two-level and IOSP kinds.
    ///
    /// # Errors
    /// Why the structure cannot hold the input ([`BuildError`]): a grid or IOSP past its
    /// `u32` limits, or a scene that cannot be reordered.
    pub fn build<'a>(
        &self,
        input: impl Into<BuildInput<'a>>,
    ) -> Result<Box<dyn Accel>, BuildError> {
        match input.into() {
            BuildInput::Scene(scene) => self.build_over_scene(scene),
            BuildInput::SceneToReorder(scene) => self.build_reordering(scene),
            BuildInput::Triangles(triangles) => self.build_over_triangles(triangles),
        }
    }

    /// [`BuildInput::SceneToReorder`]: IOSP permutes the scene, the others build over it.
    fn build_reordering(&self, scene: &mut rt_core::Scene) -> Result<Box<dyn Accel>, BuildError> {
        // Each frame rewrites an instance's world copy in its contiguous range, which a
        // reordering would scatter: over an instanced scene IOSP keeps the order and answers
        // through its index map (4 bytes per triangle, counted in its memory).
        if !scene.instances.is_empty() {
            return self.build_over_scene(scene);
        }
        let (accel, perm): (Box<dyn Accel>, Vec<u32>) = match self.kind {
            AccelKind::Iosp0 => {
                let (a, p) = crate::Iosp0::build(&scene.triangles)?;
                (Box::new(a), p)
            }
            AccelKind::Iosp4 => {
                let (a, p) = crate::Iosp4::build(&scene.triangles)?;
                (Box::new(a), p)
            }
            AccelKind::Iosp2 => {
                let (a, p) = crate::Iosp2::build(&scene.triangles)?;
                (Box::new(a), p)
            }
            _ => return self.build_over_scene(scene),
        };
        scene.permute_triangles(&perm)?;
        Ok(accel)
    }

    /// [`BuildInput::Scene`]: two-level kinds from the prototypes and instances, the others
    /// over the flat triangles.
    fn build_over_scene(&self, scene: &rt_core::Scene) -> Result<Box<dyn Accel>, BuildError> {
        Ok(match self.kind {
            AccelKind::TwoLevel => Box::new(crate::TwoLevel::build(
                scene,
                &self.build,
                &self.wide,
                self.top,
            )),
            AccelKind::Clusters => Box::new(crate::TwoLevel::build_clustered(
                scene,
                &self.build,
                &self.wide,
                self.cluster_t,
            )),
            _ => self.build_over_triangles(&scene.triangles)?,
        })
    }

    /// [`BuildInput::Triangles`]. The IOSP kinds answer in the caller's order through an
    /// index map ([`crate::iosp::Unpermuted`], 4 bytes per triangle).
    fn build_over_triangles(&self, triangles: &[[Vec3; 3]]) -> Result<Box<dyn Accel>, BuildError> {
        use crate::iosp::Unpermuted;
        Ok(match self.kind {
            AccelKind::Iosp0 => {
                let (a, perm) = crate::Iosp0::build(triangles)?;
                Box::new(Unpermuted::new(a, perm))
            }
            AccelKind::Iosp4 => {
                let (a, perm) = crate::Iosp4::build(triangles)?;
                Box::new(Unpermuted::new(a, perm))
            }
            AccelKind::Iosp2 => {
                let (a, perm) = crate::Iosp2::build(triangles)?;
                Box::new(Unpermuted::new(a, perm))
            }
            AccelKind::Grid => Box::new(crate::UniformGrid::build(triangles, &self.grid)?),
            AccelKind::IrregularGrid => {
                Box::new(crate::IrregularGrid::build(triangles, &self.irregular)?)
            }
            AccelKind::TwoLevel | AccelKind::Clusters => Box::new(crate::TwoLevel::build_flat(
                triangles,
                &self.build,
                &self.wide,
                self.top,
                (self.kind == AccelKind::Clusters).then_some(self.cluster_t),
            )),
            AccelKind::Bvh => Box::new(Bvh2::build(triangles, &self.build)),
            AccelKind::Qbvh if self.lazy => {
                Box::new(crate::OnDemandQbvh::new(triangles, &self.build, &self.wide))
            }
            AccelKind::Qbvh => Box::new(Qbvh::build_with(triangles, &self.build, &self.wide)),
            AccelKind::Bvh8 => Box::new(Bvh8::build_with(triangles, &self.build, &self.wide)),
            AccelKind::BruteForce => Box::new(BruteForce::new(triangles)),
        })
    }

    /// Applies option `key` (given as `option`, with `value` after its `=`).
    fn apply(&mut self, key: &str, value: Option<&str>, option: &str) -> Result<(), SpecError> {
        let kind = self.kind.name();
        let bad = |reason| SpecError::BadValue {
            option: option.to_string(),
            reason,
        };
        let number = |lo: u32, hi: u32, reason| {
            value
                .and_then(|v| v.parse::<u32>().ok())
                .filter(|n| (lo..=hi).contains(n))
                .ok_or_else(|| bad(reason))
        };
        let flag = || match value {
            None => Ok(()),
            Some(_) => Err(bad("this option takes no value")),
        };
        let two_level = self.kind.is_two_level();
        let tree = self.kind == AccelKind::Bvh || self.kind.is_wide() || two_level;
        let wide = self.kind.is_wide() || two_level;
        let applies = match key {
            "leaf" | "bins" | "icost" | "evh" | "bbah" | "compact" => tree,
            "order" | "tstack" | "no-tstack" | "shadow-cache" | "isect" => wide,
            "lazy" => self.kind == AccelKind::Qbvh,
            "top" => self.kind == AccelKind::TwoLevel,
            "t" => self.kind == AccelKind::Clusters,
            "lambda" => self.kind == AccelKind::Grid,
            "depth" => self.kind == AccelKind::IrregularGrid,
            _ => {
                return Err(SpecError::UnknownOption {
                    kind,
                    option: option.to_string(),
                })
            }
        };
        if !applies {
            return Err(SpecError::NotApplicable {
                kind,
                option: option.to_string(),
            });
        }
        match key {
            "leaf" => {
                let hi = if wide {
                    crate::wide::MAX_LEAF_TRIANGLES as u32
                } else {
                    1 << 16
                };
                self.build.max_leaf_size = number(
                    1,
                    hi,
                    "leaf size must be 1 to 16 (qbvh, bvh8) or 65536 (bvh)",
                )? as usize;
            }
            "bins" => {
                self.build.bins =
                    number(2, crate::MAX_BINS as u32, "bins must be 2 to 64")? as usize
            }
            "icost" => {
                self.build.intersection_cost = value
                    .and_then(|v| v.parse::<f32>().ok())
                    .filter(|c| c.is_finite() && *c > 0.0 && *c <= 1e3)
                    .ok_or_else(|| bad("the cost must be a number in (0, 1000]"))?
            }
            "evh" => {
                self.build.split = Split::Evh {
                    t: number(0, 40, "the exponent must be 0 to 40")?,
                }
            }
            "bbah" => {
                self.build.split = Split::Bbah {
                    t: number(0, 40, "the exponent must be 0 to 40")?,
                }
            }
            "compact" => {
                flag()?;
                self.build.compact_leaves = true;
            }
            "order" => {
                self.wide.order = match value {
                    Some("unsorted") => Order::Unsorted,
                    Some("distance") => Order::Distance,
                    Some("split") => Order::SplitPlane,
                    _ => return Err(bad("expected unsorted, distance or split")),
                }
            }
            "tstack" | "no-tstack" => {
                flag()?;
                self.wide.t_stack = key == "tstack";
            }
            "shadow-cache" => {
                flag()?;
                self.wide.shadow_cache = true;
            }
            "isect" => {
                self.wide.intersection = match value {
                    Some("watertight") => TriangleTest::Watertight,
                    Some("subdivision") => TriangleTest::Subdivision,
                    Some("hybrid") => TriangleTest::Hybrid,
                    _ => return Err(bad("expected watertight, subdivision or hybrid")),
                }
            }
            "lazy" => {
                flag()?;
                self.lazy = true;
            }
            "lambda" => {
                self.grid.lambda = value
                    .and_then(|v| v.parse::<f32>().ok())
                    .filter(|l| l.is_finite() && *l > 0.0 && *l <= 1e3)
                    .ok_or_else(|| bad("lambda must be a number in (0, 1000]"))?
            }
            "depth" => self.irregular.max_depth = number(0, 10, "depth must be 0 to 10")?,
            "t" => {
                self.cluster_t = value
                    .and_then(|v| v.parse::<f32>().ok())
                    .filter(|t| t.is_finite() && *t > 0.0 && *t <= 1e6)
                    .ok_or_else(|| bad("t must be a number in (0, 1e6]"))?
            }
            "top" => {
                self.top = match value {
                    Some("rebuild") => crate::TopLevel::Rebuild,
                    Some("refit") => crate::TopLevel::Refit,
                    _ => return Err(bad("expected rebuild or refit")),
                }
            }
            _ => unreachable!("keys were checked above"),
        }
        Ok(())
    }
}

/// Every option of every kind, in the order they are applied.
const KEYS: [&str; 16] = [
    "leaf",
    "bins",
    "icost",
    "evh",
    "bbah",
    "compact",
    "order",
    "tstack",
    "no-tstack",
    "shadow-cache",
    "isect",
    "lazy",
    "top",
    "t",
    "lambda",
    "depth",
];

impl FromStr for AccelSpec {
    type Err = SpecError;

    /// Parses the spec in the one option grammar ([`rt_core::options`]): a key given twice
    /// is refused, and so is a key of no structure ([`SpecError::UnknownOption`]) or of
    /// another one ([`SpecError::NotApplicable`]).
    fn from_str(s: &str) -> Result<Self, SpecError> {
        let mut o = Options::parse(s)?;
        let name = o.kind().to_string();
        let kind = AccelKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or(SpecError::UnknownKind(name))?;
        let mut spec = AccelSpec::new(kind);
        if o.take("tstack").is_some() && o.take("no-tstack").is_some() {
            return Err(SpecError::BadValue {
                option: "tstack:no-tstack".into(),
                reason: "tstack and no-tstack contradict each other",
            });
        }
        for key in KEYS {
            let value = o.take(key);
            if let Some(value) = value {
                let value = value.map(str::to_string);
                let option = value
                    .as_ref()
                    .map_or(key.to_string(), |v| format!("{key}={v}"));
                spec.apply(key, value.as_deref(), &option)?;
            }
        }
        if let Some(key) = o.unread() {
            return Err(SpecError::UnknownOption {
                kind: kind.name(),
                option: key.to_string(),
            });
        }
        Ok(spec)
    }
}

impl fmt::Display for AccelSpec {
    /// The canonical text: the kind, then every option that differs from the kind's default.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let default = AccelSpec::new(self.kind);
        f.write_str(self.kind.name())?;
        let (b, d) = (&self.build, &default.build);
        if b.max_leaf_size != d.max_leaf_size {
            write!(f, ":leaf={}", b.max_leaf_size)?;
        }
        if b.bins != d.bins {
            write!(f, ":bins={}", b.bins)?;
        }
        if b.intersection_cost != d.intersection_cost {
            write!(f, ":icost={}", b.intersection_cost)?;
        }
        match b.split {
            Split::None => {}
            Split::Evh { t } => write!(f, ":evh={t}")?,
            Split::Bbah { t } => write!(f, ":bbah={t}")?,
        }
        if b.compact_leaves {
            f.write_str(":compact")?;
        }
        let (q, dq) = (&self.wide, &default.wide);
        if q.order != dq.order {
            let o = match q.order {
                Order::Unsorted => "unsorted",
                Order::Distance => "distance",
                Order::SplitPlane => "split",
            };
            write!(f, ":order={o}")?;
        }
        if q.t_stack != dq.t_stack {
            f.write_str(if q.t_stack { ":tstack" } else { ":no-tstack" })?;
        }
        if q.shadow_cache {
            f.write_str(":shadow-cache")?;
        }
        if q.intersection != dq.intersection {
            let i = match q.intersection {
                TriangleTest::Watertight => "watertight",
                TriangleTest::Subdivision => "subdivision",
                TriangleTest::Hybrid => "hybrid",
            };
            write!(f, ":isect={i}")?;
        }
        if self.lazy {
            f.write_str(":lazy")?;
        }
        if self.top != default.top {
            write!(f, ":top={}", self.top.name())?;
        }
        if self.cluster_t != default.cluster_t {
            write!(f, ":t={}", self.cluster_t)?;
        }
        if self.grid.lambda != default.grid.lambda {
            write!(f, ":lambda={}", self.grid.lambda)?;
        }
        if self.irregular.max_depth != default.irregular.max_depth {
            write!(f, ":depth={}", self.irregular.max_depth)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_spec_is_the_default_accel() {
        let d = AccelSpec::default();
        assert_eq!(d.kind, AccelKind::Bvh8);
        assert_eq!(d, AccelSpec::new(AccelKind::Bvh8));
        assert_eq!(d.to_string(), DEFAULT_ACCEL);
    }

    #[test]
    fn parses_and_prints_back() {
        for s in [
            "qbvh",
            "bvh",
            "brute-force",
            "qbvh:order=distance:tstack",
            "qbvh:evh=14:compact",
            "bvh:leaf=8:bbah=12",
            "qbvh:icost=0.5",
            "bvh:icost=0.3",
            "qbvh:leaf=8:order=unsorted:shadow-cache:isect=hybrid:lazy",
            "bvh8",
            "bvh8:leaf=8:evh=14:no-tstack:shadow-cache",
            "bvh8:order=split",
        ] {
            let spec: AccelSpec = s.parse().unwrap();
            assert_eq!(spec.to_string(), s);
        }
        let spec: AccelSpec = "qbvh:order=split:isect=watertight:no-tstack"
            .parse()
            .unwrap();
        assert_eq!(spec, AccelSpec::new(AccelKind::Qbvh));
        let spec: AccelSpec = "bvh8:tstack:order=distance".parse().unwrap();
        assert_eq!(spec, AccelSpec::new(AccelKind::Bvh8));
    }

    #[test]
    fn every_kind_displays_a_spec_that_parses_back_to_it() {
        for kind in AccelKind::ALL {
            let s = AccelSpec::new(kind);
            assert_eq!(s.to_string(), kind.name());
            assert_eq!(s.to_string().parse::<AccelSpec>(), Ok(s));
        }
        for text in [
            "two-level:top=refit:leaf=8",
            "clusters:t=16",
            "grid:lambda=2",
            "irregular-grid:depth=2",
        ] {
            let s: AccelSpec = text.parse().unwrap();
            assert_eq!(s.to_string().parse::<AccelSpec>(), Ok(s), "{text}");
        }
        // Either separator.
        let s: AccelSpec = "qbvh:evh=14,compact".parse().unwrap();
        assert_eq!(s.to_string(), "qbvh:evh=14:compact");
    }

    #[test]
    fn rejects_bad_specs() {
        let err = |s: &str| s.parse::<AccelSpec>().unwrap_err();
        assert!(matches!(err("kd"), SpecError::UnknownKind(_)));
        assert!(matches!(err("qbvh:fast"), SpecError::UnknownOption { .. }));
        assert!(matches!(err("bvh:tstack"), SpecError::NotApplicable { .. }));
        assert!(matches!(
            err("brute-force:leaf=2"),
            SpecError::NotApplicable { .. }
        ));
        assert!(matches!(err("qbvh:leaf=17"), SpecError::BadValue { .. }));
        assert!(matches!(err("qbvh:leaf=x"), SpecError::BadValue { .. }));
        assert!(matches!(
            err("qbvh:order=random"),
            SpecError::BadValue { .. }
        ));
        assert!(matches!(err("qbvh:tstack=1"), SpecError::BadValue { .. }));
        assert!(matches!(err("qbvh:evh"), SpecError::BadValue { .. }));
        assert!(matches!(err("bvh8:lazy"), SpecError::NotApplicable { .. }));
        assert!(matches!(err("bvh8:leaf=17"), SpecError::BadValue { .. }));
        assert!(err("qbvh:leaf=0").to_string().contains("leaf=0"));
        assert_eq!(
            err("qbvh:leaf=8:leaf=4").to_string(),
            "qbvh: option `leaf` given twice"
        );
        assert!(matches!(
            err("bvh8:tstack:no-tstack"),
            SpecError::BadValue { .. }
        ));
    }
}
