//! GREE on a synthetic 512x512 image with a bank of 8 box filters, timing each stage.
//!
//! The scene is in `scene/mod.rs`: a truth with flat regions, sharp edges and fine stripes, N
//! with noise that grows to the right, and a cache "renderer" with independent noise.
//!
//! Run with `cargo run --release -p rt-gree --example synthetic [-- size [lambda [kappa]]]`
//! (defaults: 512 and [`GreeParams::default`]'s λ and κ).

mod scene;

use rt_core::rng::SplitMix64;
use rt_gree::{composite, GreeParams};
use scene::{mse, Renderer, Scene, RADII};
use std::time::Instant;

fn main() {
    let size: usize = std::env::args()
        .nth(1)
        .map_or(512, |s| s.parse().expect("size"));
    let arg = |i: usize, default: f32| {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("number"))
    };
    let defaults = GreeParams::default();
    let params = GreeParams {
        lambda: arg(2, defaults.lambda),
        kappa: arg(3, defaults.kappa),
        ..defaults
    };
    let budget = params.budget_split();
    let Scene {
        truth,
        noisy,
        variance,
        bank,
    } = Scene::new(size, budget.n);
    let radii = RADII;

    let mut renderer = Renderer {
        truth: &truth,
        rng: SplitMix64::new(2),
    };
    let t = Instant::now();
    let out = composite(&noisy, &variance, &bank, &mut renderer, &params).expect("GREE");
    let wall = t.elapsed();

    println!(
        "{size}x{size}, {} filters, n = {} spp, c = {} spp, {} caches ({} cache samples)",
        bank.len(),
        budget.n,
        budget.c,
        out.caches.len(),
        out.samples_traced
    );
    for (r, f) in radii.iter().zip(&bank) {
        println!("  box r = {r:>2}: MSE {:.3e}", mse(f, &truth));
    }
    println!("  argmin      : MSE {:.3e}", mse(&out.argmin_image, &truth));
    println!("  GREE        : MSE {:.3e}", mse(&out.image, &truth));
    println!(
        "  energy {:.4e} -> {:.4e} ({} sweeps, {} expansions accepted)",
        out.energy.0, out.energy.1, out.cut_moves.0, out.cut_moves.1
    );
    let t = out.timings;
    for (name, d) in [
        ("placement", t.placement),
        ("cache render", t.cache_render),
        ("errors", t.errors),
        ("interpolation", t.interpolation),
        ("graph cut", t.graph_cut),
        ("fusion", t.fusion),
    ] {
        println!("  {name:<14} {:>8.2} ms", d.as_secs_f64() * 1e3);
    }
    println!(
        "  {:<14} {:>8.2} ms (wall {:.2} ms)",
        "total",
        t.total().as_secs_f64() * 1e3,
        wall.as_secs_f64() * 1e3
    );
}
