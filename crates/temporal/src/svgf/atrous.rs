//! One iteration of SVGF's variance-guided edge-avoiding À-Trous wavelet filter (Schied et al.
//! 2017 §4.3, after Dammertz et al. 2010): 5×5 B3-spline taps `step` pixels apart, weighted by
//!
//! - depth: `exp(−|z_p − z_q| / (σ_z·|∇z_p|·|p − q| + 10⁻³·z_p))`,
//! - normal: `max(0, n_p·n_q)^σ_n`,
//! - luminance: `exp(−|l_p − l_q| / (σ_l·√(g₃ₓ₃(Var l_p)) + ε))`,
//!
//! and, for sharp glossy pixels, a spatial Gaussian whose width Voorhuis' Eq. 6 narrows as the
//! reflection's world footprint grows. The variance is carried along with squared weights
//! (`Var' = Σ h²w² Var / (Σ h w)²`), so it shrinks from iteration to iteration.
//!
//! Two builds of the same arithmetic: the per-pixel code here (portable, and the reference),
//! and [`super::atrous_avx2`], eight pixels at a time on structure-of-arrays planes
//! ([`super::planes`]) where the CPU has AVX2; they give the same bits (tests/svgf_bits.rs).
//!
//! Deviations (\[ours\]): |∇z| is the largest depth step to a 4-neighbour of the same kind, not a
//! screen-space derivative; the depth term's ε is relative to depth; taps across the edge of a
//! mirror (mirror vs non-mirror) get no weight, since their features describe different
//! surfaces; Eq. 6's σ is read in units of two taps, so σ = 1 is a mild falloff over the 5×5
//! footprint and σ → 0 keeps the pixel alone.

use super::fast_exp::exp_neg;
use super::features::{Class, Features};
use super::params::SvgfParams;
use super::planes::{GuidePlanes, LevelPlanes};
use rayon::prelude::*;
use rt_core::color::luminance;
use rt_core::Rgb;

/// B3-spline taps at offsets −2..=2.
pub const KERNEL: [f32; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];
/// The 3×3 Gaussian the variance is prefiltered with (Schied: corner 1/16, edge 1/8, centre 1/4).
const GAUSS3: [f32; 3] = [0.25, 0.5, 0.25];

/// Both signals of one pixel at one level: demodulated colour and the variance of its
/// luminance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Signals {
    /// Demodulated colour of the direct and the indirect light.
    pub colour: [Rgb; 2],
    /// Variance of their luminance.
    pub variance: [f32; 2],
}

/// σ_l of pixel `i` after Voorhuis' Eq. 8 (wider while the history is short).
#[inline]
pub fn sigma_l(p: &SvgfParams, length: f32) -> f32 {
    if p.wide_start {
        p.sigma_l * (8.0 - length.min(7.0)).max(1.0)
    } else {
        p.sigma_l
    }
}

/// `max(0, c)^e`, exact for the usual powers of two without calling `powf`.
#[inline]
pub fn normal_weight(c: f32, e: f32) -> f32 {
    let c = c.max(0.0);
    if e == 64.0 {
        let c2 = c * c;
        let c4 = c2 * c2;
        let c8 = c4 * c4;
        let c16 = c8 * c8;
        let c32 = c16 * c16;
        c32 * c32
    } else if e == 128.0 {
        let c64 = normal_weight(c, 64.0);
        c64 * c64
    } else {
        c.powf(e)
    }
}

/// The 3×3-Gaussian-filtered variance of signal `s` at `(x, y)`.
fn prefiltered_variance(f: &Features, input: &[Signals], x: usize, y: usize, s: usize) -> f32 {
    let (mut sum, mut wsum) = (0.0f32, 0.0f32);
    for (dy, wy) in GAUSS3.iter().enumerate() {
        let yy = y as isize + dy as isize - 1;
        if yy < 0 || yy >= f.h as isize {
            continue;
        }
        for (dx, wx) in GAUSS3.iter().enumerate() {
            let xx = x as isize + dx as isize - 1;
            if xx < 0 || xx >= f.w as isize {
                continue;
            }
            let j = yy as usize * f.w + xx as usize;
            if f.class[j] == Class::Sky {
                continue;
            }
            sum += wx * wy * input[j].variance[s];
            wsum += wx * wy;
        }
    }
    if wsum > 0.0 {
        sum / wsum
    } else {
        0.0
    }
}

/// Buffers of the iterations, kept across frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct Scratch {
    guide: GuidePlanes,
    ping: LevelPlanes,
    pong: LevelPlanes,
    /// A level as [`Signals`], for iterations the vector code does not take.
    aos: Vec<Signals>,
}

