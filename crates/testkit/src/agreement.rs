//! What the agreement tests of techniques that splat (light tracing, BDPT, the partitioned
//! renderer) share: the path tracer's estimate with its per-pixel variance, the estimate of a
//! technique from independent runs (whose film knows no per-pixel variance), optionally
//! through the `DroppedShadowRays` control, and renders split into passes for the
//! determinism tests.

use crate::mutants::DroppedShadowRays;
use crate::stats::{compare_estimates, normal_equivalent, Comparison, Estimate};
use crate::Renderer;
use rt_core::{Rgb, SampleStream, Scene};
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
        runs: None,
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

/// Mean of each `block × block` block of a `width`-wide image, row-major (`width` a multiple
/// of `block`).
pub fn block_means(image: &[Rgb], width: u32, block: u32) -> Vec<Rgb> {
    let bw = width / block;
    let bh = image.len() as u32 / width / block;
    let mut out = vec![Rgb::ZERO; (bw * bh) as usize];
    let n = (block * block) as f32;
    for (i, p) in image.iter().enumerate() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        out[((y / block) * bw + x / block) as usize] += *p / n;
    }
    out
}

/// The path tracer's estimate at block scale: block means, and their variance as the sum of
/// the pixels' over the block's size squared (a path tracer's pixels are independent).
pub fn reference_blocks(pixels: &Estimate, width: u32, block: u32) -> Estimate {
    let n = (block * block) as f32;
    Estimate {
        mean: block_means(&pixels.mean, width, block),
        variance: block_means(&pixels.variance, width, block)
            .into_iter()
            .map(|v| v / n)
            .collect(),
        runs: pixels.runs,
    }
}

/// [`technique_estimate`] at block scale: the block means of `runs` renders, with the variance
/// from the spread of the runs' *block* means. Techniques that light many pixels from one
/// sample (VPLs, photons) have correlated neighbouring pixels, so the sum of per-pixel spreads
/// underestimates a block's variance (two sets of 8 partitioned runs of identical settings
/// differed at block z 8.3 that way, 2.1–2.5 by block means).
pub fn technique_blocks(
    scene: &Scene,
    technique: &dyn Technique,
    runs: u32,
    spp: u32,
    dropped: f64,
    block: u32,
) -> Estimate {
    let width = scene.cameras[0].width;
    let plain = Renderer::new(scene).threads(2);
    let mutant = DroppedShadowRays {
        inner: plain.accel(),
        fraction: dropped,
    };
    let renderer = Renderer::new(scene).with_accel(&mutant).threads(2);
    let blocks: Vec<_> = (0..runs)
        .map(|seed| {
            let (film, _) =
                renderer.render_technique(technique, AovSet::default(), spp, 100 + seed);
            block_means(&film.mean_image(), width, block)
        })
        .collect();
    Estimate::from_runs(&blocks)
}

/// How independent runs of a technique whose pixels share samples compare with a reference of
/// independent pixels: [`runs_against_reference`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunsAgreement {
    /// The block means (each block one "pixel"); only its block part is read.
    pub blocks: Comparison,
    /// The whole images' means; only its image part is read.
    pub image: Comparison,
}

impl RunsAgreement {
    /// True if neither a block nor the whole image differs by more than its tolerance (half
    /// the false-alarm rate each, as in `compare_estimates`).
    pub fn same_within_noise(&self) -> bool {
        self.blocks.max_block_z <= self.blocks.block_crit
            && self.image.image_z.abs() <= self.image.image_crit
    }
}

/// `runs` (independent images of a `width`-wide technique, `width` and height multiples of
/// `block`) against `reference` (per-pixel means and variances of independent pixels, e.g. a
/// path tracer's film), at the scale of `block × block` blocks and of the whole image, each
/// variance of the runs from the spread of the runs' block (image) means. Techniques whose
/// samples light many pixels (a world-space cache, VPLs) correlate pixels far apart: summing
/// per-pixel spreads understates a block's variance, and the whole image's even more (the
/// world cache's default: 1.6× per 4×4 block, 9× over a 16×16 image; two sets of 8 honest
/// runs then differed at an image z of up to 6).
pub fn runs_against_reference(
    runs: &[Vec<Rgb>],
    reference: &Estimate,
    width: u32,
    block: u32,
    alpha: f64,
) -> RunsAgreement {
    let of_runs = |means: &dyn Fn(&[Rgb]) -> Vec<Rgb>| {
        Estimate::from_runs(&runs.iter().map(|r| means(r)).collect::<Vec<_>>())
    };
    let blocks = compare_estimates(
        &of_runs(&|r| block_means(r, width, block)),
        &reference_blocks(reference, width, block),
        width / block,
        1,
        alpha,
    );
    let mean = |image: &[Rgb]| vec![image.iter().copied().sum::<Rgb>() / image.len() as f32];
    let n = reference.mean.len() as f32;
    let reference_image = Estimate {
        mean: mean(&reference.mean),
        // The mean of the variances over n: the variance of the mean of n independent pixels.
        variance: mean(&reference.variance)
            .into_iter()
            .map(|v| v / n)
            .collect(),
        runs: reference.runs,
    };
    let image = compare_estimates(&of_runs(&mean), &reference_image, 1, 1, alpha);
    RunsAgreement { blocks, image }
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
            centre_first: false,
        };
        r.technique_pass(technique, &mut film, 3, &pass);
    }
    film
}

/// How far two block estimates are apart beyond a known bias: the largest
/// `(|a − b| − allowed)⁺ / σ` over blocks and channels, `allowed` per block (absolute), on
/// the normal scale of `compare_estimates`' critical value (`crit`). For a consistent but
/// biased technique whose bias has a derived bound (the caustic histogram darkens the caustic
/// light near a surface's edge by at most a few per cent of a block): a z-test alone fails on
/// it once the noise is small enough, whatever else is right. Variances from runs count with
/// their Welch–Satterthwaite degrees of freedom, as in `compare_estimates`.
pub fn excess_z(a: &Estimate, b: &Estimate, allowed: &[Rgb]) -> f64 {
    assert_eq!(a.mean.len(), b.mean.len());
    assert_eq!(a.mean.len(), allowed.len());
    let welch = |v: f64, runs: Option<u32>| runs.map_or(0.0, |k| v * v / f64::from(k.max(2) - 1));
    let mut worst = 0.0f64;
    for (i, allowed) in allowed.iter().enumerate() {
        for c in 0..3 {
            let (ma, mb) = (f64::from(a.mean[i][c]), f64::from(b.mean[i][c]));
            let (va, vb) = (f64::from(a.variance[i][c]), f64::from(b.variance[i][c]));
            let v = va + vb;
            let excess = ((ma - mb).abs() - f64::from(allowed[c])).max(0.0);
            if excess > 0.0 {
                let nu = v * v / (welch(va, a.runs) + welch(vb, b.runs));
                let t = excess / v.sqrt().max(f64::MIN_POSITIVE);
                worst = worst.max(normal_equivalent(t, nu));
            }
        }
    }
    worst
}
