//! The guided image filter (He, Sun & Tang, "Guided image filtering", ECCV 2010 / TPAMI
//! 2013), in its colour-guide form (the TPAMI paper's filtering with a colour guidance image): in every `(2r+1)²` window the
//! output is an affine function of the three-channel guide `I`, `q = aᵀI + b`, fitted to the
//! noisy colour `p` by ridge regression,
//! `a = (Σ + εU)⁻¹ (mean(I p) − μ p̄)`, `b = p̄ − aᵀμ` (Σ, μ: the guide's covariance and mean
//! in the window), and the per-window coefficients are averaged over the windows covering
//! each pixel. Every mean is a box mean by summed-area table ([`crate::blocks::sat`]), so the
//! cost does not depend on the radius. Bauszat's GREE bank (thesis ch. 5) uses r = 4, 8, 16.
//!
//! Choices and deviations:
//! - **Guide** (`guide`): the frame's `albedo` (default), its `normal`, or the noisy `colour`
//!   itself. The feature guides keep edges the geometry or texture explains and smooth
//!   everything else (lighting edges such as shadows are blurred); the colour guide keeps
//!   strong colour edges but also noise above ε.
//! - **ε is relative**: the regulariser is `eps` times the guide's variance over the whole
//!   frame (floored at 1e-8), so scaling or offsetting the guide does not change the output.
//!   With the default `eps = 0.01`, windows whose guide variance is below 1% of the frame's
//!   are smoothed as if the guide were flat there.
//! - Non-finite colour or guide pixels count as the frame's mean (a NaN would otherwise spread
//!   through the summed-area table to most of the image).
//! - Windows are cut at the image border (box means over the pixels inside).
//! - Guide and colour are centred on their frame means before the products are formed, and
//!   the table sums are `f64`, so the covariances do not lose their digits to large means.

use crate::blocks::sat::BoxMean;
use crate::blocks::{check_count, check_positive};
use crate::{Channel, DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use rayon::prelude::*;
use rt_core::glam::{DMat3, DVec3, Vec3};
use rt_core::{Image, Rgb, RgbImage};

/// Which image guides the filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Guide {
    /// The first-hit albedo.
    Albedo,
    /// The first-hit normal.
    Normal,
    /// The noisy colour itself.
    Colour,
}

/// Guided image filter of window radius `radius` and relative regulariser `eps`.
#[derive(Clone, Debug)]
pub struct GuidedFilter {
    radius: usize,
    eps: f32,
    guide: Guide,
    name: String,
}

/// Floor of the guide's frame variance when scaling ε (a flat guide still gets a positive ε).
const MIN_GUIDE_VARIANCE: f64 = 1e-8;

impl GuidedFilter {
    /// Largest radius accepted (the cost does not depend on it; larger is surely a mistake).
    pub const MAX_RADIUS: usize = 1024;

    /// A filter of window radius `radius ≥ 1`, relative regulariser `eps > 0`, guided by `guide`.
    pub fn new(radius: usize, eps: f32, guide: Guide) -> Result<Self, DenoiseError> {
        let radius = check_count("guided", "radius", radius, 1, Self::MAX_RADIUS)?;
        let eps = check_positive("guided", "eps", eps, 1e6)?;
        let g = match guide {
            Guide::Albedo => "albedo",
            Guide::Normal => "normal",
            Guide::Colour => "colour",
        };
        Ok(Self {
            radius,
            eps,
            guide,
            name: format!("guided:radius={radius}:eps={eps}:guide={g}"),
        })
    }

    /// From spec options: `radius` (default 8), `eps` (default 0.01, relative to the guide's
    /// variance), `guide` (`albedo`, `normal` or `colour`; default `albedo`).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let radius = o.usize("radius", 8)?;
        let eps = o.f32("eps", 0.01)?;
        let guide = match o.pick("guide", &["albedo", "normal", "colour"], "albedo")? {
            "normal" => Guide::Normal,
            "colour" => Guide::Colour,
            _ => Guide::Albedo,
        };
        Self::new(radius, eps, guide)
    }
}

/// Per-channel means of the finite pixels of `img`, in `f64`.
fn frame_mean(img: &[Vec3]) -> DVec3 {
    let (sum, n) = img
        .iter()
        .filter(|v| v.is_finite())
        .fold((DVec3::ZERO, 0.0), |(s, n), v| (s + v.as_dvec3(), n + 1.0));
    if n > 0.0 {
        sum / n
    } else {
        DVec3::ZERO
    }
}

