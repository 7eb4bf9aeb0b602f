//! `rt-core`: the small, dependency-free (apart from glam) heart of the renderer.
//!
//! Everything the other crates share lives here: rays and boxes, watertight ray–triangle
//! intersection, robust ray-origin offsets, sampling routines and the low-discrepancy
//! [`Sampler`], colour helpers, cameras, the layered material model of Dammertz (2011, §2.3.4),
//! light sampling, and the runtime [`Scene`] that integrators read. The seams that later crates
//! plug into are defined here too: [`Accel`] (implemented by `rt-accel`) is the only thing an
//! integrator knows about ray queries.
//!
//! Dependency direction: `rt-core` depends on nothing of ours. `rt-accel`, `rt-film` and
//! `rt-scene` depend on it; `rt-integrators` on it and `rt-film`; the `render` CLI on all.
//!
//! ```
//! use rt_core::{Ray, triangle::{RayPrecomp, intersect_triangle}};
//! use glam::Vec3;
//! let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.0, 0.0, -1.0));
//! let pre = RayPrecomp::new(&ray);
//! let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
//! let hit = intersect_triangle(&pre, &tri, f32::INFINITY).unwrap();
//! assert!((hit.t - 1.0).abs() < 1e-6);
//! ```
#![forbid(unsafe_code)]

pub mod aabb;
pub mod accel;
pub mod animation;
pub mod bump;
pub mod camera;
pub mod color;
pub mod content_hash;
pub mod delta_light;
pub mod distribution;
pub mod emission;
pub mod environment;
pub mod frame;
pub mod image;
pub mod instance;
pub mod lights;
pub mod limits;
pub mod material;
pub mod microfacet;
pub mod options;
pub mod pixel_filter;
pub mod ray;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod shapes;
pub mod spectral;
pub mod stage_time;
pub mod texture;
pub mod tint;
pub mod transform;
pub mod triangle;

pub use aabb::Aabb;
pub use accel::{Accel, Hit, TraversalCounters};
pub use camera::Camera;
pub use color::Rgb;
pub use content_hash::ContentHash;
pub use image::{Image, PixelCountError, RgbImage};
pub use material::{Layer, Material};
pub use ray::Ray;
pub use sampler::{SampleKey, SampleStream, Sampler};
pub use scene::Scene;

/// Re-export so downstream crates use the same glam version as the core.
pub use glam;
