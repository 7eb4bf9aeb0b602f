//! Non-local means with variance-normalised patch distances, after Rousselle, Knaus & Zwicker
//! 2012, "Adaptive rendering with non-local means filtering" (SIGGRAPH Asia).
//! Bauszat's GREE bank (thesis ch. 5) uses NL-means with a search window of 16 px.
//!
//! For pixel `p`, neighbour `q` in the `(2·radius+1)²` search window, and colour channel `c`,
//! the per-pixel distance term is
//! `((u_p − u_q)² − (Var_p + min(Var_p, Var_q))) / (ε + k²(Var_p + Var_q))`
//! where `Var` is the variance of the pixel mean (the frame's `variance` channel); `d²(p, q)` is
//! its mean over the channels and over the `(2·patch+1)²` patches of `p` and `q`, and the
//! weight is `exp(−max(0, d²))`. The output is the weighted mean of the `u_q`.
//!
//! Cost is O(pixels × window²): for each search offset the term is box-filtered once
//! ([`crate::blocks::patch`]), instead of summed per patch. Work is split into fixed strips of
//! rows, one rayon task each, with offsets visited in a fixed order, so the result is the same
//! bits on any thread count.
//!
//! Deviations: non-finite colours count as black and non-finite or negative variances as 0.
//! Patches are cut at the image border (mean over the patch pixels inside; the
//! neighbour's patch reads clamped pixels); search neighbours outside the image are skipped.
//! Rousselle et al. filter per buffer half and cross-filter; that belongs to a denoiser that
//! combines two filtered halves, not to this bank member.

use crate::blocks::patch::PatchScratch;
use crate::blocks::{check_count, check_range, exp_neg, STRIP_ROWS};
use crate::{Channel, DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use rayon::prelude::*;
use rt_core::glam::Vec3A;
use rt_core::{Image, Rgb, RgbImage};

/// Non-local means normalised by the variance of the pixel means.
#[derive(Clone, Debug)]
pub struct Nlm {
    radius: usize,
    patch: usize,
    k: f32,
    eps: f32,
    name: String,
}

impl Nlm {
    /// Largest search radius accepted (a 65×65 window).
    pub const MAX_RADIUS: usize = 32;
    /// Largest patch radius accepted.
    pub const MAX_PATCH: usize = 16;

    /// A filter with search window half size `radius` (at least 1), patch radius `patch`,
    /// variance-cancellation factor `k ≥ 0` and regulariser `eps > 0`.
    pub fn new(radius: usize, patch: usize, k: f32, eps: f32) -> Result<Self, DenoiseError> {
        const NAME: &str = "nlm";
        let radius = check_count(NAME, "radius", radius, 1, Self::MAX_RADIUS)?;
        let patch = check_count(NAME, "patch", patch, 0, Self::MAX_PATCH)?;
        let k = check_range(NAME, "k", k, 0.0, 1e6)?;
        let eps = crate::blocks::check_positive(NAME, "eps", eps, 1e6)?;
        Ok(Self {
            radius,
            patch,
            k,
            eps,
            name: format!("nlm:radius={radius}:patch={patch}:k={k}:eps={eps:e}"),
        })
    }

    /// From spec options: `radius` (search window half size, default 7: 15×15), `patch` (patch
    /// radius, default 3: 7×7), `k` (default 0.45), `eps` (default 1e-10).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        Self::new(
            o.usize("radius", 7)?,
            o.usize("patch", 3)?,
            o.f32("k", 0.45)?,
            o.f32("eps", 1e-10)?,
        )
    }
}

/// Rousselle et al.'s per-pixel distance term between `p` and `q` (colours `up`, `uq`,
/// variances of the means `vp`, `vq` ≥ 0), averaged over the three channels.
#[inline]
fn distance_term(up: Vec3A, uq: Vec3A, vp: Vec3A, vq: Vec3A, k2: f32, eps: f32) -> f32 {
    let d = up - uq;
    let num = d * d - (vp + vp.min(vq));
    let den = Vec3A::splat(eps) + (vp + vq) * k2;
    (num / den).element_sum() * (1.0 / 3.0)
}

