//! Times the graph cut alone on the synthetic scene (`scene/mod.rs`), for a few
//! [`CutOptions`], and reports each one's energy and the MSE of its fused composite, so a
//! faster but weaker setting shows its quality cost.
//!
//! Run with `cargo run --release -p rt-gree --example cut_bench [-- size [repeats]]`
//! (defaults: 512 and 3; the time is the best of the repeats).

mod scene;

use rt_core::rng::SplitMix64;
use rt_gree::fusion::fuse;
use rt_gree::graph_cut::{alpha_expansion, CutOptions, LabelProblem};
use rt_gree::{composite, GreeParams};
use scene::{mse, Renderer, Scene};
use std::time::Instant;

fn main() {
    let arg = |i: usize, default: usize| {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("number"))
    };
    let (size, repeats) = (arg(1, 512), arg(2, 3).max(1));
    let params = GreeParams::default();
    let scene = Scene::new(size, params.budget_split().n);
    let mut renderer = Renderer {
        truth: &scene.truth,
        rng: SplitMix64::new(2),
    };
    let out = composite(
        &scene.noisy,
        &scene.variance,
        &scene.bank,
        &mut renderer,
        &params,
    )
    .expect("GREE");
    let problem = LabelProblem::new(&scene.bank, &out.error_maps, params.lambda, params.metric);
    let argmin = problem.argmin();
    println!(
        "{size}x{size}, {} labels, argmin energy {:.6e}, argmin fused MSE {:.4e}",
        scene.bank.len(),
        problem.energy(&argmin),
        mse(&fuse(&scene.bank, &argmin, params.jacobi_iters), &scene.truth)
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
            },
        ),
    ];
    for (name, options) in variants {
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
