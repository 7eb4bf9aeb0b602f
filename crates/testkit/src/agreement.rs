//! What the agreement tests of techniques that splat (light tracing, BDPT, the partitioned
//! renderer) share: the path tracer's estimate with its per-pixel variance, the estimate of a
//! technique from independent runs (whose film knows no per-pixel variance), optionally
//! through the `DroppedShadowRays` control, and renders split into passes for the
//! determinism tests.

use crate::mutants::DroppedShadowRays;
use crate::stats::Estimate;
use crate::Renderer;
use rt_core::{SampleStream, Scene};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{PathIntegrator, SamplePass, Technique};

/// The path tracer's image of `scene` at `spp` (seed 7) and the variance of each pixel's mean.
pub fn path_reference(scene: &Scene, max_depth: u32, spp: u32) -> Estimate {
    let (film, _) = Renderer::new(scene).threads(2).render(
        &PathIntegrator::new(max_depth),
        FilmBuffers::from(AovSet::default()).with_variance(),
        spp,
        7,
    );
    Estimate {
        mean: film.mean_image(),
        variance: film.variance_image().expect("kept"),
    }
}

/// Mean and spread of `runs` renders of `technique` at `spp` (seeds 100, 101, ...), with a
/// fraction `dropped` of its occlusion queries answered "occluded" (0 for the honest run).
pub fn technique_estimate(
    scene: &Scene,
    technique: &dyn Technique,
    runs: u32,
    spp: u32,
    dropped: f64,
) -> Estimate {
    let plain = Renderer::new(scene).threads(2);
    let mutant = DroppedShadowRays {
        inner: plain.accel(),
        fraction: dropped,
    };
    let renderer = Renderer::new(scene).with_accel(&mutant).threads(2);
    let images: Vec<_> = (0..runs)
        .map(|seed| {
            let (film, _) =
                renderer.render_technique(technique, AovSet::default(), spp, 100 + seed);
            film.mean_image()
        })
        .collect();
    Estimate::from_runs(&images)
}

/// `technique` on `threads` threads with seed 3, in passes cut at the sample indices `cuts`
/// (`[0, 8]` is one pass, `[0, 3, 8]` two), into a film with half-buffers.
pub fn render_in_passes(
    scene: &Scene,
    technique: &dyn Technique,
    threads: usize,
    cuts: &[u32],
) -> Film {
    let r = Renderer::new(scene).threads(threads);
    let mut film = r.film(FilmBuffers::from(AovSet::default()).with_halves());
    for p in cuts.windows(2) {
        let pass = SamplePass {
            indices: p[0]..p[1],
            stream: SampleStream::Render,
            pixels: None,
        };
        r.technique_pass(technique, &mut film, 3, &pass);
    }
    film
}
