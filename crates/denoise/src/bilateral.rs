//! The joint (cross) bilateral filter guided by first-hit features: the edge-aware family of
//! the GREE filter bank (Bauszat's thesis ch. 5; research digest seed000-denoise.md §2.1:
//! σ_domain = 1, 2, 4, 8 px with guides normal σ = 0.8, position σ = 0.6, albedo σ = 0.25),
//! after Eisemann & Durand 2004 and Petschnigg et al. 2004, with the feature distance of Li,
//! Wu & Chuang 2012 ("SURE-based optimization for adaptive sampling and reconstruction",
//! SIGGRAPH Asia).
//!
//! The weight of neighbour `q` for pixel `p` is
//! `exp(-|p - q|² / 2σ² - ½ Σ_g max(0, |f_g(p) - f_g(q)|² - (V_g(p) + V_g(q))) / σ_g²)`
//! over the guide groups `g` (normal, position, albedo, and optionally colour), where `V_g` is
//! the variance of the group's mean summed over its three components (Li et al.'s modification:
//! a difference no larger than the features' own noise costs nothing). The window is the disc
//! of radius `⌈3σ⌉`, cut at the image border and renormalised by the weight sum.
//!
//! Deviations and choices:
//! - **Scale-invariant positions.** Positions are divided by the scene's extent as the frame
//!   sees it: the root-mean-square distance of the frame's finite positions from their mean
//!   (1 if that is zero). Scaling the scene then leaves the output unchanged (seed 002,
//!   claim 17); σ_position = 0.6 means 0.6 of that spread. The thesis does not say how it
//!   scaled positions.
//! - **Variances** (`variances=auto`, the default) are used for each group whose variance
//!   channel the frame has; `on` requires them (they appear in [`Denoiser::needs`]); `off`
//!   ignores them (the plain joint bilateral filter).
//! - A guide σ of 0 turns that guide off (and drops its channel from the needs).
//! - The colour range term (`colour`, off by default) is in the frame's absolute radiance
//!   units.

use crate::blocks::{check_positive, check_range, exp_neg};
use crate::{Channel, DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use rayon::prelude::*;
use rt_core::glam::{Vec3, Vec4};
use rt_core::{Image, Rgb, RgbImage};

/// How the filter uses feature variances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarianceUse {
    /// Use each guide's variance channel when the frame has it.
    Auto,
    /// Require the variance channels of the enabled guides.
    On,
    /// Ignore variances.
    Off,
}

/// Guide groups, in the order of [`Guide::f`].
const GROUPS: usize = 4;

/// One pixel's scaled guide features (each group divided by its σ) and the scaled variances of
/// its groups: one 64-byte record, read once per neighbour, laid out by component
/// (`x[k]` is the x component of group `k`) so the four groups are handled as one 4-lane
/// vector (glam's `Vec4`, SSE2 on x86-64).
#[derive(Clone, Copy, Debug, Default)]
#[repr(align(64))]
struct Guide {
    x: Vec4,
    y: Vec4,
    z: Vec4,
    v: Vec4,
}

impl Guide {
    /// `Σ_g max(0, |f_g(p) − f_g(q)|² − (V_g(p) + V_g(q)))`.
    #[inline]
    fn distance(&self, q: &Guide) -> f32 {
        let (dx, dy, dz) = (self.x - q.x, self.y - q.y, self.z - q.z);
        (dx * dx + dy * dy + dz * dz - (self.v + q.v))
            .max(Vec4::ZERO)
            .element_sum()
    }
}

/// A guide group's feature image, its variance image, and the unit its values are measured in.
type FeatureSource<'a> = (Option<&'a Image<Vec3>>, Option<&'a Image<Vec3>>, f32);

/// Joint bilateral filter of spatial σ `sigma` guided by normal, position and albedo.
#[derive(Clone, Debug)]
pub struct JointBilateral {
    radius: usize,
    /// `-(dx² + dy²) / 2σ²` over the `(2r+1)²` window, row-major.
    spatial: Vec<f32>,
    /// Half width of the disc of radius `radius` at row offset `|dy|`.
    half: Vec<usize>,
    /// σ of normal, position, albedo, colour (0: off).
    sigmas: [f32; GROUPS],
    variances: VarianceUse,
    needs: Vec<Channel>,
    name: String,
}

impl JointBilateral {
    /// Largest spatial σ accepted (a 193-pixel-wide window).
    pub const MAX_SIGMA: f32 = 32.0;

