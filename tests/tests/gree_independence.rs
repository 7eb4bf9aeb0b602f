//! GREE through the real renderer draws its cache samples independently of the image's.
//!
//! `rt_session::render_gree` renders N at `n` spp from the render stream and the caches at
//! `c` spp through its own `Caches` renderer, which must use another stream
//! (`crates/gree/tests/independence.rs` shows why: caches correlated with N make the identity
//! filter look right). Here the bank is the identity (N itself) and a 3 × 3 box, on a smooth
//! lit floor where the box's bias is small, with `n = 7`, `c = 8` (budget 8, sparsity 0.1). For
//! a pixel of per-sample variance σ², the expected squared error the caches measure
//! (`crates/gree/src/errors.rs`) is, with independent caches, `σ²/n + σ²/c` for the identity and
//! about `σ²/(9n) + σ²/c` (plus the box's bias²) for the box, so the box wins at most pixels.
//! With caches that reuse the image's streams, N's `n` samples are the cache's first `n`, the
//! covariance `σ²/c` comes off twice, and the identity measures `σ²/n − σ²/c` (1/56 σ²) against
//! the box's `σ²/(9n) + (7/9) σ²/c` (0.113 σ²): the identity wins at most pixels. So the test:
//! the real run's labels (after the graph cut, what the composite uses) give under half of the
//! pixels to the identity; the control, GREE composited
//! in the test from the same N and bank with caches rendered by the same integrator from the
//! image's stream (`SampleStream::Render`, the seed of N), labels over half with it.

use rt_core::{Rgb, SampleStream};
use rt_denoise::Bank;
use rt_gree::{composite, CacheRenderer};
use rt_integrators::{render_pixels, Ctx, Integrator, PathIntegrator};
use rt_session::{render_gree, GreeSpec};
use rt_testkit::scene_from_toml;

const SEED: u32 = 21;

/// Caches from the image's own stream: the broken renderer.
struct ReusesTheImageStreams<'a> {
    ctx: &'a Ctx<'a>,
    integrator: &'a dyn Integrator,
}

impl CacheRenderer for ReusesTheImageStreams<'_> {
    type Error = std::convert::Infallible;
    fn render_caches(&mut self, pixels: &[(u32, u32)], spp: u32) -> Result<Vec<Rgb>, Self::Error> {
        let stream = SampleStream::Render;
        Ok(render_pixels(self.ctx, self.integrator, pixels, spp, SEED, stream).0)
    }
}

fn identity_share(labels: &[u16]) -> f64 {
    labels.iter().filter(|&&l| l == 0).count() as f64 / labels.len() as f64
}

#[test]
fn gree_caches_are_independent_of_the_image_samples() {
    let t = std::time::Instant::now();
    let scene = scene_from_toml(
        r#"
[[camera]]
name = "c"
position = [0.0, 1.5, 1.0]
look_at = [0.0, 0.0, -0.2]
fov = 35.0
resolution = [32, 24]

[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[material]]
name = "lamp"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-4, 0, 4], [4, 0, 4], [4, 0, -4], [-4, 0, -4]]
material = "white"

[[geometry]]
name = "light"
shape = "quad"
vertices = [[-0.4, 3, -0.4], [0.4, 3, -0.4], [0.4, 3, 0.4], [-0.4, 3, 0.4]]
material = "lamp"
"#,
    );
    let accel = rt_testkit::default_accel(&scene);
    let ctx = Ctx {
        scene: &scene,
        accel: accel.as_ref(),
        camera: &scene.cameras[0],
    };
    let integrator = PathIntegrator::new(4);
    let bank = Bank::from_specs(&["box:radius=0", "box:radius=1"]).unwrap();
    let params = "sparsity=0.1"
        .parse::<GreeSpec>()
        .unwrap()
        .params(8, SEED)
        .unwrap();
    let budget = params.budget_split();
    assert_eq!(
        (budget.n, budget.c),
        (7, 8),
        "the split the derivation assumes"
    );
    let run = render_gree(&ctx, &integrator, &bank, &params, SEED, &|_| {}).unwrap();
    let variance = run.frame.variance.clone().unwrap();
    let reused = composite(
        &run.frame.colour,
        &variance,
        &run.bank.images,
        &mut ReusesTheImageStreams {
            ctx: &ctx,
            integrator: &integrator,
        },
        &params,
    )
    .unwrap();
    let (honest, control) = (
        identity_share(&run.composite.labels),
        identity_share(&reused.labels),
    );
    eprintln!(
        "identity chosen at {honest:.3} of the pixels (real caches), {control:.3} (caches from the image's streams); per-pixel argmin before the cut {:.3}, {:.3}; {:.2?}",
        identity_share(&run.composite.argmin_labels),
        identity_share(&reused.argmin_labels),
        t.elapsed()
    );
    assert!(
        honest < 0.5,
        "the real caches favour the identity: {honest:.3}"
    );
    assert!(
        control > 0.5,
        "reused streams do not favour the identity: {control:.3}"
    );
}
