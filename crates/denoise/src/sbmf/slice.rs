//! SBMF step A's slice (Bauszat thesis §4.2.2, Eqs. 4.3–4.4): each sample's filtered colour is
//! the `φ`-weighted sum over all manifolds of the blurred colours at its pixel over the
//! `φ`-weighted sum of the blurred weights, `φ` the sample's Gaussian weight to each manifold
//! (recomputed here rather than cached from the splat: 4 bytes per sample and manifold saved
//! for one 9-D distance each). Samples whose denominator is below `min_weight` take the
//! fallback colour of their pixel.
//!
//! Pixels (and so their samples) are independent: they run in parallel over rows.

use super::guides::{phi, Guide};
use super::splat::Splat;
use rayon::prelude::*;
use rt_core::Rgb;
use rt_film::SampleRecords;

/// The step-A colour of every sample, and how many took the fallback.
pub(crate) fn slice(
    records: &SampleRecords,
    guides: &[Guide],
    manifolds: &[Vec<Guide>],
    blurred: &[Vec<Splat>],
    fallback: &[Rgb],
    min_weight: f32,
) -> (Vec<Rgb>, usize) {
    let mut out = vec![Rgb::ZERO; records.len()];
    let pixels = records.offsets().len() - 1;
    // Chunks of whole pixels: split the output at pixel offsets.
    let chunk_pixels = 1024;
    let mut parts: Vec<(usize, &mut [Rgb])> = Vec::new();
    let mut rest = out.as_mut_slice();
    let mut p0 = 0;
    while p0 < pixels {
        let p1 = (p0 + chunk_pixels).min(pixels);
        let n = records.offsets()[p1] - records.offsets()[p0];
        let (a, b) = std::mem::take(&mut rest).split_at_mut(n);
        parts.push((p0, a));
        rest = b;
        p0 = p1;
    }
    let fallbacks: usize = parts
        .into_par_iter()
        .map(|(p0, part)| {
            let base = records.offsets()[p0];
            let mut fell = 0;
            for i in p0..(p0 + chunk_pixels).min(pixels) {
                for j in records.pixel_range(i) {
                    let g = &guides[j];
                    let (mut num, mut den) = (Rgb::ZERO, 0.0f32);
                    for (eta, b) in manifolds.iter().zip(blurred) {
                        let w = phi(&eta[i], g);
                        let s = &b[i];
                        num += w * Rgb::new(s[0], s[1], s[2]);
                        den += w * s[3];
                    }
                    part[j - base] = if den >= min_weight && (num / den).is_finite() {
                        num / den
                    } else {
                        fell += 1;
                        fallback[i]
                    };
                }
            }
            fell
        })
        .sum();
    (out, fallbacks)
}
