//! Light tracing estimates the path tracer's image where it can (no delta bounce seen by the
//! camera, no environment seen directly): on the Cornell box the two agree within noise by the
//! block z-test of `estimators_agree.rs`. The light tracer's film knows no per-pixel variance
//! (its splats land anywhere), so its variance comes from the spread of independent runs.
//!
//! Control: the light tracer with 2 % of its camera connections reported occluded (the
//! `DroppedShadowRays` mutant) must be caught. Also: bit-identical images for any thread count
//! and for a render split into passes.

use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{LightTracer, PathIntegrator, SamplePass};
use rt_testkit::mutants::DroppedShadowRays;
use rt_testkit::stats::{compare_estimates, Comparison, Estimate, ALPHA};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

const SIZE: u32 = 24;
const BLOCK: u32 = 4;
const DEPTH: u32 = 6;

fn light_estimate(scene: &rt_core::Scene, runs: u32, spp: u32, dropped: f64) -> Estimate {
    let renderer = Renderer::new(scene).threads(2);
    let mutant = DroppedShadowRays {
        inner: renderer.accel(),
        fraction: dropped,
    };
    let renderer = Renderer::new(scene).with_accel(&mutant).threads(2);
    let images: Vec<_> = (0..runs)
        .map(|seed| {
            let (film, _) = renderer.render_technique(
                &LightTracer::new(DEPTH),
                AovSet::default(),
                spp,
                100 + seed,
            );
            film.mean_image()
        })
        .collect();
    Estimate::from_runs(&images)
}

/// The light tracer (8 runs of 256 light paths per pixel) against the path tracer (2048 spp):
/// honestly and with 2 % of the connections dropped.
fn honest_and_biased(scene: &rt_core::Scene) -> (Comparison, Comparison) {
    let path = Renderer::new(scene).threads(2).render(
        &PathIntegrator::new(DEPTH),
        FilmBuffers::from(AovSet::default()).with_variance(),
        2048,
        7,
    );
    let reference = Estimate {
        mean: path.0.mean_image(),
        variance: path.0.variance_image().expect("kept"),
    };
    let test = |dropped| {
        let lt = light_estimate(scene, 8, 256, dropped);
        compare_estimates(&lt, &reference, SIZE, BLOCK, ALPHA)
    };
    let (honest, biased) = (test(0.0), test(0.02));
    eprintln!("honest {honest:?}\nbiased {biased:?}");
    (honest, biased)
}

#[test]
fn light_tracing_agrees_with_path_tracing_on_the_cornell_box() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    let (honest, biased) = honest_and_biased(&scene);
    assert!(
        honest.same_within_noise(),
        "light tracing disagrees: {honest:?}"
    );
    assert!(
        !biased.same_within_noise(),
        "control: 2 % of camera connections dropped passes: {biased:?}"
    );
}

/// Through a thin lens (blur circles of about 2.5 pixels on the front block and the back
/// wall), the connection samples the lens.
#[test]
fn light_tracing_agrees_with_path_tracing_through_a_thin_lens() {
    let scene = shipped_scene("cornell-box.toml")
        .with_resolution(SIZE, SIZE)
        .with_lens(150.0, 1100.0);
    let (honest, _) = honest_and_biased(&scene);
    assert!(
        honest.same_within_noise(),
        "light tracing disagrees: {honest:?}"
    );
}

#[test]
fn light_tracing_is_deterministic_across_threads_and_passes() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(20, 12);
    let lt = LightTracer::new(DEPTH);
    // Pass boundaries as sample-index cut points: [0, 8] is one pass, [0, 3, 8] two.
    let render = |threads, cuts: &[u32]| -> Film {
        let r = Renderer::new(&scene).threads(threads);
        let mut film = r.film(FilmBuffers::from(AovSet::default()).with_halves());
        for p in cuts.windows(2) {
            let pass = SamplePass {
                indices: p[0]..p[1],
                stream: rt_core::SampleStream::Render,
                pixels: None,
            };
            r.technique_pass(&lt, &mut film, 3, &pass);
        }
        film
    };
    let one = render(1, &[0, 8]);
    let three = render(3, &[0, 8]);
    let split = render(2, &[0, 3, 8]);
    assert_eq!(one.mean_image(), three.mean_image());
    assert_eq!(one.mean_image(), split.mean_image());
    assert_eq!(one.half_image(0), split.half_image(0));
    assert_eq!(one.light_paths(), 20 * 12 * 8);
    assert!(one.mean_image().iter().any(|p| p.max_element() > 0.0));
    assert_ne!(one.half_image(0), one.half_image(1));
}