    /// A filter of spatial σ `sigma` pixels with guide σs for normal, position (in units of the
    /// frame's position spread), albedo and colour (0 turns a guide off).
    pub fn new(
        sigma: f32,
        [normal, position, albedo, colour]: [f32; 4],
        variances: VarianceUse,
    ) -> Result<Self, DenoiseError> {
        const NAME: &str = "bilateral";
        let sigma = check_positive(NAME, "sigma", sigma, Self::MAX_SIGMA)?;
        let sigmas = [
            check_range(NAME, "normal", normal, 0.0, f32::MAX)?,
            check_range(NAME, "position", position, 0.0, f32::MAX)?,
            check_range(NAME, "albedo", albedo, 0.0, f32::MAX)?,
            check_range(NAME, "colour", colour, 0.0, f32::MAX)?,
        ];
        let radius = (3.0 * sigma).ceil() as usize;
        let r = radius as isize;
        let inv = -0.5 / (sigma * sigma);
        let mut spatial = Vec::with_capacity((2 * radius + 1).pow(2));
        for dy in -r..=r {
            for dx in -r..=r {
                spatial.push((dx * dx + dy * dy) as f32 * inv);
            }
        }
        let half = (0..=r)
            .map(|dy| {
                (0..=r)
                    .rev()
                    .find(|dx| dx * dx + dy * dy <= r * r)
                    .unwrap_or(0) as usize
            })
            .collect();
        let channels = [
            (Channel::Normal, Channel::NormalVariance),
            (Channel::Position, Channel::PositionVariance),
            (Channel::Albedo, Channel::AlbedoVariance),
            (Channel::Colour, Channel::Variance),
        ];
        let mut needs = Vec::new();
        for (&s, (c, v)) in sigmas.iter().zip(channels) {
            if s > 0.0 {
                if c != Channel::Colour {
                    needs.push(c);
                }
                if variances == VarianceUse::On {
                    needs.push(v);
                }
            }
        }
        let mode = match variances {
            VarianceUse::Auto => "auto",
            VarianceUse::On => "on",
            VarianceUse::Off => "off",
        };
        Ok(Self {
            radius,
            spatial,
            half,
            sigmas,
            variances,
            needs,
            name: format!(
                "bilateral:sigma={sigma}:normal={}:position={}:albedo={}:colour={}:variances={mode}",
                sigmas[0], sigmas[1], sigmas[2], sigmas[3]
            ),
        })
    }

    /// From spec options: `sigma` (spatial, pixels, default 2), `normal` (0.8), `position`
    /// (0.6, in units of the frame's position spread), `albedo` (0.25), `colour` (0, off),
    /// `variances` (`auto`, `on` or `off`; default `auto`).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let sigma = o.f32("sigma", 2.0)?;
        let guides = [
            o.f32("normal", 0.8)?,
            o.f32("position", 0.6)?,
            o.f32("albedo", 0.25)?,
            o.f32("colour", 0.0)?,
        ];
        let variances = match o.pick("variances", &["auto", "on", "off"], "auto")? {
            "on" => VarianceUse::On,
            "off" => VarianceUse::Off,
            _ => VarianceUse::Auto,
        };
        Self::new(sigma, guides, variances)
    }

    /// The per-pixel guide records of `frame`.
    fn guides(&self, frame: &NoisyFrame) -> Vec<Guide> {
        let n = frame.colour.len();
        let mut g = vec![Guide::default(); n];
        let scale = position_spread(frame.position.as_ref());
        let colour = Some(&frame.colour);
        let features: [FeatureSource; GROUPS] = [
            (frame.normal.as_ref(), frame.normal_variance.as_ref(), 1.0),
            (
                frame.position.as_ref(),
                frame.position_variance.as_ref(),
                scale,
            ),
            (frame.albedo.as_ref(), frame.albedo_variance.as_ref(), 1.0),
            (colour, frame.variance.as_ref(), 1.0),
        ];
        for (k, ((feat, var, unit), &sigma)) in features.iter().zip(&self.sigmas).enumerate() {
            let (Some(feat), true) = (feat, sigma > 0.0) else {
                continue;
            };
            let s = 1.0 / (sigma * unit);
            for (gi, f) in g.iter_mut().zip(feat.pixels()) {
                let f = *f * s;
                (gi.x[k], gi.y[k], gi.z[k]) = (f.x, f.y, f.z);
            }
            let var = var.filter(|_| self.variances != VarianceUse::Off);
            if let Some(var) = var {
                for (gi, v) in g.iter_mut().zip(var.pixels()) {
                    gi.v[k] = v.element_sum() * s * s;
                }
            }
        }
        g
    }
}

