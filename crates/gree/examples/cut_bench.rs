//! Times the graph cut alone on the synthetic scene (`scene/mod.rs`), for a few
//! [`CutOptions`], and reports each one's energy and the MSE of its fused composite, so a
//! faster but weaker setting shows its quality cost.
//!
//! Run with `cargo run --release -p rt-gree --example cut_bench [-- size [repeats
//! [variant]]]` (defaults: 512, 3 and all variants; the time is the best of the repeats).
//! The error maps are made as [`rt_gree::composite`] makes them, without its cut, so
//! `valgrind --tool=callgrind` on one variant minus the variant `none` counts the cut alone.

mod scene;

use rt_core::rng::SplitMix64;
use rt_gree::errors::sparse_errors;
use rt_gree::fusion::fuse;
use rt_gree::graph_cut::{alpha_expansion, CutOptions, LabelProblem};
use rt_gree::interpolate::Interpolator;
use rt_gree::placement::{place, PlacementParams};
use rt_gree::scale::mean_radiance;
use rt_gree::{CacheRenderer, GreeParams};
use scene::{mse, Renderer, Scene};
use std::time::Instant;

fn main() {
    let arg = |i: usize, default: usize| {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("number"))
    };
    let (size, repeats) = (arg(1, 512), arg(2, 3).max(1));
    let only = std::env::args().nth(3);
    let params = GreeParams::default();
    let budget = params.budget_split();
    let scene = Scene::new(size, budget.n);
    let mut renderer = Renderer {
        truth: &scene.truth,
        rng: SplitMix64::new(2),
    };
    let caches = place(
        &scene.bank,
        &scene.variance,
        &PlacementParams {
            count: budget.caches(size * size),
            kappa: params.kappa,
            sigma_r: params.sigma_r,
            mu: mean_radiance(&scene.bank),
            seed: params.seed,
        },
    );
    let Ok(values) = renderer.render_caches(&caches, budget.c);
    let sparse = sparse_errors(&scene.bank, &caches, &values, params.metric);
    let interp = Interpolator::new(size, size, &caches).expect("triangulation");
    let error_maps: Vec<Vec<f32>> = sparse.iter().map(|e| interp.apply(e)).collect();
    let problem = LabelProblem::new(&scene.bank, &error_maps, params.lambda, params.metric);
    let argmin = problem.argmin();
    println!(
        "{size}x{size}, {} labels, argmin energy {:.6e}, argmin fused MSE {:.4e}",
        scene.bank.len(),
        problem.energy(&argmin),
        mse(
            &fuse(&scene.bank, &argmin, params.jacobi_iters),
            &scene.truth
        )
    );
    let variants = [
        ("default", CutOptions::default()),
        (
            "1 sweep",
            CutOptions {
                max_sweeps: 1,
                ..CutOptions::default()
            },
        ),
        (
            "2 sweeps",
            CutOptions {
                max_sweeps: 2,
                ..CutOptions::default()
            },
        ),
        (
            "converged",
            CutOptions {
                max_sweeps: 50,
                tolerance: 0.0,
                ..CutOptions::default()
            },
        ),
        (
            "band 8",
            CutOptions {
                band: Some(8),
                ..CutOptions::default()
            },
        ),
        (
            "band 2",
            CutOptions {
                band: Some(2),
                ..CutOptions::default()
            },
        ),
        (
            "band 16",
            CutOptions {
                band: Some(16),
                ..CutOptions::default()
            },
        ),
    ];
    for (name, options) in variants {
        if only.as_ref().is_some_and(|o| o != name) {
            continue;
        }
        let mut best = f64::INFINITY;
        let mut cut = None;
        for _ in 0..repeats {
            let t = Instant::now();
            let c = alpha_expansion(&problem, argmin.clone(), &options);
            best = best.min(t.elapsed().as_secs_f64());
            cut = Some(c);
        }
        let cut = cut.expect("one repeat");
        let image = fuse(&scene.bank, &cut.labels, params.jacobi_iters);
        println!(
            "  {name:<10} {:>9.1} ms  energy {:.6e}  {} sweeps  {} accepted  MSE {:.4e}",
            best * 1e3,
            cut.energy,
            cut.sweeps,
            cut.accepted,
            mse(&image, &scene.truth)
        );
    }
}
