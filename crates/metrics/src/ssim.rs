//! Structural similarity (SSIM), after Wang, Bovik, Sheikh and Simoncelli 2004; the definition
//! and its choices are documented on [`ssim`].
//!
//! The Gaussian is separable, so the five moment images (μx, μy, E[x²], E[y²], E[xy]) are
//! blurred along rows, then along columns: 2·11 taps per pixel instead of 121. The image is
//! processed in bands of rows, each band on one worker with buffers allocated once per band, and
//! the per-band sums are added in band order, so the result does not depend on the thread count.

use crate::error::Result;
use crate::image::{validate_pair, RgbImage};
use crate::reduce::ordered_sum;
use rt_core::Rgb;

/// Side of the square window in pixels.
const WINDOW: usize = 11;
const RADIUS: usize = WINDOW / 2;
/// Standard deviation of the Gaussian window in pixels.
const SIGMA: f64 = 1.5;
/// Stabilising constant of the luminance term, (K1·L)² with K1 = 0.01, L = 1.
const C1: f64 = 0.01 * 0.01;
/// Stabilising constant of the contrast-structure term, (K2·L)² with K2 = 0.03, L = 1.
const C2: f64 = 0.03 * 0.03;

/// Output rows per band. Each band also blurs the `WINDOW − 1` source rows around it, so
/// larger bands waste less work; 64 rows keep that overhead near 15 % and the band buffers
/// (40 bytes per pixel of a row, times 74 rows) small.
const BAND: usize = 64;

/// Mean structural similarity of the test image and the reference: 1 for identical images,
/// lower the less alike they are; symmetric in its two arguments.
///
/// The definition is Wang, Bovik, Sheikh and Simoncelli, "Image quality assessment: from error
/// visibility to structural similarity", IEEE TIP 13(4), 2004, with the paper's parameters: an
/// 11×11 Gaussian window with σ = 1.5 (normalised to sum 1), K1 = 0.01, K2 = 0.03 and dynamic
/// range L = 1, so C1 = (K1·L)² = 1e-4 and C2 = (K2·L)² = 9e-4. At each window position, with
/// μ the weighted means, σ² the weighted variances and σxy the weighted covariance,
///
/// ```text
/// SSIM = (2·μx·μy + C1)·(2·σxy + C2) / ((μx² + μy² + C1)·(σx² + σy² + C2))
/// ```
///
/// Choices the paper leaves open, made deliberately:
/// - **Signal.** SSIM is defined on one channel. We use the Rec. 709 luminance
///   `0.2126·R + 0.7152·G + 0.0722·B` of the *linear* pixel values, each channel first clamped
///   to [0, 1] so that L = 1 is the true range. No tone curve is applied: the metric sees the
///   same linear data as MSE, so noise in dark regions weighs less than it would on a
///   display-encoded image.
/// - **Which windows.** The result is the mean over the window positions that lie entirely
///   inside the image, as in the authors' reference code (`filter2(..., 'valid')`) and in
///   scikit-image with `gaussian_weights=True`. Along a dimension shorter than 11 pixels there
///   is no such position; there the window is centred on every pixel and samples beyond the
///   edge repeat the edge pixel. Both rules agree wherever both apply.
/// - **Moments** are the weighted population moments, e.g. `σx² = E[x²] − μx²`, as in the
///   paper (not scikit-image's default sample covariance).
pub fn ssim(test: &RgbImage, reference: &RgbImage) -> Result<f64> {
    validate_pair(test, reference)?;
    Ok(mean_ssim_checked(test, reference))
}

/// [`ssim`] of a pair that [`validate_pair`] has accepted.
pub(crate) fn mean_ssim_checked(test: &RgbImage, reference: &RgbImage) -> f64 {
    mean_ssim(test, reference, BAND)
}

/// The normalised 1D Gaussian; the 2D window is its outer product with itself.
fn gaussian() -> [f64; WINDOW] {
    let mut w = [0.0; WINDOW];
    for (i, w) in w.iter_mut().enumerate() {
        let d = i as f64 - RADIUS as f64;
        *w = (-d * d / (2.0 * SIGMA * SIGMA)).exp();
    }
    let sum: f64 = w.iter().sum();
    w.map(|v| v / sum)
}

/// The centres of the windows averaged along a dimension of `n` pixels.
fn centres(n: usize) -> (usize, usize) {
    if n >= WINDOW {
        (RADIUS, n - RADIUS)
    } else {
        (0, n)
    }
}

#[inline]
fn luminance(p: Rgb) -> f64 {
    let c = |v: f32| f64::from(v.clamp(0.0, 1.0));
    0.2126 * c(p.x) + 0.7152 * c(p.y) + 0.0722 * c(p.z)
}

