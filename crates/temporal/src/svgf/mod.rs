//! Spatiotemporal variance-guided filtering (Schied et al., HPG 2017) with Voorhuis' extensions
//! for temporally stable reflections (Voorhuis 2018; digest `seed001-svgf.md`).
//!
//! Per frame, for the direct and the indirect light separately:
//!
//! 1. **Demodulate** by the primary albedo (a mirror: by the product of the albedos along its
//!    reflection, Voorhuis §4.2), so texture never has to survive the filter.
//! 2. **Reproject** (`reproject.rs`): the history where the surface was (primary motion
//!    vectors), or for specular pixels with `reflections=reproject` where its reflection was
//!    (diamond search on reflected hits for mirrors, on representative rays for sharp glossy
//!    surfaces), fetched bilinearly from taps passing the consistency tests.
//! 3. **Clip** specular pixels' history to the 5×5 range of the blurred current frame
//!    ([`clip`]).
//! 4. **Accumulate** colour and luminance moments: `α_eff = max(α, 1/h)`, so the first frames
//!    after a disocclusion are a true mean (Voorhuis §2.7 change 1); α is 0.2 on diffuse and
//!    0.1 on specular pixels.
//! 5. **Variance** from the moments, or while the history is shorter than 4 frames from the
//!    neighbours' accumulated moments over a 7×7 depth- and normal-weighted window, scaled by
//!    4/h as Falcor does.
//! 6. **À-Trous** (`atrous.rs`), 5 iterations; the output of the `feedback`-th is the next
//!    frame's colour history.
//! 7. **Remodulate**, add emission; a 3×3 median on diffuse pixels for display only.
//!
//! Not done (deviations): TAA after tone mapping (we write linear frames; supersampling with
//! guide rays is the thesis' alternative and not built yet); fireflies are not clamped.

mod atrous;
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod atrous_avx2;
pub mod clip;
pub mod diamond;
mod fast_exp;
mod features;
mod history;
mod params;
mod planes;
mod reproject;
pub mod supersample;

pub use atrous::{normal_weight, Signals, KERNEL};
pub use features::{Class, MIN_ALBEDO};
pub use params::{Reflections, SvgfParams};
pub use reproject::ray_distance;

use features::Features;
use history::History;
use rayon::prelude::*;
use rt_core::color::luminance;
use rt_core::{Image, Rgb, RgbImage};
use rt_film::GuideBuffers;

/// One frame's input: the guide buffers and the frame's light, split by bounce.
#[derive(Clone, Copy, Debug)]
pub struct SvgfInput<'a> {
    /// Noise-free features and motion.
    pub guides: &'a GuideBuffers,
    /// Light after one bounce (not demodulated).
    pub direct: &'a RgbImage,
    /// Light after two or more bounces.
    pub indirect: &'a RgbImage,
    /// Light emitted toward the camera (the environment's where no surface).
    pub emission: &'a RgbImage,
}

/// SVGF with its history.
#[derive(Clone, Debug)]
pub struct Svgf {
    params: SvgfParams,
    history: Option<History>,
    /// Whether the AVX2 code may run (where the CPU has it).
    simd: bool,
    scratch: atrous::Scratch,
}

/// Luminance moments of a demodulated colour.
#[inline]
fn moments(c: Rgb) -> [f32; 2] {
    let l = luminance(c);
    [l, l * l]
}

/// Radius of the spatial variance estimate's window (7×7).
const SPATIAL_RADIUS: isize = 3;
/// History length below which the variance is estimated spatially.
const SHORT_HISTORY: f32 = 4.0;

impl Svgf {
    /// A filter with no history.
    pub fn new(params: SvgfParams) -> Self {
        Self {
            params,
            history: None,
            simd: true,
            scratch: atrous::Scratch::default(),
        }
    }

    /// The same filter with the AVX2 code allowed (the default, used where the CPU has it) or
    /// not. Both give the same bits; this is for comparing them.
    pub fn with_simd(mut self, allow: bool) -> Self {
        self.simd = allow;
        self
    }

    /// True if [`Svgf::push`] runs AVX2 code on this CPU.
    pub fn uses_simd(&self) -> bool {
        self.simd && atrous::simd_available()
    }