/// True if [`run`] with `simd` uses the AVX2 row code on this CPU.
pub(crate) fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        super::atrous_avx2::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// All `p.iterations` iterations on `signals` (in place: on return the last level), the
/// output of iteration `p.feedback` copied into `feedback` (the input if 0, the last level if
/// there is no such iteration). `simd` allows the AVX2 row code; both paths give the same
/// bits.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    f: &Features,
    p: &SvgfParams,
    lengths: &[f32],
    hold: [bool; 2],
    simd: bool,
    scratch: &mut Scratch,
    signals: &mut [Signals],
    feedback: &mut [Signals],
) {
    if p.feedback == 0 || p.feedback > p.iterations {
        feedback.copy_from_slice(signals);
    }
    if simd && simd_available() && p.iterations > 0 {
        #[cfg(target_arch = "x86_64")]
        {
            let Scratch {
                guide,
                ping,
                pong,
                aos,
            } = scratch;
            guide.fill(f, p, lengths, 1 << (p.iterations - 1));
            ping.load(guide.layout, signals);
            for it in 0..p.iterations {
                let step = 1usize << it;
                if ping.finite() {
                    super::atrous_avx2::iterate(guide, p.sigma_n, step, hold, ping, pong);
                } else {
                    // A non-finite value: the per-pixel code, which skips what the vector
                    // code would multiply by zero.
                    aos.resize(signals.len(), Signals::default());
                    ping.store(signals);
                    iterate_portable(f, p, lengths, step, hold, signals, aos);
                    pong.load(guide.layout, aos);
                }
                std::mem::swap(ping, pong);
                if it + 1 == p.feedback {
                    ping.store(feedback);
                }
            }
            ping.store(signals);
            if p.feedback > p.iterations {
                feedback.copy_from_slice(signals);
            }
            return;
        }
    }
    let aos = &mut scratch.aos;
    aos.resize(signals.len(), Signals::default());
    for it in 0..p.iterations {
        iterate_portable(f, p, lengths, 1 << it, hold, signals, aos);
        signals.copy_from_slice(aos);
        if it + 1 == p.feedback {
            feedback.copy_from_slice(signals);
        }
    }
    if p.feedback > p.iterations {
        feedback.copy_from_slice(signals);
    }
}

/// One iteration with taps `step` pixels apart, from `input` into `output` (the vector code
/// where it runs, else the per-pixel code). `hold[s]` keeps signal `s`'s variance as it was
/// instead of propagating it.
#[cfg(test)]
pub fn iterate(
    f: &Features,
    p: &SvgfParams,
    lengths: &[f32],
    step: usize,
    hold: [bool; 2],
    input: &[Signals],
    output: &mut [Signals],
) {
    #[cfg(target_arch = "x86_64")]
    if simd_available() {
        let mut g = GuidePlanes::default();
        g.fill(f, p, lengths, step);
        let (mut a, mut b) = (LevelPlanes::default(), LevelPlanes::default());
        a.load(g.layout, input);
        assert!(a.finite());
        super::atrous_avx2::iterate(&g, p.sigma_n, step, hold, &a, &mut b);
        b.store(output);
        return;
    }
    iterate_portable(f, p, lengths, step, hold, input, output);
}

