//! `rt-accel`: ray-query acceleration structures over the scene's triangles.
//!
//! Every structure here implements [`rt_core::Accel`], the only interface integrators use for
//! ray queries, so the renderer can switch structures without touching anything else:
//!
//! - [`Bvh2`]: a binary bounding volume hierarchy built with the binned surface area heuristic
//!   and traversed front to back with a robust slab test. Hits come from the watertight
//!   triangle test in `rt-core` and culling is conservative, so closed meshes have no cracks.
//! - [`Bvh8`] (the default, [`DEFAULT_ACCEL`]) and [`Qbvh`]: eight- and four-wide BVHs collapsed
//!   from a [`Bvh2`] (module [`wide`]: one generic [`WideBvh`] over the node type), whose child
//!   boxes are tested together (AVX2 or SSE2, chosen at run time, with a portable fallback),
//!   with split-plane or distance child order, a shadow cache, EVH/BBAH triangle splitting and
//!   an on-demand variant ([`OnDemandQbvh`]).
//! - [`UniformGrid`] and [`IrregularGrid`] (module [`grid`]): the grid baselines of seed 002, a
//!   Cleary-resolution uniform grid walked by 3D-DDA and the irregular grid of Pérard-Gayot et
//!   al. 2017 (two-level grid, SAH merging, cell expansion, virtual-grid lookup).
//! - [`iosp`]: Implicit Object Space Partitioning (Eisemann, Bauszat et al., EGSR 2012): BVHs
//!   whose planes are rebuilt from triangles at known array positions. [`Iosp0`] stores
//!   nothing beyond the permuted triangles, [`Iosp4`] one word per node, [`Iosp2`] a SAH top
//!   over IOSP-0 leaves; each build returns the permutation the renderer must apply.
//! - [`crack_free`]: the crack-free intersection tests of Dammertz §3.4.
//! - [`BruteForce`]: tests every triangle; the reference the others are checked against.
//! - [`points`]: a balanced point kd-tree ([`PointKdTree`]) for photon maps and the caustic
//!   histogram's bins (k nearest, within a radius, nearest covering item); not an `Accel`.
//!
//! [`AccelSpec`] is the one dispatch point: it parses `bvh8:order=distance` and the like and
//! builds the structure. Later work adds the implicit IOSP BVH behind the same trait.
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