    /// Its parameters.
    pub fn params(&self) -> &SvgfParams {
        &self.params
    }

    /// Forgets the history (a cut).
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// History length of every pixel after the last frame (empty before the first).
    pub fn history_lengths(&self) -> &[f32] {
        self.history.as_ref().map_or(&[], |h| &h.length)
    }

    /// Filters one frame of a sequence and keeps its history. The images must all have the
    /// guides' size (callers check: [`crate::TemporalDenoiser`] does).
    pub fn push(&mut self, input: &SvgfInput<'_>) -> RgbImage {
        self.push_supersampled(input, &[])
    }

    /// [`Svgf::push`] with further samples of every pixel besides the guide ray's: each is
    /// assigned to a neighbouring guide, averaged into its input and remodulated from its
    /// filtered light ([`supersample`], Voorhuis Eq. 7).
    pub fn push_supersampled(
        &mut self,
        input: &SvgfInput<'_>,
        extra: &[supersample::ExtraSample<'_>],
    ) -> RgbImage {
        let p = &self.params;
        let g = input.guides;
        let f = Features::new(g, p);
        let (w, h) = (f.w, f.h);
        let n = w * h;
        if self
            .history
            .as_ref()
            .is_some_and(|h| h.w != w || h.h != f.h)
        {
            self.history = None;
        }
        // 1. Demodulate.
        let mut current: Vec<[Rgb; 2]> = (0..n)
            .into_par_iter()
            .map(|i| {
                if f.class[i] == features::Class::Sky {
                    return [Rgb::ZERO; 2];
                }
                let a = f.albedo[i].max(Rgb::splat(MIN_ALBEDO));
                let [direct, indirect] = features::without_emitted(
                    input.direct.pixels()[i],
                    input.indirect.pixels()[i],
                    f.reflected_emission[i],
                );
                [direct / a, indirect / a]
            })
            .collect();
        let gathered = (!extra.is_empty()).then(|| supersample::gather(&f, g, extra, &mut current));
        // 2. Reproject.
        let fetched: Vec<reproject::Fetched> = match &self.history {
            Some(hist) => (0..n)
                .into_par_iter()
                .map(|i| reproject::fetch(&f, g, hist, p, i))
                .collect(),
            None => vec![reproject::Fetched::default(); n],
        };
        // 3. Clip specular history to the current frame's neighbourhood.
        let clipping = p.clip
            && p.reflections == Reflections::Reproject
            && (0..n).any(|i| f.class[i].specular() && fetched[i].valid);
        let guides: Option<[Vec<Rgb>; 2]> = clipping.then(|| {
            [0, 1].map(|s| {
                let plane: Vec<Rgb> = current.iter().map(|c| c[s]).collect();
                clip::guide(&plane, w, h)
            })
        });
        // 4. Accumulate.
        let mut lengths = vec![0.0f32; n];
        let mut acc = vec![Signals::default(); n];
        let mut acc_moments = vec![[[0.0f32; 2]; 2]; n];
        acc.par_iter_mut()
            .zip(acc_moments.par_iter_mut())
            .zip(lengths.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((out, m), len))| {
                let fh = &fetched[i];
                let cur = current[i];
                let specular = f.class[i].specular();
                let length = if fh.valid {
                    (fh.length + 1.0).min(p.max_history)
                } else {
                    1.0
                };
                let alpha = if specular { p.alpha_specular } else { p.alpha };
                let (a, am) = if fh.valid {
                    (alpha.max(1.0 / length), p.alpha_moments.max(1.0 / length))
                } else {
                    (1.0, 1.0)
                };
                for s in 0..2 {
                    let mut hist = fh.colour[s];
                    if let (Some(gd), true) = (&guides, specular && fh.valid) {
                        hist = clip::clip(hist, clip::range(&gd[s], w, h, i % w, i / w));
                    }
                    out.colour[s] = hist.lerp(cur[s], a);
                    let mc = moments(cur[s]);
                    m[s] = [
                        fh.moments[s][0] + (mc[0] - fh.moments[s][0]) * am,
                        fh.moments[s][1] + (mc[1] - fh.moments[s][1]) * am,
                    ];
                    out.variance[s] = (m[s][1] - m[s][0] * m[s][0]).max(0.0);
                }
                *len = length;
            });
        // 5. Spatial variance while the history is short.
        let spatial: Vec<Option<[f32; 2]>> = (0..n)
            .into_par_iter()
            .map(|i| {
                (f.class[i] != features::Class::Sky && lengths[i] < SHORT_HISTORY)
                    .then(|| spatial_variance(&f, p, &acc_moments, i, lengths[i]))
            })
            .collect();
        acc.par_iter_mut().zip(&spatial).for_each(|(a, s)| {
            if let Some(v) = s {
                a.variance = *v;
            }
        });
        // 6. À-Trous, keeping the feedback tap.
        let hold = [false, p.hold_indirect_variance];
        let mut ping = acc;
        let mut feedback = vec![Signals::default(); n];
        atrous::run(
            &f,
            p,
            &lengths,
            hold,
            self.simd,
            &mut self.scratch,
            &mut ping,
            &mut feedback,
        );
        // 7. Remodulate; median on diffuse pixels for display.
        let illumination: Vec<Rgb> = ping.par_iter().map(|s| s.colour[0] + s.colour[1]).collect();
        let shown = if p.median {
            median_diffuse(&f, &illumination)
        } else {
            illumination
        };
        let mut pixels: Vec<Rgb> = (0..n)
            .into_par_iter()
            .map(|i| {
                let e = input.emission.pixels()[i];
                let c = if f.class[i] == features::Class::Sky {
                    e + input.direct.pixels()[i] + input.indirect.pixels()[i]
                } else {
                    e + f.reflected_emission[i] + f.albedo[i].max(Rgb::splat(MIN_ALBEDO)) * shown[i]
                };
                if c.is_finite() {
                    c.max(Rgb::ZERO)
                } else {
                    Rgb::ZERO
                }
            })
            .collect();
        if let Some(gathered) = &gathered {
            supersample::resolve(&f, extra, gathered, &shown, &mut pixels);
        }
        let out = Image::new(w, h, pixels).expect("one output pixel per pixel");
        // Keep the history.
        // The previous history has been read: its buffers take the new one.
        let mut next = match self.history.take() {
            Some(mut old) => {
                old.refill(&f, g);
                old
            }
            None => History::from_frame(&f, g),
        };
        let [c0, c1] = &mut next.colour;
        let [m0, m1] = &mut next.moments;
        c0.par_iter_mut()
            .zip(c1.par_iter_mut())
            .zip(m0.par_iter_mut())
            .zip(m1.par_iter_mut())
            .zip(next.length.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((((c0, c1), m0), m1), len))| {
                *c0 = feedback[i].colour[0];
                *c1 = feedback[i].colour[1];
                *m0 = acc_moments[i][0];
                *m1 = acc_moments[i][1];
                *len = lengths[i];
            });
        self.history = Some(next);
        out
    }
}

