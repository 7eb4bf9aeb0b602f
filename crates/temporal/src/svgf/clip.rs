//! Neighbourhood clipping tailored to SVGF (Voorhuis 2018 §4.5): TAA's 3×3 colour box is too
//! noisy at one sample per pixel, so the box is taken over 5×5 pixels of the current frame
//! blurred by a separable 7×7 Gaussian, and a specular pixel's reprojected history is clamped
//! into it. A history from a wrong motion vector is thereby pulled to what the pixel sees now.
//!
//! Reading (\[ours\]; the thesis gives no σ): the 7 taps are the binomial weights
//! (1, 6, 15, 20, 15, 6, 1)/64, a Gaussian of σ ≈ 1.2 pixels; clamping is per channel.

use rayon::prelude::*;
use rt_core::Rgb;

const BLUR: [f32; 7] = [
    1.0 / 64.0,
    6.0 / 64.0,
    15.0 / 64.0,
    20.0 / 64.0,
    15.0 / 64.0,
    6.0 / 64.0,
    1.0 / 64.0,
];
/// Half the width of the window the box is taken over.
const WINDOW: isize = 2;

/// `img` (w × h) blurred by the separable 7×7 binomial filter, borders renormalised.
pub fn guide(img: &[Rgb], w: usize, h: usize) -> Vec<Rgb> {
    let pass = |src: &[Rgb], horizontal: bool| -> Vec<Rgb> {
        let mut out = vec![Rgb::ZERO; w * h];
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                let (mut sum, mut wsum) = (Rgb::ZERO, 0.0f32);
                for (k, wk) in BLUR.iter().enumerate() {
                    let d = k as isize - 3;
                    let (xx, yy) = if horizontal {
                        (x as isize + d, y as isize)
                    } else {
                        (x as isize, y as isize + d)
                    };
                    if xx < 0 || yy < 0 || xx >= w as isize || yy >= h as isize {
                        continue;
                    }
                    sum += src[yy as usize * w + xx as usize] * *wk;
                    wsum += wk;
                }
                *o = sum / wsum;
            }
        });
        out
    };
    pass(&pass(img, true), false)
}

/// The per-channel range of `guide` over the 5×5 window around `(x, y)`.
pub fn range(guide: &[Rgb], w: usize, h: usize, x: usize, y: usize) -> (Rgb, Rgb) {
    let (mut lo, mut hi) = (Rgb::splat(f32::INFINITY), Rgb::splat(f32::NEG_INFINITY));
    for yy in (y as isize - WINDOW).max(0)..=(y as isize + WINDOW).min(h as isize - 1) {
        for xx in (x as isize - WINDOW).max(0)..=(x as isize + WINDOW).min(w as isize - 1) {
            let c = guide[yy as usize * w + xx as usize];
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    (lo, hi)
}

/// `history` clamped into `[lo, hi]` per channel.
#[inline]
pub fn clip(history: Rgb, (lo, hi): (Rgb, Rgb)) -> Rgb {
    history.clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_history_inside_the_range_is_left_unchanged() {
        let (w, h) = (9, 7);
        let img: Vec<Rgb> = (0..w * h)
            .map(|i| Rgb::new((i % 5) as f32, (i % 3) as f32 * 0.5, 1.0 + (i % 7) as f32))
            .collect();
        let g = guide(&img, w, h);
        let r = range(&g, w, h, 4, 3);
        // Anything between the bounds stays bit for bit.
        for t in [0.0, 0.25, 0.5, 1.0] {
            let inside = r.0 + (r.1 - r.0) * t;
            assert_eq!(clip(inside, r), inside);
        }
        // Outside is pulled to the nearest bound.
        assert_eq!(clip(r.1 + Rgb::ONE, r), r.1);
        assert_eq!(clip(r.0 - Rgb::ONE, r), r.0);
    }

    #[test]
    fn the_guide_of_a_constant_image_is_the_constant() {
        let img = vec![Rgb::new(0.3, 2.0, 7.0); 6 * 5];
        for c in guide(&img, 6, 5) {
            assert!((c - Rgb::new(0.3, 2.0, 7.0)).abs().max_element() < 1e-6);
        }
    }
}