impl Denoiser for Nlm {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[Channel] {
        &[Channel::Variance]
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        let Some(variance) = frame.variance.as_ref() else {
            return frame.colour.clone();
        };
        if w == 0 || h == 0 {
            return frame.colour.clone();
        }
        // SIMD-width copies (glam's Vec3A). A non-finite colour counts as black and a negative
        // or non-finite variance as 0: the patch sums run along whole rows, so one NaN would
        // otherwise spoil every patch distance to its right.
        let finite = |v: Vec3A| if v.is_finite() { v } else { Vec3A::ZERO };
        let u: Vec<Vec3A> = frame
            .colour
            .pixels()
            .iter()
            .map(|&c| finite(c.into()))
            .collect();
        let var: Vec<Vec3A> = variance
            .pixels()
            .iter()
            .map(|&v| finite(v.into()).max(Vec3A::ZERO))
            .collect();
        let k2 = self.k * self.k;
        let (r, eps) = (self.radius as isize, self.eps);
        let mut out = vec![Rgb::ZERO; w * h];
        out.par_chunks_mut(w * STRIP_ROWS)
            .enumerate()
            .for_each(|(s, strip)| {
                let y0 = s * STRIP_ROWS;
                let y1 = y0 + strip.len() / w;
                let mut scratch = PatchScratch::default();
                let mut dist = vec![0.0f32; strip.len()];
                let mut wsum = vec![0.0f32; strip.len()];
                strip.fill(Rgb::ZERO);
                for dy in -r..=r {
                    for dx in -r..=r {
                        // The distance term between pixel (x, y) and its neighbour at the
                        // offset, clamped into the image (only patch pixels near the border
                        // read a clamped neighbour).
                        let term = |y: usize, row: &mut [f32]| {
                            let qy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                            let (urow, vrow) = (&u[y * w..][..w], &var[y * w..][..w]);
                            let (uq, vq) = (&u[qy * w..][..w], &var[qy * w..][..w]);
                            for (x, t) in row.iter_mut().enumerate() {
                                let qx = (x as isize + dx).clamp(0, w as isize - 1) as usize;
                                *t = distance_term(urow[x], uq[qx], vrow[x], vq[qx], k2, eps);
                            }
                        };
                        scratch.patch_means((w, h), (y0, y1), self.patch, term, &mut dist);
                        let qx0 = (-dx).max(0) as usize;
                        let qx1 = (w as isize - dx).min(w as isize).max(0) as usize;
                        for (i, ((orow, wrow), drow)) in strip
                            .chunks_mut(w)
                            .zip(wsum.chunks_mut(w))
                            .zip(dist.chunks(w))
                            .enumerate()
                        {
                            let qy = (y0 + i) as isize + dy;
                            if qy < 0 || qy >= h as isize || qx0 >= qx1 {
                                continue;
                            }
                            let urow = &u[qy as usize * w..][..w];
                            for x in qx0..qx1 {
                                let wgt = exp_neg(-drow[x]);
                                orow[x] += Rgb::from(urow[(x as isize + dx) as usize]) * wgt;
                                wrow[x] += wgt;
                            }
                        }
                    }
                }
                // The centre's own weight is 1 (its distance is never positive), so `ws ≥ 1`.
                for (o, &ws) in strip.iter_mut().zip(&wsum) {
                    *o /= ws;
                }
            });
        Image::new(w, h, out).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_term_is_rousselles() {
        let (k, eps) = (0.45f32, 1e-10f32);
        let up = Vec3A::new(1.0, 2.0, 0.5);
        let uq = Vec3A::new(1.5, 1.0, 0.5);
        let vp = Vec3A::new(0.04, 0.01, 0.09);
        let vq = Vec3A::new(0.01, 0.02, 0.09);
        let got = distance_term(up, uq, vp, vq, k * k, eps);
        let mut want = 0.0;
        for c in 0..3 {
            let d = up[c] - uq[c];
            want += (d * d - (vp[c] + vp[c].min(vq[c]))) / (eps + k * k * (vp[c] + vq[c]));
        }
        want /= 3.0;
        assert!((got - want).abs() < 1e-5 * want.abs(), "{got} vs {want}");
        // Equal colours: never a positive distance, so the centre's weight is 1.
        assert!(distance_term(up, up, vp, vp, k * k, eps) < 0.0);
        // Identical noisy-free pixels: 0/eps, not NaN.
        assert_eq!(
            distance_term(up, up, Vec3A::ZERO, Vec3A::ZERO, k * k, eps),
            0.0
        );
    }

    #[test]
    fn weights_are_exp_of_the_patch_mean_distance() {
        // Two pixels, patch radius 0: pixel 0's output is (u0 + w u1) / (1 + w) with
        // w = exp(-max(0, d²(0, 1))).
        let u = [Rgb::splat(0.0), Rgb::new(0.3, 0.2, 0.1)];
        let v = [Rgb::splat(0.01), Rgb::splat(0.02)];
        let mut f = NoisyFrame::new(Image::new(2, 1, u.to_vec()).unwrap());
        f.variance = Some(Image::new(2, 1, v.to_vec()).unwrap());
        let out = Nlm::new(1, 0, 0.45, 1e-10).unwrap().denoise(&f).unwrap();
        let d2 = distance_term(
            u[0].into(),
            u[1].into(),
            v[0].into(),
            v[1].into(),
            0.2025,
            1e-10,
        );
        let wgt = (-d2.max(0.0)).exp();
        let want = (u[0] + u[1] * wgt) / (1.0 + wgt);
        assert!(wgt > 0.01 && wgt < 0.99, "{wgt}");
        assert!(
            (out.pixel(0, 0) - want).abs().max_element() < 1e-6,
            "{}",
            out.pixel(0, 0)
        );
    }
}
