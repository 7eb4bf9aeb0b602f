//! Progressive passes and reference streams (`rt_integrators::render_samples`): a render split
//! into passes is the same image, bit for bit, as one render; a reference stream with the same
//! seed is a different image of the same scene.

use rt_core::{SampleStream, Scene};
use rt_film::{AovSet, Film};
use rt_integrators::{PathIntegrator, SamplePass};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

fn cornell_24() -> Scene {
    shipped_scene("cornell-box.toml").with_resolution(24, 24)
}

/// Renders the passes one after the other into one film, on two threads.
fn render_passes(scene: &Scene, seed: u32, passes: &[SamplePass]) -> Film {
    let renderer = Renderer::new(scene).threads(2);
    // The variance buffer is kept: the independence test below weighs differences by it.
    let aovs = AovSet {
        variance: true,
        ..AovSet::default()
    };
    let mut film = renderer.film(aovs);
    let integrator = PathIntegrator::new(6);
    for pass in passes {
        let stats = renderer.render_pass(&integrator, &mut film, seed, pass);
        assert_eq!(stats.samples, 24 * 24 * pass.indices.len() as u64);
    }
    film
}

fn pass(indices: std::ops::Range<u32>, stream: SampleStream) -> SamplePass {
    SamplePass {
        indices,
        stream,
        pixels: None,
        centre_first: false,
    }
}

#[test]
fn passes_add_up_to_one_render_bit_for_bit() {
    let scene = cornell_24();
    let r = SampleStream::Render;
    let split = render_passes(&scene, 3, &[pass(0..1, r), pass(1..5, r), pass(5..16, r)]);
    let whole = render_passes(&scene, 3, &[pass(0..16, r)]);
    assert_eq!(split.mean_image(), whole.mean_image());
    assert_eq!(split.variance_image(), whole.variance_image());
    assert_eq!(split.half_image(1), whole.half_image(1));
    // And the plain driver entry point is the single pass 0..spp of the render stream.
    let (film, _) = Renderer::new(&scene).render(&PathIntegrator::new(6), AovSet::default(), 16, 3);
    assert_eq!(film.mean_image(), whole.mean_image());
}

#[test]
fn reference_stream_is_independent_of_the_render_stream_of_the_same_seed() {
    let scene = cornell_24();
    let normal = render_passes(&scene, 5, &[pass(0..8, SampleStream::Render)]);
    let again = render_passes(&scene, 5, &[pass(0..8, SampleStream::Render)]);
    let reference = render_passes(&scene, 5, &[pass(0..8, SampleStream::Reference)]);
    assert_eq!(normal.mean_image(), again.mean_image(), "not deterministic");
    // Independent estimates of the same image: they differ in (almost) every lit pixel, yet
    // agree on average. In one channel (channels of a pixel are correlated, pixels are not) the
    // difference of two independent pixel means has variance var_a + var_b, so the sum over
    // the 576 pixels must be within 4 standard deviations of 0.
    let a: Vec<_> = normal.pixels().collect();
    let b: Vec<_> = reference.pixels().collect();
    let differing = a.iter().zip(&b).filter(|(p, q)| p.mean() != q.mean());
    let lit = a.iter().filter(|p| p.mean().max_element() > 0.0).count();
    assert!(differing.count() * 10 >= lit * 9, "streams look shared");
    let mut diff = 0.0f64;
    let mut var = 0.0f64;
    for (p, q) in a.iter().zip(&b) {
        let var_of_mean = |p: &rt_film::PixelStats| p.variance_of_mean().expect("variance kept");
        let (d, v) = (p.mean() - q.mean(), var_of_mean(p) + var_of_mean(q));
        diff += d.y as f64;
        var += v.y as f64;
    }
    assert!(
        diff.abs() < 4.0 * var.sqrt(),
        "diff {diff}, sd {}",
        var.sqrt()
    );
}
