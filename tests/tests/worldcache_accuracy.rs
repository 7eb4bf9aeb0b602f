//! The world-space cache end to end agrees with the path tracer.
//!
//! A cached render ends a secondary path at a diffuse vertex with its throughput times the
//! cache's reflected radiance there: a Shepard-weighted mean of the records of the points
//! within the lookup radius, each point holding records from positions within about one voxel
//! edge of it. So a lookup at `p` is a weighted mean of unbiased estimates of the reflected
//! radiance `L_r(y)` at positions `|y − p| ≤ R` (`R` the lookup radius plus a voxel edge, on
//! surfaces of the same normal bin), and its bias is at most `R · max |∇L_r|`: the bias bound
//! the cache's resolution gives. The scene here is the interior white furnace, a closed box
//! whose every wall emits `L_e` and reflects with albedo `a` on both sides, where `L_r = a L`
//! is the same at every point and every direction, so the bound is zero and the cached image
//! must equal the path tracer's within noise (the truncation at `DEPTH` bounces, which the
//! cache's records mix over depths, is `a^DEPTH` ≈ 10⁻¹⁰ of `L`).
//!
//! Judged by the block z-test, the cached render's variance from independent runs (cache
//! lookups correlate pixels, so a film's per-pixel variance would understate a block's), the
//! path tracer's from its film. Control in the test: the same cache returning twice the
//! radiance it holds must fail.

use rt_core::glam::Vec3;
use rt_core::{Rgb, Scene};
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::{CachedPasses, CameraRays, PathIntegrator, RadianceCache, Technique};
use rt_testkit::stats::{compare_estimates, Comparison, Estimate, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};
use rt_worldcache::CacheSpec;
use std::sync::Arc;

const DEPTH: u32 = 32;
const SPP: u32 = 16;
const RUNS: u32 = 8;
const BLOCK: u32 = 4;

/// The interior furnace: walls of albedo 0.5 emitting 0.5 on both sides, so `L = 1`.
fn scene() -> Scene {
    scene_from_toml(
        r#"
[[camera]]
name = "c"
position = [0.0, 0.2, 0.8]
look_at = [0.3, -0.1, 0.0]
fov = 70.0
resolution = [16, 16]

[[material]]
name = "wall"
color = [0.5, 0.5, 0.5]
emission = [0.5, 0.5, 0.5]
two_sided = true

[[geometry]]
name = "room"
shape = "box"
min = [-1, -1, -1]
max = [1, 1, 1]
material = "wall"
"#,
    )
}

/// A cache that answers twice what it holds.
struct Doubled(Arc<dyn RadianceCache>);

impl RadianceCache for Doubled {
    fn lookup(&self, p: Vec3, n: Vec3) -> Option<Rgb> {
        self.0.lookup(p, n).map(|l| l * 2.0)
    }
    fn record(&self, p: Vec3, n: Vec3, value: Rgb, xi: u32) {
        self.0.record(p, n, value, xi);
    }
    fn end_pass(&self) {
        self.0.end_pass();
    }
}

/// A fresh cache `spec` over `scene`, wrapped by `wrap`.
fn cached(
    spec: &str,
    scene: &Scene,
    wrap: fn(Arc<dyn RadianceCache>) -> Arc<dyn RadianceCache>,
) -> Box<dyn Technique> {
    let spec: CacheSpec = spec.parse().unwrap();
    let cache = wrap(rt_session::worldcache::build(&spec, scene).unwrap());
    let path = PathIntegrator::new(DEPTH).with_cache(cache.clone());
    Box::new(CachedPasses::new(
        Box::new(CameraRays(Box::new(path))),
        cache,
    ))
}

fn cached_runs(
    spec: &str,
    scene: &Scene,
    wrap: fn(Arc<dyn RadianceCache>) -> Arc<dyn RadianceCache>,
) -> Estimate {
    let images: Vec<Vec<Rgb>> = (0..RUNS)
        .map(|k| {
            let t = cached(spec, scene, wrap);
            let (film, _) = Renderer::new(scene).threads(2).render_technique(
                t.as_ref(),
                FilmBuffers::for_outputs(AovSet::default()),
                SPP,
                500 + 131 * k,
            );
            film.mean_image()
        })
        .collect();
    Estimate::from_runs(&images)
}

/// The cached render of `spec` against the path tracer, and the same cache doubled.
fn agreement(spec: &str) -> (Comparison, Comparison) {
    let t = std::time::Instant::now();
    let scene = scene();
    let film = rt_testkit::render(&scene, &PathIntegrator::new(DEPTH), 256, 3);
    let path = Estimate {
        mean: film.mean_image(),
        variance: film.variance_image().unwrap(),
        runs: None,
    };
    let w = scene.cameras[0].width;
    let honest = cached_runs(spec, &scene, |c| c);
    let doubled = cached_runs(spec, &scene, |c| Arc::new(Doubled(c)));
    let judge = |e: &Estimate| -> Comparison { compare_estimates(e, &path, w, BLOCK, ALPHA) };
    let (h, d) = (judge(&honest), judge(&doubled));
    let mean = |v: &[Rgb]| v.iter().map(|c| c.x as f64).sum::<f64>() / v.len() as f64;
    eprintln!(
        "{spec}: path {:.4}, cached {:.4} {h:?}, doubled {:.4} {d:?}; {:.2?}",
        mean(&path.mean),
        mean(&honest.mean),
        mean(&doubled.mean),
        t.elapsed()
    );
    (h, d)
}

fn check(spec: &str) {
    let (h, d) = agreement(spec);
    assert!(
        h.same_within_noise(),
        "{spec}: the cached render is biased: {h:?}"
    );
    assert!(
        !d.same_within_noise(),
        "{spec}: a cache returning twice its radiance passes: {d:?}"
    );
}

#[test]
fn implicit_points_with_four_samples_agree_with_the_path_tracer() {
    check("worldspace:min-samples=4");
}

#[test]
fn the_fixed_grid_agrees_with_the_path_tracer() {
    check("grid");
}

/// The shipped default (`worldspace`, `min-samples=0`) is 1.0 % dark here (cached 0.9896
/// against 1.0010, image z −5.0 against 3.76 at 16 spp, 8 runs); with `min-samples=4` or the
/// fixed grid it agrees. Left ignored until the cause is found (docs/testing.md, issue 30).
#[test]
#[ignore = "known bias of the default implicit-point cache, under investigation"]
fn the_default_cache_agrees_with_the_path_tracer() {
    check("worldspace");
}
