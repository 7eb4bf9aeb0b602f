//! `rt-e2e`: cross-crate checks that need the whole pipeline (scene loading, BVH, integrators,
//! film): white-furnace tests, agreement of estimators, determinism. The helpers here build and
//! render small scenes; the tests themselves are in `tests/tests/`.

use rt_core::Scene;
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