/// Root-mean-square distance of the finite positions from their mean, or 1 if there are none
/// or they coincide: the unit positions are measured in, so that σ_position is scale-free.
fn position_spread(position: Option<&Image<Vec3>>) -> f32 {
    let Some(p) = position else { return 1.0 };
    let (mut n, mut sum, mut sq) = (0.0f64, [0.0f64; 3], 0.0f64);
    for v in p.pixels().iter().filter(|v| v.is_finite()) {
        n += 1.0;
        for (s, c) in sum.iter_mut().zip(v.to_array()) {
            *s += f64::from(c);
        }
        sq += f64::from(v.length_squared());
    }
    if n == 0.0 {
        return 1.0;
    }
    let mean2: f64 = sum.iter().map(|s| (s / n) * (s / n)).sum();
    let spread = (sq / n - mean2).max(0.0).sqrt() as f32;
    if spread.is_finite() && spread > 0.0 {
        spread
    } else {
        1.0
    }
}

impl Denoiser for JointBilateral {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[Channel] {
        &self.needs
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        if w == 0 || h == 0 {
            return frame.colour.clone();
        }
        let guides = self.guides(frame);
        let colour = frame.colour.pixels();
        let r = self.radius;
        let side = 2 * r + 1;
        let mut out = vec![Rgb::ZERO; w * h];
        out.par_chunks_mut(w).enumerate().for_each(|(y, orow)| {
            let (y0, y1) = crate::blocks::window(y, r, h);
            for (x, o) in orow.iter_mut().enumerate() {
                let gp = &guides[y * w + x];
                let (mut sum, mut wsum) = (Rgb::ZERO, 0.0f32);
                for qy in y0..=y1 {
                    // The disc's row at this height, cut at the image border.
                    let half = self.half[qy.abs_diff(y)];
                    let (qx0, qx1) = crate::blocks::window(x, half, w);
                    let srow = &self.spatial[(qy + r - y) * side..][qx0 + r - x..=qx1 + r - x];
                    let row = qy * w + qx0..=qy * w + qx1;
                    for ((gq, &c), &s) in guides[row.clone()].iter().zip(&colour[row]).zip(srow) {
                        let wgt = exp_neg(s - 0.5 * gp.distance(gq));
                        sum += c * wgt;
                        wsum += wgt;
                    }
                }
                // The centre's weight is 1, so `wsum >= 1`.
                *o = sum / wsum;
            }
        });
        Image::new(w, h, out).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two pixels, colours 0 and 1, normals `n0` and `n1` (other guides off).
    fn pair(n: [Vec3; 2], nvar: Option<f32>) -> NoisyFrame {
        let mut f = NoisyFrame::new(Image::new(2, 1, vec![Rgb::ZERO, Rgb::ONE]).unwrap());
        f.normal = Some(Image::new(2, 1, n.to_vec()).unwrap());
        f.normal_variance = nvar.map(|v| Image::filled(2, 1, Vec3::splat(v)));
        f
    }

    #[test]
    fn the_weight_is_spatial_times_guide_term_with_lis_variance_cancellation() {
        let (sigma, sn) = (1.5f32, 0.8f32);
        let n = [Vec3::Z, Vec3::new(0.0, 0.6, 0.8)];
        let d2 = (n[0] - n[1]).length_squared(); // 0.4
        let filter = |v| JointBilateral::new(sigma, [sn, 0.0, 0.0, 0.0], v).unwrap();
        let out = |f: &NoisyFrame, v| filter(v).denoise(f).unwrap().pixel(0, 0).x;
        let spatial = -0.5 / (sigma * sigma);
        let expect = |e: f32| {
            let w = (spatial - 0.5 * e / (sn * sn)).exp();
            w / (1.0 + w)
        };
        let plain = pair(n, None);
        assert!((out(&plain, VarianceUse::Auto) - expect(d2)).abs() < 1e-6);
        // Variance 0.05 per component per pixel: 0.4 - 2·3·0.05 = 0.1 remains.
        let noisy = pair(n, Some(0.05));
        assert!((out(&noisy, VarianceUse::Auto) - expect(d2 - 0.3)).abs() < 1e-6);
        assert!((out(&noisy, VarianceUse::Off) - expect(d2)).abs() < 1e-6);
        // More variance than difference: the guide costs nothing (clamped at 0).
        let very = pair(n, Some(1.0));
        assert!((out(&very, VarianceUse::On) - expect(0.0)).abs() < 1e-6);
        assert_eq!(
            filter(VarianceUse::On).needs(),
            &[Channel::Normal, Channel::NormalVariance]
        );
    }

    #[test]
    fn positions_are_measured_in_their_spread() {
        let p = Image::new(2, 1, vec![Vec3::ZERO, Vec3::new(6.0, 0.0, 0.0)]).unwrap();
        assert_eq!(position_spread(Some(&p)), 3.0);
        assert_eq!(position_spread(Some(&Image::filled(3, 1, Vec3::ONE))), 1.0);
        assert_eq!(position_spread(None), 1.0);
    }
}
