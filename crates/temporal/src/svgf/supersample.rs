//! Supersampling with guide rays (Bauszat et al. 2011, as Voorhuis 2018 §4.6 modifies it): at
//! more than one sample per pixel, sample 0 of each pixel (through its centre) is the *guide*
//! whose features the filter uses; every other sample is assigned to the most similar of the
//! guides of its own pixel and its four neighbours, *before* filtering, and each guide's input
//! is the mean of its own and its assigned samples (Eq. 7). After filtering, every sample takes
//! its guide's filtered illumination times its own albedo, and a pixel is the mean of its
//! samples: sharp anti-aliased edges and textures without TAA, and less input noise.
//!
//! Readings (\[ours\]; the thesis leaves them open, seed 001 §2.6): similarity is the distance of
//! the first hits relative to the guide's depth plus `1 − n·n'`, and a sample whose best guide
//! scores above [`MAX_SCORE`] (it saw a surface no neighbouring guide saw) is not assigned and
//! keeps its own, unfiltered light; a sample is demodulated by its own albedo times the ratio of
//! its guide's demodulation albedo to the guide's albedo (a mirror guide's reflected albedo
//! carries over), after taking out the light its mirror guide's chain ends in, which the
//! sample takes back from the guide; samples that see the sky are never assigned.

use super::features::{without_emitted, Class, Features, MIN_ALBEDO};
use rayon::prelude::*;
use rt_core::glam::Vec3;
use rt_core::{Image, Rgb, RgbImage};
use rt_film::GuideBuffers;

/// Largest similarity score at which a sample is assigned to a guide.
pub const MAX_SCORE: f32 = 0.25;
/// No guide.
const NONE: u32 = u32::MAX;

/// One further sample of every pixel (sample index k ≥ 1), as a one-sample frame.
#[derive(Clone, Copy, Debug)]
pub struct ExtraSample<'a> {
    /// Light after one bounce.
    pub direct: &'a RgbImage,
    /// Light after more bounces.
    pub indirect: &'a RgbImage,
    /// Emitted light seen directly.
    pub emission: &'a RgbImage,
    /// First-hit albedo (zero where the sample saw no surface).
    pub albedo: &'a RgbImage,
    /// First-hit normal (zero where the sample saw no surface).
    pub normal: &'a Image<Vec3>,
    /// First-hit position.
    pub position: &'a Image<Vec3>,
}

/// Where every extra sample went: per layer and pixel, its guide and its demodulation albedo.
pub struct Gathered {
    guide: Vec<Vec<u32>>,
    albedo: Vec<Vec<Rgb>>,
}

/// The guide of pixel `p`'s sample in `layer`, and the albedo it is demodulated by.
fn choose(f: &Features, g: &GuideBuffers, layer: &ExtraSample<'_>, p: usize) -> (u32, Rgb) {
    let n_s = layer.normal.pixels()[p];
    if n_s == Vec3::ZERO {
        return (NONE, Rgb::ZERO);
    }
    let p_s = layer.position.pixels()[p];
    let (x, y) = (p % f.w, p / f.w);
    let mut best = (NONE, f32::INFINITY);
    let mut consider = |q: usize| {
        if f.class[q] == Class::Sky {
            return;
        }
        let depth = g.depth.pixels()[q].max(1e-3);
        let score =
            (p_s - g.position.pixels()[q]).length() / depth + (1.0 - n_s.dot(g.normal.pixels()[q]));
        if score < best.1 {
            best = (q as u32, score);
        }
    };
    consider(p);
    if x > 0 {
        consider(p - 1);
    }
    if x + 1 < f.w {
        consider(p + 1);
    }
    if y > 0 {
        consider(p - f.w);
    }
    if y + 1 < f.h {
        consider(p + f.w);
    }
    if best.1 > MAX_SCORE {
        return (NONE, Rgb::ZERO);
    }
    let q = best.0 as usize;
    let ratio = f.albedo[q] / g.albedo.pixels()[q].max(Rgb::splat(MIN_ALBEDO));
    let a = (layer.albedo.pixels()[p] * ratio).max(Rgb::splat(MIN_ALBEDO));
    (best.0, a)
}

/// Assigns every extra sample and replaces each guide's demodulated input (`current`) by the
/// mean of its own and its samples' (Eq. 7).
pub fn gather(
    f: &Features,
    g: &GuideBuffers,
    extra: &[ExtraSample<'_>],
    current: &mut [[Rgb; 2]],
) -> Gathered {
    let n = f.w * f.h;
    let mut sums: Vec<[Rgb; 2]> = current.to_vec();
    let mut counts = vec![1u32; n];
    let mut gathered = Gathered {
        guide: Vec::with_capacity(extra.len()),
        albedo: Vec::with_capacity(extra.len()),
    };
    for layer in extra {
        let (guide, albedo): (Vec<u32>, Vec<Rgb>) = (0..n)
            .into_par_iter()
            .map(|p| choose(f, g, layer, p))
            .unzip();
        // In pixel order, so the sums do not depend on the thread count.
        for p in 0..n {
            if guide[p] == NONE {
                continue;
            }
            let q = guide[p] as usize;
            let [direct, indirect] = without_emitted(
                layer.direct.pixels()[p],
                layer.indirect.pixels()[p],
                f.reflected_emission[q],
            );
            sums[q][0] += direct / albedo[p];
            sums[q][1] += indirect / albedo[p];
            counts[q] += 1;
        }
        gathered.guide.push(guide);
        gathered.albedo.push(albedo);
    }
    for (i, c) in current.iter_mut().enumerate() {
        if f.class[i] != Class::Sky {
            let k = counts[i] as f32;
            *c = [sums[i][0] / k, sums[i][1] / k];
        }
    }
    gathered
}

/// The pixel means: `guide_out` (each guide's own remodulated value) and every extra sample,
/// remodulated from its guide's filtered illumination `shown`, or its own light where it was
/// not assigned.
pub fn resolve(
    f: &Features,
    extra: &[ExtraSample<'_>],
    gathered: &Gathered,
    shown: &[Rgb],
    guide_out: &mut [Rgb],
) {
    let samples = 1.0 + extra.len() as f32;
    guide_out.par_iter_mut().enumerate().for_each(|(p, out)| {
        let mut sum = *out;
        for (k, layer) in extra.iter().enumerate() {
            let e = layer.emission.pixels()[p];
            let q = gathered.guide[k][p];
            sum += if q == NONE {
                e + layer.direct.pixels()[p] + layer.indirect.pixels()[p]
            } else {
                let q = q as usize;
                e + f.reflected_emission[q] + gathered.albedo[k][p] * shown[q]
            };
        }
        let c = sum / samples;
        *out = if c.is_finite() {
            c.max(Rgb::ZERO)
        } else {
            Rgb::ZERO
        };
    });
}
