//! A pixel filter applied by splatting (Mitsuba's way, `gaussian:splat`) against the same
//! filter applied by importance sampling (the default).
//!
//! What is equal in expectation: not the two estimators at a finite sample count. The
//! importance-sampled pixel is an unbiased estimate of `∫f(x − c)L(x)dx / ∫f`; the splatted
//! pixel is a ratio `Σ wᵢLᵢ / Σ wᵢ` of two unbiased sums, `E[Σ wᵢLᵢ] = N·∫_image f(x − c)L(x)dx`
//! and `E[Σ wᵢ] = N·∫_image f(x − c)dx`, so it converges (with a bias of order 1/N) to
//! the ratio of their expectations, which is the importance-sampled pixel's value wherever
//! the filter's support lies inside the image. Pixels within the filter's radius of the
//! border differ by construction (Mitsuba's edge pixels lose the weight of samples that would
//! lie outside the image; importance sampling traces those rays). So the test compares the
//! interior pixels of two converged images, with the statistic
//! `T = Σ(S − F)² / Σ(var S + var F)` (about 1 when both estimate the same image; the
//! variances are the importance-sampled film's variance of the mean and, for the splatted
//! film, which has no per-pixel variance, `(even half − odd half)²/4`).
//!
//! Controls: a splatted filter 40 % wider and the box filter, which see the same scene through
//! other filters, must give `T` far above the bound.
//!
//! Both path tracers feed the splatting film: the wavefront image is the scalar one, bit for
//! bit, for any thread count, batch size and split into passes, and so are sample ranges
//! carried as part bytes.

use rt_core::pixel_filter::PixelFilter;
use rt_core::{Rgb, Scene};
use rt_film::{AovSet, Film, FilmBuffers, Rect};
use rt_integrators::{CameraRays, PathIntegrator, SamplePass, Technique, Wavefront};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

const SIZE: u32 = 40;

fn scene_with(filter: &PixelFilter) -> Scene {
    let mut scene = shipped_scene("cornell-box.toml").with_resolution(SIZE, SIZE);
    scene.cameras[0].filter = filter.clone();
    scene
}

fn pass(indices: std::ops::Range<u32>) -> SamplePass {
    SamplePass::render(indices)
}

/// Renders `passes` of `technique` on `threads` threads into a film keeping `buffers`.
fn render(
    scene: &Scene,
    technique: &dyn Technique,
    buffers: FilmBuffers,
    passes: &[SamplePass],
    threads: usize,
) -> Film {
    let r = Renderer::new(scene).threads(threads);
    let mut film = r.film(buffers);
    for p in passes {
        r.technique_pass(technique, &mut film, 9, p);
    }
    film
}

fn path() -> CameraRays {
    CameraRays(Box::new(PathIntegrator::new(6)))
}

/// `T` over the pixels at least `border` pixels from the image's edge: the splatted film
/// `s` (with half-buffers) against the importance-sampled film `f` (with the variance).
fn statistic(s: &Film, f: &Film, border: u32) -> f64 {
    let (sm, h0, h1) = (
        s.mean_image(),
        s.half_image(0).expect("halves"),
        s.half_image(1).expect("halves"),
    );
    let (fm, fv) = (f.mean_image(), f.variance_image().expect("variance"));
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for y in border..SIZE - border {
        for x in border..SIZE - border {
            let i = (y * SIZE + x) as usize;
            for c in 0..3 {
                let d = f64::from(sm[i][c]) - f64::from(fm[i][c]);
                let half = f64::from(h0[i][c]) - f64::from(h1[i][c]);
                num += d * d;
                den += half * half / 4.0 + f64::from(fv[i][c]);
            }
        }
    }
    num / den
}

#[test]
fn splatting_converges_to_the_importance_sampled_image_inside_the_border() {
    let spp = 256;
    let fis = PixelFilter::gaussian(0.5);
    let splat = fis.clone().splatted();
    let variance = FilmBuffers::from(AovSet::default()).with_variance();
    let halves = FilmBuffers::from(AovSet::default()).with_halves();
    let f = render(&scene_with(&fis), &path(), variance, &[pass(0..spp)], 2);
    let wavefront = Wavefront::new(PathIntegrator::new(6), 256);
    let s = render(&scene_with(&splat), &wavefront, halves, &[pass(0..spp)], 2);
    // The Gaussian's support is 2 pixels: the interior starts 2 pixels in.
    let t = statistic(&s, &f, 2);
    // With a few thousand pixel channels (correlated between neighbours by the splats) the
    // statistic's spread is a few per cent; 1.5 leaves room for the variance estimates' own
    // error (the halves' is one degree of freedom per pixel).
    assert!(t < 1.5, "splatted vs importance-sampled Gaussian: T = {t}");
    // Controls: another filter's image is seen.
    for (name, other) in [
        (
            "a 40 % wider splatted Gaussian",
            PixelFilter::gaussian(0.7).splatted(),
        ),
        ("the box", PixelFilter::Box),
    ] {
        let c = match other.splats() {
            true => render(&scene_with(&other), &wavefront, halves, &[pass(0..spp)], 2),
            false => render(
                &scene_with(&other),
                &wavefront,
                variance,
                &[pass(0..spp)],
                2,
            ),
        };
        let t = if other.splats() {
            statistic(&c, &f, 3)
        } else {
            statistic(&s, &c, 3)
        };
        assert!(
            t > 5.0,
            "control {name}: T = {t} does not see the other filter"
        );
    }
}

/// The splatted image's bits: mean and both halves.
fn bits(film: &Film) -> Vec<u32> {
    let mut v = Vec::new();
    for img in [
        film.mean_image(),
        film.half_image(0).unwrap_or_default(),
        film.half_image(1).unwrap_or_default(),
    ] {
        v.extend(
            img.iter()
                .flat_map(|p: &Rgb| p.to_array().map(f32::to_bits)),
        );
    }
    v
}

#[test]
fn both_tracers_splat_the_same_bits_for_any_threads_batches_passes_and_parts() {
    let scene = scene_with(&PixelFilter::tent(1.5).splatted());
    let halves = FilmBuffers::from(AovSet::default()).with_halves();
    let want = render(&scene, &path(), halves, &[pass(0..6)], 1);
    assert!(want.has_filtered());
    let want_bits = bits(&want);
    for (lanes, threads, split) in [(1024, 2, 6), (7, 1, 2), (64, 2, 1)] {
        let w = Wavefront::new(PathIntegrator::new(6), lanes);
        let got = render(
            &scene,
            &w,
            halves,
            &[pass(0..split), pass(split..6)],
            threads,
        );
        assert!(
            bits(&got) == want_bits,
            "wavefront ({lanes} lanes, {threads} threads, passes split at {split}) differs from path"
        );
    }
    let got = render(&scene, &path(), halves, &[pass(0..4), pass(4..6)], 2);
    assert!(bits(&got) == want_bits, "path in two passes on two threads");
    // Sample ranges as part bytes, merged into a fresh film.
    let full = Rect::full(SIZE, SIZE);
    let mut merged = Film::new(SIZE, SIZE, halves);
    for r in [0..1, 1..6] {
        let part = render(&scene, &path(), halves, &[pass(r)], 2);
        merged
            .add_encoded(full, &part.encode_sums(full), true)
            .unwrap();
    }
    assert!(bits(&merged) == want_bits, "parts merged");
    // Control: another seed's image differs (the comparison sees one sample's change).
    let r = Renderer::new(&scene).threads(1);
    let mut other = r.film(halves);
    r.technique_pass(&path(), &mut other, 10, &pass(0..6));
    assert!(bits(&other) != want_bits);
}