/// SSIM at one position from the window's moments `[μx, μy, E[x²], E[y²], E[xy]]`.
#[inline]
fn ssim_from_moments([mx, my, exx, eyy, exy]: [f64; 5]) -> f64 {
    let sxx = exx - mx * mx;
    let syy = eyy - my * my;
    let sxy = exy - mx * my;
    // C2 > 0 keeps the denominator positive even when cancellation leaves a variance at -1e-17.
    ((2.0 * mx * my + C1) * (2.0 * sxy + C2)) / ((mx * mx + my * my + C1) * (sxx + syy + C2))
}

/// Mean SSIM of a validated pair, in bands of `band` output rows.
fn mean_ssim(test: &RgbImage, reference: &RgbImage, band: usize) -> f64 {
    let weights = gaussian();
    let (x0, x1) = centres(test.width());
    let (y0, y1) = centres(test.height());
    let bands = (y1 - y0).div_ceil(band);
    let [total] = ordered_sum(bands, |i| {
        let b0 = y0 + i * band;
        let b1 = (b0 + band).min(y1);
        [band_sum(test, reference, &weights, (x0, x1), (b0, b1))]
    });
    total / ((x1 - x0) * (y1 - y0)) as f64
}

/// Sum of the SSIM map over output columns `x0..x1` of output rows `b0..b1`.
fn band_sum(
    test: &RgbImage,
    reference: &RgbImage,
    weights: &[f64; WINDOW],
    (x0, x1): (usize, usize),
    (b0, b1): (usize, usize),
) -> f64 {
    let (w, h) = (test.width(), test.height());
    let nx = x1 - x0;
    let source_rows = b1 - b0 + 2 * RADIUS;
    // Row-blurred moments of every source row the band's windows touch, for the output columns.
    let mut blurred = vec![[0.0f64; 5]; source_rows * nx];
    // One source row's luminances (test, reference), padded by RADIUS copies of the edge pixel
    // on each side so the tap loop needs no bounds logic.
    let mut padded = vec![[0.0f64; 2]; w + 2 * RADIUS];
    for j in 0..source_rows {
        let sy = (b0 + j).saturating_sub(RADIUS).min(h - 1);
        let (ra, rb) = (test.row(sy), reference.row(sy));
        for (i, l) in padded.iter_mut().enumerate() {
            let sx = i.saturating_sub(RADIUS).min(w - 1);
            *l = [luminance(ra[sx]), luminance(rb[sx])];
        }
        let out = &mut blurred[j * nx..(j + 1) * nx];
        for (k, o) in out.iter_mut().enumerate() {
            // Padded index p holds pixel p − RADIUS, so the window centred on pixel x starts at
            // padded index x.
            let x = x0 + k;
            let mut m = [0.0; 5];
            for (wt, &[a, b]) in weights.iter().zip(&padded[x..x + WINDOW]) {
                m[0] += wt * a;
                m[1] += wt * b;
                // Products of the signals first (`wt * (a * b)`, not `wt * a * b`): swapping the
                // images then gives the same bits (SSIM is symmetric), and identical images
                // give E[xy] = E[x²] = E[y²] bit for bit (SSIM exactly 1).
                m[2] += wt * (a * a);
                m[3] += wt * (b * b);
                m[4] += wt * (a * b);
            }
            *o = m;
        }
    }
    let mut sum = 0.0;
    for j in 0..b1 - b0 {
        // Output row b0 + j is centred on source row j + RADIUS of this band.
        let mut row = 0.0;
        for k in 0..nx {
            let mut m = [0.0; 5];
            for (t, wt) in weights.iter().enumerate() {
                let v = &blurred[(j + t) * nx + k];
                for q in 0..5 {
                    m[q] += wt * v[q];
                }
            }
            row += ssim_from_moments(m);
        }
        sum += row;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random value in [-1, 1) for index `i` (the workspace's test RNG,
    /// seeded by the index).
    fn noise(i: u64) -> f32 {
        rt_testkit::Rng::new(i).f32() * 2.0 - 1.0
    }

    fn smooth(w: usize, h: usize) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| {
            let v = 0.25 + 0.5 * (x as f32 / w as f32) * (y as f32 / h as f32);
            Rgb::new(v, 0.8 * v, 1.1 * v)
        })
    }

    fn noisy(base: &RgbImage, strength: f32, seed: u64) -> RgbImage {
        let w = base.width();
        RgbImage::from_fn(w, base.height(), |x, y| {
            let i = ((y * w + x) as u64) * 3 + seed * 1_000_003;
            base.pixel(x, y) + strength * Rgb::new(noise(i), noise(i + 1), noise(i + 2))
        })
    }

    /// The definition evaluated directly: a full 11×11 window per position, edge pixels
    /// repeated, averaged over the same positions.
    fn brute_force(a: &RgbImage, b: &RgbImage) -> f64 {
        let g = gaussian();
        let (w, h) = (a.width() as isize, a.height() as isize);
        let (x0, x1) = centres(a.width());
        let (y0, y1) = centres(a.height());
        let mut sum = 0.0;
        for y in y0..y1 {
            for x in x0..x1 {
                let mut m = [0.0; 5];
                for dy in -(RADIUS as isize)..=RADIUS as isize {
                    for dx in -(RADIUS as isize)..=RADIUS as isize {
                        let sx = (x as isize + dx).clamp(0, w - 1) as usize;
                        let sy = (y as isize + dy).clamp(0, h - 1) as usize;
                        let wt =
                            g[(dx + RADIUS as isize) as usize] * g[(dy + RADIUS as isize) as usize];
                        let (p, q) = (luminance(a.pixel(sx, sy)), luminance(b.pixel(sx, sy)));
                        m[0] += wt * p;
                        m[1] += wt * q;
                        m[2] += wt * p * p;
                        m[3] += wt * q * q;
                        m[4] += wt * p * q;
                    }
                }
                sum += ssim_from_moments(m);
            }
        }
        sum / ((x1 - x0) * (y1 - y0)) as f64
    }

    #[test]
    fn window_is_the_papers_gaussian() {
        let g = gaussian();
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert_eq!(g[0], g[10]);
        // Neighbouring taps of a σ = 1.5 Gaussian differ by exp(-(2d+1)/4.5).
        assert!((g[4] / g[5] - (-1.0f64 / 4.5).exp()).abs() < 1e-15);
        assert_eq!((C1, C2), (1e-4, 9e-4));
    }

    #[test]
    fn identical_images_give_exactly_one() {
        for (w, h) in [(1, 1), (5, 3), (11, 11), (40, 150)] {
            let a = noisy(&smooth(w, h), 0.2, 1);
            assert_eq!(ssim(&a, &a).unwrap(), 1.0, "{w}x{h}");
        }
    }

    #[test]
    fn constant_images_match_the_closed_form() {
        // With no variance the contrast-structure term is C2/C2 = 1.
        for (a, b) in [(0.3f32, 0.6f32), (0.0, 1.0), (0.9, 0.1), (0.05, 0.05)] {
            let (fa, fb) = (f64::from(a), f64::from(b));
            let expected = (2.0 * fa * fb + C1) / (fa * fa + fb * fb + C1);
            for (w, h) in [(3, 2), (16, 13)] {
                let ia = RgbImage::from_fn(w, h, |_, _| Rgb::splat(a));
                let ib = RgbImage::from_fn(w, h, |_, _| Rgb::splat(b));
                let s = ssim(&ia, &ib).unwrap();
                assert!((s - expected).abs() < 1e-12, "{a} {b}: {s} vs {expected}");
            }
        }
    }

    #[test]
    fn separable_banded_filter_matches_the_direct_definition() {
        for (w, h) in [(7, 5), (23, 150), (11, 30), (30, 9), (1, 20)] {
            let a = noisy(&smooth(w, h), 0.1, 2);
            let b = noisy(&smooth(w, h), 0.05, 3);
            let direct = brute_force(&a, &b);
            for band in [1, 3, BAND] {
                let s = mean_ssim(&a, &b, band);
                assert!(
                    (s - direct).abs() < 1e-12,
                    "{w}x{h} band {band}: {s} vs {direct}"
                );
            }
        }
    }

    #[test]
    fn more_noise_means_lower_ssim() {
        let base = smooth(64, 48);
        let mut last = 1.0;
        for strength in [0.005, 0.01, 0.02, 0.05, 0.1, 0.2] {
            let s = ssim(&noisy(&base, strength, 4), &base).unwrap();
            assert!(s < last, "strength {strength}: {s} !< {last}");
            last = s;
        }
        assert!(last < 0.5, "{last}");
    }

    #[test]
    fn symmetric_and_clamped() {
        let a = noisy(&smooth(20, 20), 0.1, 5);
        let b = noisy(&smooth(20, 20), 0.1, 6);
        assert_eq!(ssim(&a, &b).unwrap(), ssim(&b, &a).unwrap());
        // Beyond [0, 1] every value reads as its clamp.
        let hot = RgbImage::from_fn(12, 12, |_, _| Rgb::splat(5.0));
        let one = RgbImage::from_fn(12, 12, |_, _| Rgb::ONE);
        assert_eq!(ssim(&hot, &one).unwrap(), 1.0);
    }

    #[test]
    fn deterministic_across_thread_counts() {
        let a = noisy(&smooth(50, 300), 0.1, 7);
        let b = smooth(50, 300);
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ssim(&a, &b).unwrap())
        };
        assert_eq!(run(1).to_bits(), run(3).to_bits());
    }
}
