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
//! Judged by the block z-test and the whole image's z-test, the cached render's variances from
//! the spread of independent runs' block and image means, the path tracer's from its film. A
//! lookup reads records that many pixels read too, so a cached render's pixels are correlated
//! across the image: per-pixel spreads summed over a 4×4 block understate its variance 1.6×,
//! over the image 9× (the default cache, 1024 runs), and with them two sets of 8 honest runs
//! of the same cache differed at an image z of up to 6 (4 of 16 pairs failed), which the
//! per-pixel test once read as the default cache being 1 % dark. With block and image means,
//! `RUNS` runs resolve about 1 % of the default's image (its runs' image means spread by
//! 1.85 %). Controls in the tests: the same cache returning twice the radiance it holds, or
//! 0.95 of it (an image 0.6 % darker with `min-samples=4`, 1.7–1.8 % with the default and the
//! grid, where lookups feed more records), must fail.

use rt_core::glam::Vec3;
use rt_core::{Rgb, Scene};
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::{CachedPasses, CameraRays, PathIntegrator, RadianceCache, Technique};
use rt_testkit::agreement::{runs_against_reference, RunsAgreement};
use rt_testkit::stats::{Estimate, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};
use rt_worldcache::CacheSpec;
use std::sync::Arc;

const DEPTH: u32 = 32;
const SPP: u32 = 16;
const RUNS: u32 = 64;
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

/// A cache that answers a multiple of what it holds.
struct Scaled(Arc<dyn RadianceCache>, f32);

impl RadianceCache for Scaled {
    fn lookup(&self, p: Vec3, n: Vec3) -> Option<Rgb> {
        self.0.lookup(p, n).map(|l| l * self.1)
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
    runs: u32,
) -> Vec<Vec<Rgb>> {
    (0..runs)
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
        .collect()
}

/// The cached render of `spec` against the path tracer, and the same cache scaled by 2 and
/// by 0.95.
fn agreement(spec: &str) -> [RunsAgreement; 3] {
    let t = std::time::Instant::now();
    let scene = scene();
    let film = rt_testkit::render(&scene, &PathIntegrator::new(DEPTH), 256, 3);
    let path = Estimate {
        mean: film.mean_image(),
        variance: film.variance_image().unwrap(),
        runs: None,
    };
    let w = scene.cameras[0].width;
    let mean = |runs: &[Vec<Rgb>]| {
        let n = (runs.len() * runs[0].len()) as f64;
        runs.iter().flatten().map(|c| c.x as f64).sum::<f64>() / n
    };
    // The doubled cache is far off: a few runs show it.
    type Wrap = fn(Arc<dyn RadianceCache>) -> Arc<dyn RadianceCache>;
    let wraps: [(Wrap, u32); 3] = [
        (|c| c, RUNS),
        (|c| Arc::new(Scaled(c, 2.0)), 16),
        (|c| Arc::new(Scaled(c, 0.95)), RUNS),
    ];
    let mut line = format!("{spec}: path {:.4}", mean(std::slice::from_ref(&path.mean)));
    let verdicts = wraps.map(|(wrap, runs)| {
        let runs = cached_runs(spec, &scene, wrap, runs);
        let a = runs_against_reference(&runs, &path, w, BLOCK, ALPHA);
        line += &format!(
            "; {:.4}: image z {:.2} (tolerance {:.2}), block max |z| {:.2} (tolerance {:.2})",
            mean(&runs),
            a.image.image_z,
            a.image.image_crit,
            a.blocks.max_block_z,
            a.blocks.block_crit
        );
        a
    });
    eprintln!("{line}; {:.2?}", t.elapsed());
    verdicts
}

fn check(spec: &str) {
    let [honest, doubled, dimmed] = agreement(spec);
    assert!(
        honest.same_within_noise(),
        "{spec}: the cached render is biased: {honest:?}"
    );
    assert!(
        !doubled.same_within_noise(),
        "{spec}: a cache returning twice its radiance passes: {doubled:?}"
    );
    assert!(
        !dimmed.same_within_noise(),
        "{spec}: a cache returning 0.95 of its radiance passes: {dimmed:?}"
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

/// The shipped default (`worldspace`, `min-samples=0`). The per-pixel test of 8 runs once
/// failed it (0.9896 against 1.0010, image z −5.0): its pixels share single-record lookups,
/// so summed per-pixel spreads understated the image's variance 9×; over 1024 runs it and the
/// grid both averaged 0.998 (±0.0006), over 2048 runs at other seeds it averaged 1.0007
/// (±0.0004), and two sets of 8 of its honest runs failed that test against each other 4
/// times in 16 (docs/worldcache.md, issue 30).
#[test]
fn the_default_cache_agrees_with_the_path_tracer() {
    check("worldspace");
}
