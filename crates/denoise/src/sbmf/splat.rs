//! SBMF step A's splat and blur (Bauszat thesis §4.2.2, Eqs. 4.1–4.2): every sample of pixel
//! `i` is splatted onto manifold `k` at `i` with weight `φ(η_k(i) − sg_m(i))`, colours and
//! weights summed and divided by the pixel's sample count `d_N(i)`; then both are blurred with
//! the domain transform's recursive filter, edge-aware along the manifold's own guide values
//! (so the blur does not cross the manifold's creases).
//!
//! Each manifold is independent: they run in parallel, each written to its own image.

use super::domain_transform::{distances, recursive_filter};
use super::guides::{phi, Guide};
use rayon::prelude::*;
use rt_film::SampleRecords;

/// Per pixel of one manifold: blurred splatted colour (RGB) and weight.
pub(crate) type Splat = [f32; 4];

/// The blurred splat images of every manifold.
pub(crate) fn splat_and_blur(
    records: &SampleRecords,
    guides: &[Guide],
    manifolds: &[Vec<Guide>],
    width: usize,
    sigma_s: f32,
) -> Vec<Vec<Splat>> {
    manifolds
        .par_iter()
        .map(|eta| {
            let mut img: Vec<Splat> = eta
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let range = records.pixel_range(i);
                    let n = range.len();
                    let mut s = [0.0f32; 4];
                    for j in range {
                        let w = phi(e, &guides[j]);
                        let c = records.radiance()[j];
                        s[0] += w * c.x;
                        s[1] += w * c.y;
                        s[2] += w * c.z;
                        s[3] += w;
                    }
                    if n > 0 {
                        s.map(|v| v / n as f32)
                    } else {
                        s
                    }
                })
                .collect();
            // σ_s/σ_r with σ_r = 1: the guides are already in units of their σ.
            let d = distances(eta, width, sigma_s);
            recursive_filter(&mut img, width, sigma_s, Some(&d));
            img
        })
        .collect()
}