/// Voorhuis §2.7 change 1: the variance of pixel `i` from its neighbours' accumulated moments
/// over a 7×7 window weighted by depth and normal, scaled by 4/h as Falcor does.
fn spatial_variance(
    f: &Features,
    p: &SvgfParams,
    moments: &[[[f32; 2]; 2]],
    i: usize,
    length: f32,
) -> [f32; 2] {
    let (x, y) = ((i % f.w) as isize, (i / f.w) as isize);
    let (z, n) = (f.depth[i], f.normal[i]);
    let z_scale = p.sigma_z * f.depth_step[i];
    let mirror = f.class[i] == features::Class::Mirror;
    let mut sum = [[0.0f32; 2]; 2];
    let mut wsum = 0.0f32;
    for yy in (y - SPATIAL_RADIUS).max(0)..=(y + SPATIAL_RADIUS).min(f.h as isize - 1) {
        for xx in (x - SPATIAL_RADIUS).max(0)..=(x + SPATIAL_RADIUS).min(f.w as isize - 1) {
            let j = yy as usize * f.w + xx as usize;
            let c = f.class[j];
            if c == features::Class::Sky || (c == features::Class::Mirror) != mirror {
                continue;
            }
            let dist = (((xx - x).pow(2) + (yy - y).pow(2)) as f32).sqrt();
            let wz = fast_exp::exp_neg(-(z - f.depth[j]).abs() / (z_scale * dist + 1e-3 * z));
            let w = wz * normal_weight(n.dot(f.normal[j]), p.sigma_n);
            for s in 0..2 {
                sum[s][0] += w * moments[j][s][0];
                sum[s][1] += w * moments[j][s][1];
            }
            wsum += w;
        }
    }
    if wsum <= 0.0 {
        return [0.0; 2];
    }
    let boost = SHORT_HISTORY / length.max(1.0);
    [0, 1].map(|s| {
        let m1 = sum[s][0] / wsum;
        let m2 = sum[s][1] / wsum;
        (m2 - m1 * m1).max(0.0) * boost
    })
}

