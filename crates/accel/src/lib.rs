//! `rt-accel`: ray-query acceleration structures over the scene's triangles.
//!
//! Every structure here implements [`rt_core::Accel`], the only interface integrators use for
//! ray queries, so the renderer can switch structures without touching anything else. Where
//! each one lives (module, then file):
//!
//! - [`Bvh2`] (`bvh2/`): a binary bounding volume hierarchy built with the binned surface area
//!   heuristic (`bvh2/build.rs`) and traversed front to back with a robust slab test
//!   (`bvh2/traverse.rs`). Hits come from the watertight triangle test in `rt-core` and culling
//!   is conservative, so closed meshes have no cracks. Every tree structure starts from it,
//!   including its triangle splitting: the Edge Volume Heuristic and the Bounding Box Area
//!   Heuristic (`bvh2/evh_split.rs`, [`Split`]).
//! - [`Qbvh`] and [`Bvh8`] (the default, [`DEFAULT_ACCEL`]), module [`wide`]: four- and
//!   eight-wide BVHs collapsed from a [`Bvh2`] (`wide/collapse.rs`), one generic [`WideBvh`]
//!   over the node type: the QBVH's 128-byte [`QNode`] (`wide/qbvh_node.rs`), the BVH8's
//!   256-byte [`Node8`] (`wide/bvh8_node.rs`). Child boxes are tested together (AVX2 or SSE2,
//!   chosen at run time, with a portable fallback) in one traversal loop (`wide/traverse.rs`),
//!   with split-plane or distance child order, a shadow cache (`wide/shadow_cache.rs`), ray
//!   streams and packets (`wide/stream.rs`, `wide/packet.rs`).
//! - [`OnDemandQbvh`] (`on_demand/`): the QBVH built lazily, a subtree the first time a ray
//!   reaches it.
//! - [`TwoLevel`] (`two_level/`): per-object BVH8s under an eight-wide top level over the
//!   instances' placements (`two_level/top.rs`), rebuilt or refitted per frame ([`TopLevel`]);
//!   spec `two-level`. With rigid-body entry-point clustering (spec `clusters`,
//!   [`TwoLevel::build_clustered`]) the top level's entries are object nodes rather than whole
//!   objects.
//! - [`UniformGrid`] and [`IrregularGrid`] (module [`grid`]): the grid baselines of seed 002, a
//!   Cleary-resolution uniform grid walked by 3D-DDA and the irregular grid of Pérard-Gayot et
//!   al. 2017 (two-level grid, SAH merging, cell expansion, virtual-grid lookup).
//! - [`iosp`]: Implicit Object Space Partitioning (Eisemann, Bauszat et al., EGSR 2012): BVHs
//!   whose planes are rebuilt from triangles at known array positions. [`Iosp0`]
//!   (`iosp/iosp0.rs`) stores nothing beyond the permuted triangles, [`Iosp4`]
//!   (`iosp/iosp4.rs`) one word per node, [`Iosp2`] (`iosp/iosp2.rs`) a four-wide SAH top over
//!   IOSP-0 heaps; each build returns the permutation the renderer must apply.
//! - [`BruteForce`]: tests every triangle; the reference the others are checked against.
//! - [`crack_free`]: the crack-free intersection tests of Dammertz §3.4.
//! - [`points`]: a balanced point kd-tree ([`PointKdTree`]) for photon maps and the caustic
//!   histogram's bins (k nearest, within a radius, nearest covering item); not an `Accel`.
//!
//! [`AccelSpec`] is the one dispatch point: it parses `bvh8:order=distance` and the like and
//! builds the structure over a scene or triangles ([`AccelSpec::build`], [`BuildInput`]).
//! The traversals share their slab test, closest-hit rule and nearest-first stack
//! (`traversal/`); [`bench`](mod@bench) measures them on ray files.
//!
//! Depends on `rt-core` (rays, boxes, the triangle test and the `Accel` trait), `glam` for
//! vectors and `rayon` to build large subtrees in parallel.
//!
//! ```
//! use rt_accel::{BruteForce, BuildParams, Bvh2};
//! use rt_core::{glam::Vec3, Accel, Ray};
//!
//! let triangles = [
//!     [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//!     [Vec3::new(0.0, 0.0, 2.0), Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.0, 1.0, 2.0)],
//! ];
//! let bvh = Bvh2::build(&triangles, &BuildParams::default());
//! bvh.validate().unwrap();
//!
//! let ray = Ray::new(Vec3::new(0.25, 0.25, 5.0), Vec3::new(0.0, 0.0, -1.0));
//! let hit = bvh.intersect(&ray, f32::INFINITY).unwrap();
//! assert_eq!((hit.prim, hit.t), (1, 3.0));
//! assert!(!bvh.occluded(&ray, 2.5));
//! assert_eq!(BruteForce::new(&triangles).intersect(&ray, f32::INFINITY), Some(hit));
//! ```
//!
//! Build the default structure from a spec, as `render --accel` does:
//!
//! ```
//! use rt_accel::AccelSpec;
//! use rt_core::{glam::Vec3, Ray};
//! let triangles = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
//! let accel = AccelSpec::default().build(&triangles).expect("a bvh8 holds one triangle");
//! assert_eq!(accel.name(), "bvh8");
//! let hit = accel.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z), f32::INFINITY);
//! assert_eq!(hit.map(|h| h.t), Some(1.0));
//! ```
// Unsafe code is allowed only in the wide BVHs' SIMD kernels and its uninitialised traversal
// stacks, item by item, each with its safety argument.
#![deny(unsafe_code)]
#![deny(missing_docs)]

pub mod bench;
pub mod brute_force;
pub mod build_input;
pub mod bvh2;
pub mod crack_free;
pub mod grid;
pub mod iosp;
pub mod on_demand;
pub mod points;
pub mod spec;
mod traversal;
pub mod two_level;
pub mod wide;

pub use brute_force::BruteForce;
pub use build_input::BuildInput;
pub use grid::{GridError, IrregularGrid, IrregularGridParams, UniformGrid, UniformGridParams};

/// A structure that breaks one of its invariants (found by its `validate`, which the tests and
/// `bench-accel --check` run after every build).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("invalid {structure}: {problem}")]
pub struct ValidationError {
    /// The structure's name (`bvh`, `qbvh`, `bvh8`, ...).
    pub structure: String,
    /// The first broken invariant found.
    pub problem: String,
}
pub use bvh2::{BuildParams, Bvh2, BvhStats, Node, Split, MAX_BINS};
pub use iosp::{Iosp0, Iosp2, Iosp4, IospError};
pub use on_demand::OnDemandQbvh;
pub use points::PointKdTree;
pub use spec::{AccelKind, AccelSpec, BuildError, SpecError, DEFAULT_ACCEL};
pub use two_level::{TopLevel, TwoLevel};
pub use wide::{
    Bvh8, Node8, Order, QNode, Qbvh, TriangleTest, WideBvh, WideNode, WideOptions,
    FINE_LEAVES_MAX_TRIANGLES,
};