/// The per-pixel code of one iteration with taps `step` pixels apart, from `input` into
/// `output`. `hold[s]` keeps signal `s`'s variance as it was instead of propagating it.
pub(crate) fn iterate_portable(
    f: &Features,
    p: &SvgfParams,
    lengths: &[f32],
    step: usize,
    hold: [bool; 2],
    input: &[Signals],
    output: &mut [Signals],
) {
    output.par_chunks_mut(f.w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            *out = pixel(f, p, lengths, step, hold, input, x, y);
        }
    });
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn pixel(
    f: &Features,
    p: &SvgfParams,
    lengths: &[f32],
    step: usize,
    hold: [bool; 2],
    input: &[Signals],
    x: usize,
    y: usize,
) -> Signals {
    let i = y * f.w + x;
    let centre = input[i];
    let class = f.class[i];
    if class == Class::Sky {
        return centre;
    }
    let z = f.depth[i];
    let n = f.normal[i];
    let z_scale = p.sigma_z * f.depth_step[i];
    let z_eps = 1e-3 * z;
    let sl = sigma_l(p, lengths[i]);
    let lum = [luminance(centre.colour[0]), luminance(centre.colour[1])];
    let l_scale = [
        1.0 / (sl * prefiltered_variance(f, input, x, y, 0).sqrt() + 1e-10),
        1.0 / (sl * prefiltered_variance(f, input, x, y, 1).sqrt() + 1e-10),
    ];
    let spatial = f.sigma_spatial[i];
    let mirror = class == Class::Mirror;
    let mut sum_c = [Rgb::ZERO; 2];
    let mut sum_w = [0.0f32; 2];
    let mut sum_v = [0.0f32; 2];
    for (ky, hy) in KERNEL.iter().enumerate() {
        let dy = ky as isize - 2;
        let yy = y as isize + dy * step as isize;
        if yy < 0 || yy >= f.h as isize {
            continue;
        }
        for (kx, hx) in KERNEL.iter().enumerate() {
            let dx = kx as isize - 2;
            let xx = x as isize + dx * step as isize;
            if xx < 0 || xx >= f.w as isize {
                continue;
            }
            let j = yy as usize * f.w + xx as usize;
            let cq = f.class[j];
            if cq == Class::Sky || (cq == Class::Mirror) != mirror {
                continue;
            }
            let q = &input[j];
            let taps2 = (dx * dx + dy * dy) as f32;
            let dist = step as f32 * taps2.sqrt();
            let ez = -(z - f.depth[j]).abs() / (z_scale * dist + z_eps);
            let mut base = hx * hy * normal_weight(n.dot(f.normal[j]), p.sigma_n);
            if spatial > 0.0 {
                // Eq. 6's σ in units of two taps ([ours], see the module doc).
                let s = (2.0 * spatial).max(1e-3);
                base *= exp_neg(-taps2 / (2.0 * s * s));
            }
            if base <= 0.0 {
                continue;
            }
            for s in 0..2 {
                let el = -(lum[s] - luminance(q.colour[s])).abs() * l_scale[s];
                let w = base * exp_neg(ez + el);
                sum_c[s] += q.colour[s] * w;
                sum_w[s] += w;
                sum_v[s] += w * w * q.variance[s];
            }
        }
    }
    let mut out = centre;
    for s in 0..2 {
        // The centre tap always has weight > 0, so sum_w > 0 unless the exponent underflowed.
        if sum_w[s] > 0.0 {
            out.colour[s] = sum_c[s] / sum_w[s];
            if !hold[s] {
                out.variance[s] = sum_v[s] / (sum_w[s] * sum_w[s]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::glam::{Vec2, Vec3};
    use rt_core::Image;
    use rt_film::{GuideBuffers, NO_ID};

    fn flat(w: usize, h: usize) -> GuideBuffers {
        GuideBuffers {
            depth: Image::filled(w, h, 3.0),
            position: Image::filled(w, h, Vec3::ZERO),
            normal: Image::filled(w, h, Vec3::Y),
            albedo: Image::filled(w, h, Rgb::ONE),
            emission: Image::filled(w, h, Rgb::ZERO),
            motion: Image::filled(w, h, Vec2::ZERO),
            previous_depth: Image::filled(w, h, 3.0),
            object: Image::filled(w, h, 0),
            instance: Image::filled(w, h, NO_ID),
            roughness: Image::filled(w, h, 1.0),
            reflected: None,
        }
    }

    #[test]
    fn variance_propagates_with_squared_kernel_weights() {
        // Equal features and equal colours make every edge-stopping weight 1, so each tap's
        // weight is the B3 product alone and Var' = Σ (h_x h_y)² Var_q.
        let (w, h) = (16, 16);
        let p = SvgfParams::default();
        let f = Features::new(&flat(w, h), &p);
        let input: Vec<Signals> = (0..w * h)
            .map(|i| Signals {
                colour: [Rgb::splat(0.7); 2],
                variance: [(i % 7) as f32 * 0.1, (i % 5) as f32 * 0.2],
            })
            .collect();
        let mut out = vec![Signals::default(); w * h];
        for step in [1usize, 2] {
            iterate(
                &f,
                &p,
                &vec![10.0; w * h],
                step,
                [false, true],
                &input,
                &mut out,
            );
            let (x, y) = (8, 7);
            let mut expected = 0.0f32;
            for (ky, hy) in KERNEL.iter().enumerate() {
                for (kx, hx) in KERNEL.iter().enumerate() {
                    let xx = x + (kx as isize - 2) * step as isize;
                    let yy = y + (ky as isize - 2) * step as isize;
                    let q = yy as usize * w + xx as usize;
                    expected += (hx * hy).powi(2) * input[q].variance[0];
                }
            }
            let got = out[y as usize * w + x as usize];
            assert!(
                (got.variance[0] - expected).abs() < 1e-6,
                "{} vs {expected}",
                got.variance[0]
            );
            // The held signal keeps its variance; the colour of a constant image is unchanged.
            assert_eq!(got.variance[1], input[7 * w + 8].variance[1]);
            assert!((got.colour[0] - Rgb::splat(0.7)).abs().max_element() < 1e-6);
        }
    }

    #[test]
    fn depth_and_normal_edges_stop_the_filter() {
        // Left half at depth 3 facing +y, right half at depth 9 facing +x, different light.
        let (w, h) = (16, 8);
        let mut g = flat(w, h);
        for y in 0..h {
            for x in w / 2..w {
                g.depth.pixels_mut()[y * w + x] = 9.0;
                g.normal.pixels_mut()[y * w + x] = Vec3::X;
            }
        }
        let p = SvgfParams::default();
        let f = Features::new(&g, &p);
        let input: Vec<Signals> = (0..w * h)
            .map(|i| Signals {
                colour: [Rgb::splat(if i % w < w / 2 { 1.0 } else { 5.0 }); 2],
                variance: [1.0; 2],
            })
            .collect();
        let mut out = vec![Signals::default(); w * h];
        iterate(&f, &p, &vec![10.0; w * h], 1, [false; 2], &input, &mut out);
        for y in 0..h {
            assert!((out[y * w + w / 2 - 1].colour[0].x - 1.0).abs() < 1e-4);
            assert!((out[y * w + w / 2].colour[0].x - 5.0).abs() < 1e-4);
        }
    }
}
