//! SBMF step B, the fast sweep-blur (Bauszat thesis §4.3.2, Eqs. 4.5–4.8): depth of field from
//! per-sample colours and signed circles of confusion, at a cost independent of the CoC.
//!
//! 1. **Splat.** Each sample goes to its two nearest layers ([`Layers::classify`]) with linear
//!    weights (energy-conserving), as RGBα with α = weight / `d_N(i)`, so α sums to 1 over the
//!    layers of a pixel with samples.
//! 2. **Blur and accumulate, front to back.** For layer `k` one summed-area table is built and
//!    every scale's box `B_f^k` read from it (four lookups each, whatever the radius). With
//!    the running coverage `cov_f` of each scale (the α the layers in front already spread
//!    with scale `f`), the layer contributes `A^k = Σ_f w_f·B_f^k`, the weights from
//!    [`layer_weights`] (Eqs. 4.5–4.6), and then adds `Bα_{f_k}^k·cw` to its own scale's
//!    coverage (Eq. 4.7, one running image per scale).
//! 3. **Normalise** by the accumulated α (Eq. 4.8). A pixel whose α is zero (no sample within
//!    any box around it) keeps the mean of its own samples' colours (zero without samples).
//!
//! Pixels are independent within a layer: rows run in parallel, each writing its own
//! accumulators, so the result is the same for any thread count.

use super::layers::{layer_weights, Layers, MAX_SCALES};
use super::sat::{Sat, LOOKUPS_PER_BOX};
use rayon::prelude::*;
use rt_core::{Image, Rgb, RgbImage};
use rt_film::SampleRecords;

/// What one sweep did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SweepStats {
    /// Summed-area-table lookups (four per box): the step's work, independent of `τ`.
    pub sat_lookups: u64,
    /// Layers used.
    pub layers: usize,
    /// CoC of the outermost layers in pixels (the samples' largest `|CoC|` unless set).
    pub tau: f32,
}

/// Sweeps samples of colours `colour` (one per record) into a `w × h` image.
pub(crate) fn sweep(
    records: &SampleRecords,
    colour: &[Rgb],
    w: usize,
    h: usize,
    layers: Layers,
) -> (RgbImage, SweepStats) {
    let n_l = layers.count();
    let scales = layers.n_f + 1;
    // 1. Splat: per pixel, per layer RGBα.
    let mut splat = vec![[0.0f32; 4]; w * h * n_l];
    splat
        .par_chunks_mut(n_l * w)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..w {
                let i = y * w + x;
                let range = records.pixel_range(i);
                let inv = 1.0 / range.len().max(1) as f32;
                for j in range {
                    let (k0, k1, t) = layers.classify(records.coc()[j]);
                    let c = colour[j];
                    for (k, wt) in [(k0, (1.0 - t) * inv), (k1, t * inv)] {
                        let p = &mut row[x * n_l + k];
                        p[0] += wt * c.x;
                        p[1] += wt * c.y;
                        p[2] += wt * c.z;
                        p[3] += wt;
                    }
                }
            }
        });
    // 2. Front to back.
    let half: Vec<usize> = (0..scales).map(|f| layers.half_width(f)).collect();
    let mut cov = vec![[0.0f32; MAX_SCALES]; w * h];
    let mut acc = vec![[0.0f64; 4]; w * h];
    let mut sat = Sat::new(w, h);
    let mut layer = vec![[0.0f32; 4]; w * h];
    let mut lookups = 0u64;
    for k in 0..n_l {
        for (i, p) in layer.iter_mut().enumerate() {
            *p = splat[i * n_l + k];
        }
        sat.build(&layer);
        let own = layers.scale(k);
        let (sat, layer, half) = (&sat, &layer, &half);
        lookups += cov
            .par_chunks_mut(w.max(1))
            .zip(acc.par_chunks_mut(w.max(1)))
            .enumerate()
            .map(|(y, (cov_row, acc_row))| {
                let mut n = 0u64;
                for x in 0..w {
                    let mut b = [[0.0f32; 4]; MAX_SCALES];
                    b[0] = layer[y * w + x];
                    for f in 1..scales {
                        b[f] = sat.box_mean(x, y, half[f]);
                        n += LOOKUPS_PER_BOX;
                    }
                    let wts = layer_weights(&cov_row[x], scales, own);
                    for f in 0..scales {
                        for c in 0..4 {
                            acc_row[x][c] += (wts[f] * b[f][c]) as f64;
                        }
                    }
                    cov_row[x][own] += b[own][3] * wts[own];
                }
                n
            })
            .sum::<u64>();
    }
    // 3. Normalise.
    let pixels = (0..w * h)
        .map(|i| {
            let a = acc[i];
            if a[3] > 1e-12 {
                let c = Rgb::new(a[0] as f32, a[1] as f32, a[2] as f32) / a[3] as f32;
                if c.is_finite() {
                    return c;
                }
            }
            let range = records.pixel_range(i);
            let n = range.len();
            if n == 0 {
                return Rgb::ZERO;
            }
            colour[range].iter().copied().sum::<Rgb>() / n as f32
        })
        .collect();
    let image = Image::new(w, h, pixels).unwrap_or_default();
    let stats = SweepStats {
        sat_lookups: lookups,
        layers: n_l,
        tau: layers.tau,
    };
    (image, stats)
}
