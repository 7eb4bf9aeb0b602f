//! The separable Gaussian with border renormalisation: rows, then columns, each tap weight
//! divided by the sum of the weights that fall inside the image, so the kernel is cut at the
//! border instead of reading clamped or mirrored pixels, and a constant image stays constant up
//! to the edge.

use super::{window, STRIP_ROWS};
use rayon::prelude::*;
use std::ops::{Add, Mul};

/// A pixel type the separable filter averages: anything with a sum and a scale.
pub trait Pixel:
    Copy + Default + Send + Sync + Add<Output = Self> + Mul<f32, Output = Self>
{
}

impl<T> Pixel for T where T: Copy + Default + Send + Sync + Add<Output = T> + Mul<f32, Output = T> {}

/// Half of the taps of a Gaussian of standard deviation `sigma` (pixels) cut at `3 sigma`:
/// `weights[k]` is the weight at distance `k`, unnormalised (`weights[0] = 1`). `sigma = 0`
/// gives the single tap `[1]`.
pub fn gaussian_taps(sigma: f32) -> Vec<f32> {
    if sigma <= 0.0 {
        return vec![1.0];
    }
    let radius = (3.0 * sigma).ceil() as usize;
    let inv = -0.5 / (sigma * sigma);
    (0..=radius).map(|k| ((k * k) as f32 * inv).exp()).collect()
}

/// Convolves the `w × h` row-major image `src` with the symmetric kernel `taps` (half taps
/// from [`gaussian_taps`]) along rows and then columns, renormalising at the border.
pub fn convolve<T: Pixel>(src: &[T], w: usize, h: usize, taps: &[f32]) -> Vec<T> {
    assert_eq!(src.len(), w * h, "image size");
    if src.is_empty() {
        return Vec::new();
    }
    let r = taps.len() - 1;
    let mut tmp = vec![T::default(); w * h];
    tmp.par_chunks_mut(w)
        .zip(src.par_chunks(w))
        .for_each(|(out, row)| {
            for (x, o) in out.iter_mut().enumerate() {
                let (lo, hi) = window(x, r, w);
                let (mut sum, mut norm) = (T::default(), 0.0f32);
                for (k, &v) in row.iter().enumerate().take(hi + 1).skip(lo) {
                    let t = taps[k.abs_diff(x)];
                    sum = sum + v * t;
                    norm += t;
                }
                *o = sum * (1.0 / norm);
            }
        });
    let mut out = vec![T::default(); w * h];
    out.par_chunks_mut(w * STRIP_ROWS)
        .enumerate()
        .for_each(|(s, strip)| {
            for (i, orow) in strip.chunks_mut(w).enumerate() {
                let y = s * STRIP_ROWS + i;
                let (lo, hi) = window(y, r, h);
                let norm: f32 = (lo..=hi).map(|k| taps[k.abs_diff(y)]).sum();
                let scale = 1.0 / norm;
                orow.fill(T::default());
                for k in lo..=hi {
                    let t = taps[k.abs_diff(y)] * scale;
                    for (o, &v) in orow.iter_mut().zip(&tmp[k * w..(k + 1) * w]) {
                        *o = *o + v * t;
                    }
                }
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_reach_three_sigma_and_zero_sigma_is_identity() {
        let t = gaussian_taps(2.0);
        assert_eq!(t.len(), 7);
        assert!((t[2] - (-0.5f32).exp()).abs() < 1e-6);
        let img: Vec<f32> = (0..12).map(|i| i as f32).collect();
        assert_eq!(convolve(&img, 4, 3, &gaussian_taps(0.0)), img);
    }

    #[test]
    fn constant_stays_constant_at_the_border_and_impulse_is_normalised() {
        let img = vec![3.5f32; 7 * 5];
        for p in convolve(&img, 7, 5, &gaussian_taps(4.0)) {
            assert!((p - 3.5).abs() < 3.5e-6, "{p}");
        }
        let mut img = vec![0.0f32; 21 * 21];
        img[10 * 21 + 10] = 1.0;
        let out = convolve(&img, 21, 21, &gaussian_taps(1.5));
        let total: f32 = out.iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        assert!(out[10 * 21 + 11] < out[10 * 21 + 10]);
        assert!((out[10 * 21 + 11] - out[11 * 21 + 10]).abs() < 1e-7);
    }
}
