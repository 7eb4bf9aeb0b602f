//! Benchmark ray sets and their `.bin` file format, shared by `render bench-accel` and
//! `tools/accel-peers` so that every tool traces exactly the same rays; [`anim`] measures
//! seconds per frame of an animated scene with them (`render bench-anim`).
//!
//! - [`generate`] makes the four sets from a scene, a camera and a reference structure:
//!   `primary` (one jittered camera ray per pixel), `incoherent` (a cosine-distributed diffuse
//!   bounce from each primary hit, as the path tracer spawns it), `shadow` (a segment from each
//!   primary hit to a point on a light, traced as an occlusion query over (0, 1)) and `uniform`
//!   ([`uniform`]: origins uniform in the scene's bounding box, directions uniform on the
//!   sphere).
//! - [`write_rays`] / [`read_rays`] store a set as six little-endian `f32` per ray (origin xyz,
//!   direction xyz); [`encode`] / [`decode`] do the same in memory. Reading never panics on a
//!   bad file: it returns a [`RayFileError`].
//!
//! Every random number is drawn from one generator, [`RayRng`], seeded by (seed, set, ray
//! index), so the sets do not depend on the thread count and any ray can be regenerated alone.
//!
//! ```
//! use rt_accel::bench::{decode, encode, uniform};
//! use rt_core::{glam::Vec3, Aabb};
//!
//! let bounds = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
//! let set = uniform(&bounds, 1000, 7);
//! assert_eq!(set.name, "uniform");
//! assert!(set.rays.iter().all(|r| bounds.contains(r.origin)));
//! assert!(set.rays.iter().all(|r| (r.dir.length() - 1.0).abs() < 1e-5));
//! // Deterministic: the same seed gives the same rays.
//! assert_eq!(uniform(&bounds, 1000, 7).rays, set.rays);
//!
//! let bytes = encode(&set.rays);
//! assert_eq!(bytes.len(), 24 * 1000);
//! assert_eq!(decode(&bytes).unwrap(), set.rays);
//! assert!(decode(&bytes[..100]).is_err()); // truncated: an error, not a panic
//! ```

pub mod anim;
mod file;
mod list;
pub mod measure;
mod rng;
mod sets;

pub use file::{
    decode, dump, encode, read_rays, read_set, write_rays, FormatError, RayFileError, RAY_BYTES,
};
pub use list::{contenders, ListError};
pub use rng::{ray_rng, RayRng};
pub use sets::{generate, uniform, Generated, Lights, Query, RaySet, SET_NAMES};
