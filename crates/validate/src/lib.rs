//! `rt-validate`: numerical validation of the renderer, as a library that `render stress` and
//! the tests share (so the shipped binary depends on no test crate).
//!
//! - [`stress`]: the numerical stress suite (transformed scenes compared within noise,
//!   self-intersection counts, bad geometry and bad values), run with a small budget by
//!   `cargo test` and a large one by `render stress --long`.
//! - [`self_hit`]: counters of rays that hit the surface they leave.
//! - [`data`]: the one lookup of the shared test meshes (`../shared/data`), which skips
//!   visibly or, under `RT_REQUIRE_DATA=1`, fails.
//! - [`render::Renderer`]: the one "build the acceleration structure, make a film, render"
//!   helper, with the shipped default structure ([`rt_accel::AccelSpec::default`]).
//! - [`Rng`]: the one seeded pseudo-random stream of the validation cases and the tests.
//!
//! Depends on `rt-core`, `rt-accel`, `rt-film`, `rt-scene` and `rt-integrators` (and rayon for
//! thread pools); nothing depends on it but `rt-cli` and the tests. Errors are typed:
//! [`LoadError`] (a scene that does not load) and [`data::MissingData`].
//!
//! ```
//! use rt_validate::stress::{cases_named, Budget};
//! // Count false self-hits of rays leaving huge triangles, without the CLI.
//! let mut budget = Budget::ci();
//! budget.rays_per_surface = 2_000;
//! let report = cases_named("self-hit/huge-triangles")[0].run(&budget, 1);
//! assert!(report.passed(), "{report}");
//! ```

#![forbid(unsafe_code)]

pub mod data;
pub mod render;
pub mod self_hit;
pub mod stress;

pub use render::Renderer;

use rt_core::{glam::Vec3, Scene};
use std::path::Path;

/// A scene that did not load or generate.
#[derive(Debug, thiserror::Error)]
#[error("cannot load {what}: {message}")]
pub struct LoadError {
    /// Which scene.
    pub what: String,
    /// The loader's message.
    pub message: String,
}

impl LoadError {
    /// The error `e` of loading `what`.
    pub fn new(what: impl Into<String>, e: impl std::fmt::Display) -> Self {
        Self {
            what: what.into(),
            message: e.to_string(),
        }
    }
}

/// The acceleration structure `render` uses by default ([`rt_accel::AccelSpec::default`],
/// i.e. [`rt_accel::DEFAULT_ACCEL`]), built over `scene`'s triangles. Wide structures test
/// large triangles in leaves shared with others, where the binary BVH often culls them by a
/// flat box, so they also show false hits that the binary BVH would hide.
pub fn default_accel(scene: &Scene) -> Box<dyn rt_core::Accel> {
    rt_accel::AccelSpec::default().build(&scene.triangles)
}

/// A bare mesh file as a scene: one grey material, a white sky, no camera.
pub fn mesh_scene(path: &Path) -> Result<Scene, LoadError> {
    let err = |e: &dyn std::fmt::Display| LoadError::new(path.display().to_string(), e);
    let abs = std::fs::canonicalize(path).map_err(|e| err(&e))?;
    let text = abs.to_str().ok_or_else(|| err(&"the path is not UTF-8"))?;
    let toml = mesh_scene_toml(text);
    let base = abs.parent().unwrap_or(Path::new("/"));
    let mut scene = rt_scene::load_str(&toml, base, path)
        .map_err(|e| err(&e))?
        .scene;
    scene.cameras.clear();
    Ok(scene)
}

/// The TOML of a scene made of one mesh file (absolute path `file`): a white sky, one grey
/// material, a placeholder camera (callers replace it).
pub fn mesh_scene_toml(file: &str) -> String {
    let quoted = file.replace('\\', "\\\\").replace('"', "\\\"");
    format!(
        "[environment]\ncolor = [1, 1, 1]\n\n\
         [[camera]]\nname = \"auto\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n\n\
         [[material]]\nname = \"grey\"\n\n\
         [[geometry]]\nname = \"mesh\"\nfile = \"{quoted}\"\nmaterial = \"grey\"\n"
    )
}

/// A camera inside a room-like scene: from the middle of its bounds at 60 % of the height,
/// looking along the longer horizontal axis and a little down (the view `render bench-accel`
/// uses for rooms), 512 × 512.
pub fn inside_camera(scene: &Scene, accel: &dyn rt_core::Accel) -> rt_core::Camera {
    let b = rt_core::Aabb::from_points(scene.triangles.iter().flatten());
    let (lo, c, e) = (b.min, b.center(), b.extent());
    let axis = if e.x >= e.z { Vec3::X } else { Vec3::Z };
    let mid = Vec3::new(c.x, lo.y + 0.6 * e.y, c.z);
    let behind = accel
        .intersect(&rt_core::Ray::new(mid, -axis), f32::INFINITY)
        .map_or(0.5 * e.dot(axis), |h| h.t);
    let eye = mid - axis * (0.7 * behind);
    let target = Vec3::new(c.x, lo.y + 0.3 * e.y, c.z) + axis * (0.5 * behind);
    rt_core::Camera::look_at("inside", eye, target, Vec3::Y, 60.0, 512, 512, 0.0, 1.0)
}

/// The one seeded stream of the workspace's tests (`rt-testkit` re-exports it).
pub use rt_core::rng::SplitMix64 as Rng;
