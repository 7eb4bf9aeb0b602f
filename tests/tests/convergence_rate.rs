//! The path tracer's mean squared error against a high-sample reference falls at least as fast
//! as 1/spp: the least-squares slope of log MSE against log spp is at most −1 plus a tolerance
//! derived from the estimator's own variance. Independent samples give exactly −1; our
//! Owen-scrambled Sobol' samples stratify the first dimensions of every path and can only do
//! better, so the test is one-sided (docs/experiments.md records the measured slopes).
//!
//! What would break it: samples that do not advance with the sample index, passes that repeat
//! samples, a film that mis-weights its samples, anything that leaves error behind that more
//! samples do not remove. Control, in the test: films whose samples repeat the first four
//! indices must fail.

use rt_core::{Rgb, SampleStream, Scene};
use rt_film::{AovSet, Film};
use rt_integrators::{PathIntegrator, SamplePass};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

/// Image side, reference samples, test sample counts.
const SIDE: u32 = 48;
const REFERENCE_SPP: u32 = 2048;
const TEST_SPP: [u32; 6] = [4, 8, 16, 32, 64, 128];

fn render(scene: &Scene, seed: u32, spp: u32, stream: SampleStream) -> Film {
    let renderer = Renderer::new(scene);
    let mut film = renderer.film(AovSet::default());
    let pass = SamplePass {
        indices: 0..spp,
        stream,
        pixels: None,
        centre_first: false,
    };
    renderer.render_pass(&PathIntegrator::new(4), &mut film, seed, &pass);
    film
}

/// Mean and sample standard deviation.
fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

/// The least-squares slope of log MSE against log spp over [`TEST_SPP`], and its tolerance.
struct Slope {
    slope: f64,
    se: f64,
    bias: f64,
    tolerance: f64,
    mse: Vec<f64>,
}

/// [`Slope`] of the films `film_at(seed, spp)` against the reference `r`, whose own error is
/// at most `floor_bound`.
fn measure(r: &[Rgb], floor_bound: f64, film_at: &dyn Fn(u32, u32) -> Film) -> Slope {
    // One point per sample count, each from its own seed, so the points are independent.
    let mut x = Vec::new();
    let mut y = Vec::new();
    let mut rel_se = Vec::new();
    let mut mse = Vec::new();
    for (k, &spp) in TEST_SPP.iter().enumerate() {
        let film = film_at(1 + k as u32, spp);
        // Per-pixel squared error summed over channels; pixels are independent, so MSE is a
        // mean of P independent terms and its relative standard error is
        // sd(e) / (sqrt(P) mean(e)), measured from the terms themselves (heavy tails included).
        let e: Vec<f64> = film
            .mean_image()
            .iter()
            .zip(r)
            .map(|(a, b)| {
                let d = *a - *b;
                (d.x * d.x + d.y * d.y + d.z * d.z) as f64
            })
            .collect();
        let (mean, sd) = mean_sd(&e);
        x.push((spp as f64).ln());
        y.push((mean / 3.0).ln());
        mse.push(mean / 3.0);
        // Delta method: sd(ln MSE) ≈ sd(MSE) / MSE.
        rel_se.push(sd / ((e.len() as f64).sqrt() * mean));
    }

    // Ordinary least squares: slope = Σ c_k y_k with c_k = (x_k − x̄) / Sxx.
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let c: Vec<f64> = x.iter().map(|v| (v - mx) / sxx).collect();
    let slope: f64 = c.iter().zip(&y).map(|(c, y)| c * y).sum();
    // Noise: the points are independent, so Var(slope) = Σ c_k² Var(y_k).
    let se = c
        .iter()
        .zip(&rel_se)
        .map(|(c, s)| (c * s).powi(2))
        .sum::<f64>()
        .sqrt();
    // Bias from the reference's error F (0 ≤ F ≤ floor_bound): every point measures
    // V_k + F instead of V_k, i.e. y_k = ln V_k + δ_k with 0 ≤ δ_k ≤ ln(1 + F / V_k). Adding
    // a positive δ_k raises the slope at most by the sum of c_k δ_k over the points with
    // c_k > 0 (the larger sample counts).
    let bias: f64 = c
        .iter()
        .zip(&mse)
        .filter(|(c, _)| **c > 0.0)
        .map(|(c, m)| c * (1.0 + floor_bound / (m - floor_bound).max(1e-300)).ln())
        .sum();
    // Four standard errors: a correct estimator fails with probability about 3e-5.
    let tolerance = 4.0 * se + bias;
    Slope {
        slope,
        se,
        bias,
        tolerance,
        mse,
    }
}