impl Denoiser for GuidedFilter {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[Channel] {
        match self.guide {
            Guide::Albedo => &[Channel::Albedo],
            Guide::Normal => &[Channel::Normal],
            Guide::Colour => &[],
        }
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        let guide = match self.guide {
            Guide::Albedo => frame.albedo.as_ref(),
            Guide::Normal => frame.normal.as_ref(),
            Guide::Colour => Some(&frame.colour),
        };
        let (Some(guide), false) = (guide, w == 0 || h == 0) else {
            return frame.colour.clone();
        };
        let (g, p) = (guide.pixels(), frame.colour.pixels());
        let (gm, pm) = (frame_mean(g), frame_mean(p));
        // Centred guide and colour planes. A non-finite pixel becomes the frame mean: in a
        // summed-area table it would poison every sum below and right of it, not just its
        // windows.
        let plane = |img: &[Vec3], m: f64, c: usize| -> Vec<f32> {
            img.iter()
                .map(|v| {
                    if v.is_finite() {
                        (f64::from(v[c]) - m) as f32
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let gi: [Vec<f32>; 3] = std::array::from_fn(|c| plane(g, gm[c], c));
        let pi: [Vec<f32>; 3] = std::array::from_fn(|c| plane(p, pm[c], c));
        let guide_var = gi
            .iter()
            .flatten()
            .map(|&v| f64::from(v) * f64::from(v))
            .sum::<f64>()
            / (3 * g.len()) as f64;
        let eps = f64::from(self.eps) * guide_var.max(MIN_GUIDE_VARIANCE);

        let n = w * h;
        let mut boxer = BoxMean::new(w, h);
        let mut src = vec![0.0f32; n];
        let mut mean_of = |f: &dyn Fn(usize) -> f32| -> Vec<f32> {
            for (i, s) in src.iter_mut().enumerate() {
                *s = f(i);
            }
            let mut out = vec![0.0f32; n];
            boxer.apply(&src, self.radius, &mut out);
            out
        };
        let mi: [Vec<f32>; 3] = std::array::from_fn(|c| mean_of(&|i| gi[c][i]));
        let mp: [Vec<f32>; 3] = std::array::from_fn(|c| mean_of(&|i| pi[c][i]));
        const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
        let mii: [Vec<f32>; 6] = std::array::from_fn(|k| {
            let (a, b) = PAIRS[k];
            mean_of(&|i| gi[a][i] * gi[b][i])
        });
        let mip: [Vec<f32>; 9] = std::array::from_fn(|k| {
            let (a, c) = (k / 3, k % 3);
            mean_of(&|i| gi[a][i] * pi[c][i])
        });

        // Per-window coefficients: a (3×3, row c for colour channel c) and b.
        let coeffs: Vec<[f32; 12]> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mu = DVec3::new(mi[0][i].into(), mi[1][i].into(), mi[2][i].into());
                let s = |k: usize| f64::from(mii[k][i]);
                let cov =
                    DMat3::from_cols_array(&[s(0), s(1), s(2), s(1), s(3), s(4), s(2), s(4), s(5)])
                        - DMat3::from_cols(mu * mu.x, mu * mu.y, mu * mu.z)
                        + DMat3::from_diagonal(DVec3::splat(eps));
                let inv = cov.inverse();
                let mut out = [0.0f32; 12];
                for c in 0..3 {
                    let pbar = f64::from(mp[c][i]);
                    let cross = DVec3::new(
                        f64::from(mip[c][i]),
                        f64::from(mip[3 + c][i]),
                        f64::from(mip[6 + c][i]),
                    ) - mu * pbar;
                    let a = inv * cross;
                    out[3 * c..3 * c + 3].copy_from_slice(&a.as_vec3().to_array());
                    out[9 + c] = (pbar - a.dot(mu)) as f32;
                }
                out
            })
            .collect();
        drop((mi, mp, mii, mip));
        let mc: [Vec<f32>; 12] = std::array::from_fn(|k| mean_of(&|i| coeffs[i][k]));

        let out: Vec<Rgb> = (0..n)
            .into_par_iter()
            .map(|i| {
                let ig = Vec3::new(gi[0][i], gi[1][i], gi[2][i]);
                let q = |c: usize| {
                    let a = Vec3::new(mc[3 * c][i], mc[3 * c + 1][i], mc[3 * c + 2][i]);
                    (f64::from(a.dot(ig)) + f64::from(mc[9 + c][i]) + pm[c]) as f32
                };
                Rgb::new(q(0), q(1), q(2))
            })
            .collect();
        Image::new(w, h, out).unwrap_or_default()
    }
}
