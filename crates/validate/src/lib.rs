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

use rt_core::Scene;
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
    // Only the grids and IOSP have size limits ([`rt_accel::BuildError`]); a BVH8 holds any
    // scene, so this cannot fail.
    rt_accel::AccelSpec::default()
        .build(scene)
        .expect("the default BVH8 builds over any scene")
}

/// A bare mesh file as a scene ([`rt_scene::load_mesh`]), without its placeholder camera.
pub fn mesh_scene(path: &Path) -> Result<Scene, LoadError> {
    let mut scene = rt_scene::load_mesh(path)
        .map_err(|e| LoadError::new(path.display().to_string(), &e))?
        .scene;
    scene.cameras.clear();
    Ok(scene)
}

/// The view into a room-like scene that `render bench-accel --view inside` uses
/// ([`rt_scene::views::inside_view`]).
pub fn inside_camera(scene: &Scene, accel: &dyn rt_core::Accel) -> rt_core::Camera {
    let bounds = rt_core::Aabb::from_points(scene.triangles.iter().flatten());
    rt_scene::views::inside_view(&bounds, accel).0
}

/// The one seeded stream of the workspace's tests (`rt-testkit` re-exports it).
pub use rt_core::rng::SplitMix64 as Rng;