#[test]
fn path_tracer_mse_falls_at_least_as_fast_as_one_over_spp() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIDE, SIDE);
    // The reference is the average of two independent halves (two seeds of the reference
    // stream), so its own error can be measured rather than bounded: E[(r1 − r2)²] = 2 F_half
    // per value, and the average's error is F = F_half / 2 = E[(r1 − r2)²] / 4. (The film's
    // variance of the mean would overestimate it badly: stratified samples converge faster
    // than variance / N.)
    let r1 = render(&scene, 0, REFERENCE_SPP / 2, SampleStream::Reference).mean_image();
    let r2 = render(&scene, 1, REFERENCE_SPP / 2, SampleStream::Reference).mean_image();
    let r: Vec<_> = r1.iter().zip(&r2).map(|(a, b)| (*a + *b) * 0.5).collect();
    let f_terms: Vec<f64> = r1
        .iter()
        .zip(&r2)
        .map(|(a, b)| {
            let d = *a - *b;
            (d.x * d.x + d.y * d.y + d.z * d.z) as f64 / 12.0
        })
        .collect();
    let (f_mean, f_sd) = mean_sd(&f_terms);
    // An upper bound on F at four standard errors of its estimate.
    let floor_bound = f_mean + 4.0 * f_sd / (f_terms.len() as f64).sqrt();

    let Slope {
        slope,
        se,
        bias,
        tolerance,
        mse,
    } = measure(&r, floor_bound, &|seed, spp| {
        render(&scene, seed, spp, SampleStream::Render)
    });
    let points: Vec<String> = mse.iter().map(|m| format!("{m:.3e}")).collect();
    eprintln!(
        "MSE slope {slope:.3} (standard error {se:.3}, reference-noise bias at most {bias:.3}), \
         MSE {}, floor bound {floor_bound:.2e}",
        points.join(" ")
    );
    assert!(
        mse.iter().all(|&m| m > 2.0 * floor_bound),
        "the reference is too noisy for these sample counts"
    );
    assert!(
        slope <= -1.0 + tolerance,
        "MSE slope {slope:.3} is flatter than -1 + {tolerance:.3}"
    );
    // The tolerance must be tight enough to tell -1 from no convergence at all.
    assert!(
        tolerance < 0.5,
        "tolerance {tolerance:.3} too loose to mean anything"
    );
    // Control: samples that do not advance past the fourth (every film the first four sample
    // indices, repeated spp/4 times) leave their error behind, and must fail.
    let stuck = measure(&r, floor_bound, &|seed, spp| {
        let renderer = Renderer::new(&scene);
        let mut film = renderer.film(AovSet::default());
        for _ in 0..spp / 4 {
            let pass = SamplePass {
                indices: 0..4,
                stream: SampleStream::Render,
                pixels: None,
                centre_first: false,
            };
            renderer.render_pass(&PathIntegrator::new(4), &mut film, seed, &pass);
        }
        film
    });
    eprintln!("control (samples stuck at 4): MSE slope {:.3}", stuck.slope);
    assert!(
        stuck.slope > -1.0 + stuck.tolerance,
        "control: samples repeating the first four pass with slope {:.3} (tolerance {:.3})",
        stuck.slope,
        stuck.tolerance
    );
}
