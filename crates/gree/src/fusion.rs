//! Gradient-domain (Poisson) fusion of the composite (thesis §5.1.4, "Gradient-Domain
//! Fusion"): a few Jacobi iterations of the Poisson equation, started from the
//! composite `u = F_L(p)(p)`, with Neumann boundaries (only neighbours inside the image).
//!
//! The guidance gradient of the edge p → q is `F_a(q) − F_a(p)` when both pixels carry label
//! `a`, and the average of `F_a(q) − F_a(p)` and `F_b(q) − F_b(p)` across a seam (`a = L(p)`,
//! `b = L(q)`; not in the thesis; the thesis does not say). One iteration is
//! `u'_p = u_p + (1/|N(p)|) Σ_q ((u_q − u_p) − g_pq)`: written as a correction, a pixel whose
//! neighbours all share its label and still hold the composite gets exactly zero correction,
//! so label interiors are bit-exact fixed points and only pixels within `iters` steps of a
//! seam move. Cache radiance is not used as a constraint (the thesis found it
//! counter-productive).

use rayon::prelude::*;
use rt_core::{Rgb, RgbImage};

/// The composite `F_L(p)(p)`.
///
/// # Panics
/// If `labels` is not one label per pixel of the bank's images or names a missing filter.
pub fn composite_image(bank: &[RgbImage], labels: &[u16]) -> RgbImage {
    let (w, h) = (bank[0].width(), bank[0].height());
    assert_eq!(labels.len(), w * h);
    let pixels = labels
        .iter()
        .enumerate()
        .map(|(p, &l)| bank[l as usize].pixels()[p])
        .collect();
    RgbImage::new(w, h, pixels).expect("size checked")
}

/// The guidance gradient of edge p → q.
#[inline]
fn guidance(bank: &[RgbImage], labels: &[u16], p: usize, q: usize) -> Rgb {
    let (a, b) = (labels[p] as usize, labels[q] as usize);
    let ga = bank[a].pixels()[q] - bank[a].pixels()[p];
    if a == b {
        ga
    } else {
        (ga + (bank[b].pixels()[q] - bank[b].pixels()[p])) * 0.5
    }
}

/// `iters` Jacobi iterations from the composite of `labels` (0 returns the composite).
/// Row-parallel, the same bits for any thread count.
///
/// # Panics
/// As [`composite_image`].
pub fn fuse(bank: &[RgbImage], labels: &[u16], iters: u32) -> RgbImage {
    let mut u = composite_image(bank, labels);
    let (w, h) = (u.width(), u.height());
    for _ in 0..iters {
        let old = u.pixels();
        let mut next = vec![Rgb::ZERO; w * h];
        next.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let p = y * w + x;
                let mut sum = Rgb::ZERO;
                let mut count = 0.0f32;
                let mut add = |q: usize| {
                    sum += (old[q] - old[p]) - guidance(bank, labels, p, q);
                    count += 1.0;
                };
                if x > 0 {
                    add(p - 1);
                }
                if x + 1 < w {
                    add(p + 1);
                }
                if y > 0 {
                    add(p - w);
                }
                if y + 1 < h {
                    add(p + w);
                }
                *out = if count > 0.0 {
                    old[p] + sum / count
                } else {
                    old[p]
                };
            }
        });
        u = RgbImage::new(w, h, next).expect("same size");
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::rng::SplitMix64;

    fn noise_image(w: usize, h: usize, seed: u64) -> RgbImage {
        let mut rng = SplitMix64::new(seed);
        RgbImage::from_fn(w, h, |_, _| {
            Rgb::new(rng.f32(), rng.f32() * 3.0, rng.f32() * 0.1)
        })
    }

    #[test]
    fn one_label_is_unchanged() {
        let bank = vec![noise_image(17, 11, 1), noise_image(17, 11, 2)];
        for l in 0..2u16 {
            let labels = vec![l; 17 * 11];
            assert_eq!(fuse(&bank, &labels, 5), bank[l as usize]);
        }
    }

    /// Four big label regions: pixels farther than `iters` (Manhattan) from any seam keep
    /// their composite value bit for bit, and some seam pixel moves.
    #[test]
    fn label_interiors_are_fixed_points() {
        let (w, h) = (40, 30);
        let bank: Vec<_> = (0..4).map(|s| noise_image(w, h, 10 + s)).collect();
        let label = |x: usize, y: usize| (usize::from(x >= 23) + 2 * usize::from(y >= 13)) as u16;
        let labels: Vec<u16> = (0..w * h).map(|p| label(p % w, p / w)).collect();
        let iters = 2;
        let comp = composite_image(&bank, &labels);
        let fused = fuse(&bank, &labels, iters);
        let mut moved = 0;
        for y in 0..h {
            for x in 0..w {
                // Distance to the nearest pixel with a differently labelled neighbour.
                let seam_dist = (x as i64 - 22)
                    .abs()
                    .min((x as i64 - 23).abs())
                    .min((y as i64 - 12).abs().min((y as i64 - 13).abs()));
                if seam_dist > iters as i64 {
                    assert_eq!(fused.pixel(x, y), comp.pixel(x, y), "({x}, {y})");
                } else if fused.pixel(x, y) != comp.pixel(x, y) {
                    moved += 1;
                }
            }
        }
        assert!(moved > 0, "seams must move");
    }

    /// One iteration by hand on a 3x1 image labelled [0, 1, 1]: the guidance of the seam edge
    /// is the average of both filters' gradients, inside label 1 it is filter 1's own.
    #[test]
    fn one_iteration_by_hand() {
        let f0 = RgbImage::new(
            3,
            1,
            vec![Rgb::splat(1.0), Rgb::splat(2.0), Rgb::splat(4.0)],
        )
        .unwrap();
        let f1 = RgbImage::new(
            3,
            1,
            vec![Rgb::splat(0.0), Rgb::splat(8.0), Rgb::splat(16.0)],
        )
        .unwrap();
        let labels = [0u16, 1, 1];
        let out = fuse(&[f0, f1], &labels, 1);
        // u = [1, 8, 16]. Seam edge 0 -> 1: g = ((2 − 1) + (8 − 0))/2 = 4.5; edge 1 -> 2: 8.
        // u0' = 1 + ((8 − 1) − 4.5) = 3.5
        // u1' = 8 + (((1 − 8) − (−4.5)) + ((16 − 8) − 8)) / 2 = 6.75
        // u2' = 16 + ((8 − 16) − (−8)) = 16
        assert_eq!(
            out.pixels(),
            &[Rgb::splat(3.5), Rgb::splat(6.75), Rgb::splat(16.0)]
        );
    }

    /// Across a seam between two filters that differ by a constant offset, the averaged
    /// guidance is each filter's own gradient, so the iteration pulls the two sides together.
    #[test]
    fn seams_are_smoothed() {
        let (w, h) = (16, 4);
        let base = noise_image(w, h, 3);
        let shifted = RgbImage::from_fn(w, h, |x, y| base.pixel(x, y) + Rgb::splat(1.0));
        let labels: Vec<u16> = (0..w * h).map(|p| u16::from(p % w >= 8)).collect();
        let bank = vec![base, shifted];
        let jump = |img: &RgbImage| -> f32 {
            (0..h)
                .map(|y| (img.pixel(8, y) - img.pixel(7, y)).abs().element_sum())
                .sum()
        };
        let before = jump(&composite_image(&bank, &labels));
        let after = jump(&fuse(&bank, &labels, 2));
        assert!(after < before, "{after} vs {before}");
    }
}
