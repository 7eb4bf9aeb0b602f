//! `rt-e2e`: cross-crate checks that need the whole pipeline (scene loading, BVH, integrators,
//! film): white-furnace tests, agreement of estimators, determinism. The helpers here build and
//! render small scenes; the tests themselves are in `tests/tests/`. [`self_hit`] counts rays
//! that hit the surface they leave; [`stress`] holds the numerical stress cases, shared by
//! `tests/tests/stress.rs` (short) and `render stress` (long).

pub mod self_hit;
pub mod stress;

use rt_core::{glam::Vec3, Scene};
use rt_film::{AovSet, Film};
use rt_integrators::{Ctx, Integrator, RenderOptions};
use std::path::Path;

/// Loads a scene from TOML text (paths relative to the workspace's `scenes/`).
pub fn scene_from_toml(toml: &str) -> Scene {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    match rt_scene::load_str(toml, &base, Path::new("test.toml")) {
        Ok(l) => l.scene,
        Err(e) => panic!("test scene does not load: {e}"),
    }
}

/// Renders the first camera of `scene` with `spp` samples on `threads` worker threads. The film
/// keeps the variance buffer: the statistical tests read it.
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    spp: u32,
    seed: u32,
    threads: usize,
) -> Film {
    let accel = rt_accel::Bvh2::build(&scene.triangles, &rt_accel::BuildParams::default());
    let camera = &scene.cameras[0];
    let buffers = rt_film::FilmBuffers::for_outputs(AovSet::default()).with_variance();
    let mut film = Film::new(camera.width, camera.height, buffers);
    let ctx = Ctx {
        scene,
        accel: &accel,
        camera,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        rt_integrators::render(
            &ctx,
            integrator,
            &mut film,
            &RenderOptions { spp, seed },
            &|_| {},
        )
    });
    film
}

/// The variance of a pixel's mean from a film rendered by [`render`] (which keeps it).
pub fn variance_of_mean(p: &rt_film::PixelStats) -> rt_core::Rgb {
    p.variance_of_mean()
        .expect("render() keeps the variance buffer")
}

/// Mean over all pixels and channels and its standard error (from the per-pixel variances of
/// the mean; pixels are independent).
pub fn image_mean(film: &Film) -> (f64, f64) {
    let n = film.pixels().len() as f64 * 3.0;
    let mut sum = 0.0;
    let mut var = 0.0;
    for p in film.pixels() {
        let (m, v) = (p.mean(), variance_of_mean(&p));
        sum += (m.x + m.y + m.z) as f64;
        var += (v.x + v.y + v.z) as f64;
    }
    (sum / n, var.sqrt() / n)
}

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

/// The acceleration structure `render` uses by default (the QBVH). It tests large triangles in
/// leaves shared with others, where the binary BVH often culls them by a flat box, so it also
/// shows false hits that the BVH would hide.
pub fn default_accel(scene: &Scene) -> Box<dyn rt_core::Accel> {
    rt_accel::AccelSpec::new(rt_accel::AccelKind::Qbvh).build(&scene.triangles)
}

/// A bare mesh file as a scene: one grey material, a white sky, no camera.
pub fn mesh_scene(path: &Path) -> Result<Scene, LoadError> {
    let err = |e: &dyn std::fmt::Display| LoadError::new(path.display().to_string(), e);
    let abs = std::fs::canonicalize(path).map_err(|e| err(&e))?;
    let text = abs.to_str().ok_or_else(|| err(&"the path is not UTF-8"))?;
    let quoted = text.replace('\\', "\\\\").replace('"', "\\\"");
    let toml = format!(
        "[environment]\ncolor = [1, 1, 1]\n\n\
         [[camera]]\nname = \"auto\"\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n\n\
         [[material]]\nname = \"grey\"\n\n\
         [[geometry]]\nname = \"mesh\"\nfile = \"{quoted}\"\nmaterial = \"grey\"\n"
    );
    let base = abs.parent().unwrap_or(Path::new("/"));
    let mut scene = rt_scene::load_str(&toml, base, path)
        .map_err(|e| err(&e))?
        .scene;
    scene.cameras.clear();
    Ok(scene)
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

/// Deterministic pseudo-random numbers: SplitMix64.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A stream from `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x6a09_e667_f3bc_c909)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    /// Uniform in the cube [-1, 1)³.
    pub fn cube(&mut self) -> Vec3 {
        Vec3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
    }
}