/// The key whose integer order is `f32::total_cmp`'s order.
#[inline]
fn total_key(x: f32) -> i32 {
    let b = x.to_bits() as i32;
    b ^ (((b >> 31) as u32) >> 1) as i32
}

#[allow(unused_assignments)]
/// The median of 9 values in `f32::total_cmp`'s order: the 19 compare-exchanges of the
/// median-of-9 network (Paeth 1990, as in Devillard's `opt_med9`) on order keys, branch-free.
#[inline]
fn median9(v: [f32; 9]) -> f32 {
    let [mut p0, mut p1, mut p2, mut p3, mut p4, mut p5, mut p6, mut p7, mut p8] = v.map(total_key);
    macro_rules! sort {
        ($($a:ident $b:ident),*) => {
            $(
                let (x, y) = ($a, $b);
                $a = x.min(y);
                $b = x.max(y);
            )*
        };
    }
    sort!(
        p1 p2, p4 p5, p7 p8, p0 p1, p3 p4, p6 p7, p1 p2, p4 p5, p7 p8, p0 p3, p5 p8, p4 p7,
        p3 p6, p1 p4, p2 p5, p4 p7, p4 p2, p6 p4, p4 p2
    );
    let _ = (p0, p1, p3, p5, p7, p8);
    // The key is its own inverse.
    f32::from_bits(total_key(f32::from_bits(p4 as u32)) as u32)
}

/// Per-channel 3×3 median of diffuse pixels among their diffuse neighbours (Voorhuis §2.7
/// change 3); other pixels unchanged.
fn median_diffuse(f: &Features, img: &[Rgb]) -> Vec<Rgb> {
    (0..f.w * f.h)
        .into_par_iter()
        .map(|i| {
            if f.class[i] != features::Class::Diffuse {
                return img[i];
            }
            let (x, y) = ((i % f.w) as isize, (i / f.w) as isize);
            let mut vals = [[0.0f32; 9]; 3];
            let mut k = 0;
            for yy in (y - 1).max(0)..=(y + 1).min(f.h as isize - 1) {
                for xx in (x - 1).max(0)..=(x + 1).min(f.w as isize - 1) {
                    let j = yy as usize * f.w + xx as usize;
                    if f.class[j] == features::Class::Diffuse {
                        let c = img[j];
                        vals[0][k] = c.x;
                        vals[1][k] = c.y;
                        vals[2][k] = c.z;
                        k += 1;
                    }
                }
            }
            if k == 9 {
                return Rgb::new(median9(vals[0]), median9(vals[1]), median9(vals[2]));
            }
            Rgb::from_array(vals.map(|mut v| {
                let v = &mut v[..k];
                v.sort_unstable_by(f32::total_cmp);
                v[k / 2]
            }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median9_is_the_middle_of_the_total_order() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let pool = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            0.5,
            2.5,
            f32::INFINITY,
            1e-30,
            -7.0,
        ];
        for _ in 0..20_000 {
            let v: [f32; 9] = std::array::from_fn(|_| {
                let r = next();
                if r % 3 == 0 {
                    pool[(r >> 8) as usize % pool.len()]
                } else {
                    (r >> 16) as u16 as f32 / 997.0 - 30.0
                }
            });
            let mut sorted = v;
            sorted.sort_unstable_by(f32::total_cmp);
            assert_eq!(median9(v).to_bits(), sorted[4].to_bits(), "{v:?}");
        }
    }
}
