//! `rt-worldcache`: a world-space shading cache built on implicit progressive point sets
//! (M. Delaere, *Caching Shading Information in World Space using Implicit Progressive Low
//! Discrepancy Point Sets*, MSc thesis, Breda University of Applied Sciences, 2021), with the
//! fixed-grid hash of Binder et al. 2019 as the baseline at matched density.
//!
//! The pieces, in the order the thesis' passes use them:
//! - [`implicit`]: points of a virtual octree, 8 per voxel (one per octant), placed by hashing
//!   the voxel centre; never stored. [`grid`]: one point per cell centre of a fixed grid.
//!   Both implement the one seam, [`Discretisation`].
//! - [`select`]: the point a sample goes to: one of the three nearest with probability
//!   ∝ 1/d² (the thesis), the nearest, or the nearest to a tangent-jittered position (Binder).
//! - [`accumulate`]: a pass's samples summed per key in 64-bit fixed point with atomic adds,
//!   so sums do not depend on thread order; [`table`]: the persistent open-addressing table
//!   (24-byte entries: full 64-bit key, RGB, count) and the temporal merge with decay κ.
//! - [`reconstruct`]: world-space Shepard interpolation of the stored points near a position.
//! - [`WorldCache`] ties them together; [`CacheSpec`] (`worldspace[:options]`,
//!   `grid[:options]`) is the single place a cache is named and built.
//!
//! Keys are exact: a 64-bit packing of (point set, level, voxel, octant, normal bin), stored
//! whole in the table, so distinct points never share an entry ([`key`]).
//!
//! Depends on `rt-core` (shading frames), `glam` and `thiserror`; callers parallelise
//! (`record` and `lookup` take `&self` and are lock-free, `end_pass` takes `&mut self`).
//! What is reconstructed from the thesis' prose rather than read from its (lost) equations is
//! marked in each module. Design notes, tests and results: `docs/worldcache.md`.
//!
//! ```
//! use rt_worldcache::{CacheSpec, glam::Vec3};
//! let spec: CacheSpec = "worldspace:lod=4,kappa=0.9".parse().unwrap();
//! let mut cache = spec.build(16.0).unwrap();
//! let (p, n) = (Vec3::new(1.0, 0.0, 2.0), Vec3::Y);
//! assert!(cache.lookup(p, n).is_none());
//! for xi in 0..64u32 {
//!     cache.record(p, n, Vec3::splat(0.5), xi);
//! }
//! cache.end_pass();
//! let l = cache.lookup(p, n).unwrap();
//! assert!((l.value - Vec3::splat(0.5)).abs().max_element() < 1e-6);
//! ```
#![forbid(unsafe_code)]

pub mod accumulate;
mod cache;
pub mod discretisation;
pub mod grid;
pub mod hash;
pub mod implicit;
pub mod key;
pub mod reconstruct;
pub mod select;
pub mod spec;
pub mod table;

pub use cache::{AnyPoints, CacheParams, MergeStats, WorldCache};
pub use discretisation::{Connectivity, Discretisation};
pub use grid::FixedGrid;
pub use implicit::{Anchor, ImplicitPoints};
pub use key::Key;
pub use reconstruct::Lookup;
pub use select::Selection;
pub use spec::{CacheError, CacheKind, CacheSpec};
pub use table::{Entry, PersistentTable, TableFull, ENTRY_BYTES};

/// Re-export of the glam the cache uses.
pub use glam;
