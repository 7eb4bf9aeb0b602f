//! `rt-testkit` (dev-only, `publish = false`): what the workspace's tests share instead of
//! copying it.
//!
//! - [`Rng`]: the one seeded pseudo-random stream (re-exported from `rt-validate`, whose stress
//!   cases use it too).
//! - [`Renderer`]: the one "build the acceleration structure, make a film, render" helper,
//!   with the shipped default structure; [`render`] for the common case.
//! - [`data`]: the shared test meshes in `../shared/data` (skip visibly, or fail under
//!   `RT_REQUIRE_DATA=1`); [`obj`]: a dependency-free OBJ reader for them.
//! - [`scene_from_toml`], [`shipped_scene`], [`mesh_scene`], [`furnace`]: test scenes.
//! - [`mutants`]: deliberately wrong renderers for control cases.
//! - [`stats`]: image statistics (means, standard errors, variance-weighted z-tests);
//!   [`chi2`]: the χ² goodness-of-fit test of sampling routines against their pdf.
//!
//! Depends on `rt-core`, `rt-film`, `rt-scene` and `rt-validate` (which brings the accel and
//! integrator crates). It is only ever a dev-dependency. `rt-core`'s, `rt-accel`'s and
//! `rt-scene`'s integration tests use it too: cargo allows that dev-dependency cycle, because an
//! integration test links the one library that testkit links (their unit tests do not use
//! testkit's scene types, which would be a second copy of the crate).
//!
//! ```
//! use rt_testkit::SceneExt;
//! let scene = rt_testkit::shipped_scene("cornell-box.toml").with_resolution(8, 8);
//! let film = rt_testkit::render(&scene, &rt_integrators::PathIntegrator::new(2), 4, 1);
//! assert!(rt_testkit::stats::image_mean(&film).0 > 0.0);
//! ```

#![forbid(unsafe_code)]

pub mod agreement;
pub mod chi2;
pub mod furnace;
pub mod mutants;
pub mod obj;
pub mod scenes;
pub mod stats;

pub use rt_validate::{data, default_accel, inside_camera, mesh_scene, Renderer, Rng};

use rt_core::Scene;
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::Integrator;
use std::path::{Path, PathBuf};

/// The workspace root (where `scenes/` is).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Loads a scene from TOML text (paths relative to the workspace's `scenes/`).
pub fn scene_from_toml(toml: &str) -> Scene {
    let base = workspace_root().join("scenes");
    match rt_scene::load_str(toml, &base, Path::new("test.toml")) {
        Ok(l) => l.scene,
        Err(e) => panic!("test scene does not load: {e}"),
    }
}

/// Loads `scenes/{name}` of the workspace.
pub fn shipped_scene(name: &str) -> Scene {
    let path = workspace_root().join("scenes").join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    scene_from_toml(&text)
}

/// A point, a spot and a directional light for the shipped Cornell box (millimetres), which
/// light it beside its own lamp: the delta-light agreement tests' set.
pub fn cornell_box_delta_lights() -> Vec<rt_core::delta_light::DeltaLight> {
    use rt_core::delta_light::DeltaLight;
    use rt_core::glam::Vec3;
    vec![
        DeltaLight::Point {
            position: Vec3::new(150.0, 400.0, 250.0),
            intensity: Vec3::new(3e4, 2e4, 1e4),
        },
        DeltaLight::Spot {
            position: Vec3::new(400.0, 500.0, 100.0),
            axis: Vec3::new(0.0, -1.0, 0.5).normalize(),
            intensity: Vec3::splat(5e4),
            cutoff: 0.5,
            beam_width: 0.3,
        },
        DeltaLight::Directional {
            direction: Vec3::new(0.2, -0.3, 1.0).normalize(),
            irradiance: Vec3::splat(0.5),
        },
    ]
}

/// Changing a test scene's first camera.
pub trait SceneExt {
    /// The scene with its first camera rendering `width × height` pixels (same view, lens
    /// and field of view).
    fn with_resolution(self, width: u32, height: u32) -> Scene;

    /// The scene with its first camera given a thin lens of radius `aperture` focused at
    /// `focus_distance` (same view, size and field of view).
    fn with_lens(self, aperture: f32, focus_distance: f32) -> Scene;
}

/// The first camera of `scene` rebuilt with the given size and lens.
fn first_camera_as(mut scene: Scene, size: (u32, u32), lens: (f32, f32)) -> Scene {
    let c = &scene.cameras[0];
    let near_clip = c.near_clip;
    scene.cameras[0] = rt_core::Camera::look_at(
        &c.name,
        c.position,
        // A target one unit ahead rounds back onto a camera far from the origin (a mutant
        // scene's camera at 4·10⁹ got a NaN view): step as far as the position's magnitude.
        c.position + c.forward * (1.0 + c.position.abs().max_element()),
        c.up,
        c.fov_y_deg,
        size.0,
        size.1,
        lens.0,
        lens.1,
    );
    scene.cameras[0].near_clip = near_clip;
    scene
}

impl SceneExt for Scene {
    fn with_resolution(self, width: u32, height: u32) -> Scene {
        let lens = (self.cameras[0].aperture, self.cameras[0].focus_distance);
        first_camera_as(self, (width, height), lens)
    }

    fn with_lens(self, aperture: f32, focus_distance: f32) -> Scene {
        let size = (self.cameras[0].width, self.cameras[0].height);
        first_camera_as(self, size, (aperture, focus_distance))
    }
}

/// Renders `scene`'s first camera with the default acceleration structure, `spp` samples and
/// `seed`, on two worker threads (CI's core count), into a film that keeps the variance (the
/// statistical tests read it).
pub fn render(scene: &Scene, integrator: &dyn Integrator, spp: u32, seed: u32) -> Film {
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_variance();
    Renderer::new(scene)
        .threads(2)
        .render(integrator, buffers, spp, seed)
        .0
}
