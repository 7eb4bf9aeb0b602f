//! `rt-accel`: ray-query acceleration structures over the scene's triangles.
//!
//! Every structure here implements [`rt_core::Accel`], the only interface integrators use for
//! ray queries, so the renderer can switch structures without touching anything else:
//!
//! - [`Bvh2`]: a binary bounding volume hierarchy built with the binned surface area heuristic
//!   and traversed front to back with a robust slab test. Hits come from the watertight
//!   triangle test in `rt-core` and culling is conservative, so closed meshes have no cracks.
//! - [`Qbvh`]: a four-wide BVH collapsed from a [`Bvh2`], with 128-byte nodes whose child boxes
//!   are tested together (SSE2 on x86_64).
//! - [`BruteForce`]: tests every triangle; the reference the others are checked against.
//!
//! Later work adds the implicit IOSP BVH behind the same trait.
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
// Unsafe code is allowed only in the QBVH's SIMD kernels and its uninitialised traversal
// stacks, item by item, each with its safety argument.
#![deny(unsafe_code)]
#![deny(missing_docs)]

pub mod bench;
pub mod brute_force;
pub mod bvh2;
pub mod crack_free;
pub mod on_demand;
pub mod qbvh;
pub mod spec;
mod traversal;

pub use brute_force::BruteForce;
pub use bvh2::{BuildParams, Bvh2, BvhStats, Node, Split, MAX_BINS};
pub use on_demand::OnDemandQbvh;
pub use qbvh::{Bvh8, Node8, Order, QNode, Qbvh, QbvhOptions, TriangleTest, WideBvh, WideNode};
pub use spec::{AccelKind, AccelSpec, SpecError, DEFAULT_ACCEL};
