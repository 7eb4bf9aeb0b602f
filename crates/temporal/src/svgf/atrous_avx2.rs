//! One À-Trous iteration of [`super::atrous`] on [`super::planes`], eight pixels of a row at a
//! time with AVX2 intrinsics.
//!
//! Every lane does what [`super::atrous`]'s per-pixel code does, operation for operation and in
//! the same order (taps row by row, the same association of every sum and product, the
//! exponential of [`super::fast_exp::exp_neg`] step for step, no fused multiply-adds), so the
//! two give the same bits (tested). The per-pixel code's `continue`s become masks: a tap outside
//! the image, of another group or of zero base weight adds `+0` to every sum, which leaves it
//! unchanged as long as colours and variances are finite; callers check that
//! ([`super::planes::LevelPlanes::finite`]) and otherwise run the per-pixel code.
//!
//! The only `unsafe` of the crate: the call into the `#[target_feature]` row function after
//! runtime detection, and the unaligned vector loads and stores, each on a slice whose length
//! is checked just before.

use super::atrous::{normal_weight, KERNEL};
use super::fast_exp::CUTOFF;
use super::planes::{self, GuidePlanes, LevelPlanes, LEVEL_PLANES};
use rayon::prelude::*;
use std::arch::x86_64::*;

/// True if this CPU runs [`iterate`].
pub(crate) fn available() -> bool {
    std::is_x86_feature_detected!("avx2")
}

/// One iteration with taps `step` pixels apart, from `input` into `output` (resized to fit).
/// `hold[s]` keeps signal `s`'s variance. Callers check [`available`] first.
pub(crate) fn iterate(
    g: &GuidePlanes,
    sigma_n: f32,
    step: usize,
    hold: [bool; 2],
    input: &LevelPlanes,
    output: &mut LevelPlanes,
) {
    assert!(available(), "AVX2 row code called on a CPU without AVX2");
    output.resize(g.w, g.h);
    let stride = g.stride;
    output
        .data
        .par_chunks_mut(LEVEL_PLANES * stride)
        .enumerate()
        .for_each(|(y, out)| {
            // SAFETY: `available()` was asserted above: the CPU has AVX2.
            #[allow(unsafe_code)]
            unsafe {
                row(g, sigma_n, step, hold, input, y, out)
            }
        });
}

/// Eight values of plane row `run` starting at column `xs` (may be outside `0..w`): lanes
/// outside the image read 0, which for the group plane means sky, a group no tap is taken from.
#[target_feature(enable = "avx2")]
#[inline]
fn load(run: &[f32], xs: isize, w: usize) -> __m256 {
    if xs >= 0 && xs as usize + 8 <= w {
        let v = &run[xs as usize..xs as usize + 8];
        // SAFETY: `v` holds exactly 8 floats; the load is unaligned.
        #[allow(unsafe_code)]
        unsafe {
            _mm256_loadu_ps(v.as_ptr())
        }
    } else {
        let mut t = [0.0f32; 8];
        for (k, t) in t.iter_mut().enumerate() {
            let x = xs + k as isize;
            if x >= 0 && (x as usize) < w {
                *t = run[x as usize];
            }
        }
        // SAFETY: `t` holds 8 floats.
        #[allow(unsafe_code)]
        unsafe {
            _mm256_loadu_ps(t.as_ptr())
        }
    }
}

/// The 8 values at `at` (a padded row, so whole vectors are in bounds).
#[target_feature(enable = "avx2")]
#[inline]
fn load8(data: &[f32], at: usize) -> __m256 {
    let v = &data[at..at + 8];
    // SAFETY: `v` holds exactly 8 floats; the load is unaligned.
    #[allow(unsafe_code)]
    unsafe {
        _mm256_loadu_ps(v.as_ptr())
    }
}

#[target_feature(enable = "avx2")]
#[inline]
fn store8(data: &mut [f32], at: usize, v: __m256) {
    let d = &mut data[at..at + 8];
    // SAFETY: `d` holds exactly 8 floats; the store is unaligned.
    #[allow(unsafe_code)]
    unsafe {
        _mm256_storeu_ps(d.as_mut_ptr(), v)
    }
}

/// `-|a - b|`.
#[target_feature(enable = "avx2")]
#[inline]
fn neg_abs_diff(a: __m256, b: __m256) -> __m256 {
    _mm256_or_ps(_mm256_sub_ps(a, b), _mm256_set1_ps(-0.0))
}

/// [`super::fast_exp::exp_neg`] on eight lanes, with the same bits.
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn exp_neg(x: __m256) -> __m256 {
    // `x < CUTOFF || x.is_nan()` gives 0: keep the ordered `x >= CUTOFF`.
    let keep = _mm256_cmp_ps::<_CMP_GE_OQ>(x, _mm256_set1_ps(CUTOFF));
    let y = _mm256_mul_ps(
        _mm256_min_ps(x, _mm256_setzero_ps()),
        _mm256_set1_ps(std::f32::consts::LOG2_E),
    );
    // `(y - 0.5) as i32`: truncation; in range wherever `keep` holds.
    let ni = _mm256_cvttps_epi32(_mm256_sub_ps(y, _mm256_set1_ps(0.5)));
    let n = _mm256_cvtepi32_ps(ni);
    let t = _mm256_mul_ps(_mm256_sub_ps(y, n), _mm256_set1_ps(std::f32::consts::LN_2));
    const C720: f32 = 1.0 / 720.0;
    const C120: f32 = 1.0 / 120.0;
    const C24: f32 = 1.0 / 24.0;
    const C6: f32 = 1.0 / 6.0;
    let mut p = _mm256_mul_ps(t, _mm256_set1_ps(C720));
    for c in [C120, C24, C6, 0.5, 1.0] {
        p = _mm256_mul_ps(t, _mm256_add_ps(_mm256_set1_ps(c), p));
    }
    p = _mm256_add_ps(_mm256_set1_ps(1.0), p);
    let e = _mm256_slli_epi32::<23>(_mm256_max_epi32(
        _mm256_add_epi32(ni, _mm256_set1_epi32(127)),
        _mm256_set1_epi32(1),
    ));
    _mm256_and_ps(_mm256_mul_ps(p, _mm256_castsi256_ps(e)), keep)
}

/// [`normal_weight`] on eight lanes.
#[target_feature(enable = "avx2")]
#[inline]
fn normal_weight8(c: __m256, e: f32) -> __m256 {
    let square = |v: __m256| _mm256_mul_ps(v, v);
    if e == 64.0 || e == 128.0 {
        let mut v = _mm256_max_ps(c, _mm256_setzero_ps());
        for _ in 0..if e == 64.0 { 6 } else { 7 } {
            v = square(v);
        }
        v
    } else {
        let mut t = [0.0f32; 8];
        // SAFETY: `t` holds 8 floats.
        #[allow(unsafe_code)]
        unsafe {
            _mm256_storeu_ps(t.as_mut_ptr(), c)
        };
        for t in &mut t {
            *t = normal_weight(*t, e);
        }
        // SAFETY: `t` holds 8 floats.
        #[allow(unsafe_code)]
        unsafe {
            _mm256_loadu_ps(t.as_ptr())
        }
    }
}

/// Output row `y` (all planes of the row: `LEVEL_PLANES · stride` floats).
#[target_feature(enable = "avx2")]
fn row(
    g: &GuidePlanes,
    sigma_n: f32,
    step: usize,
    hold: [bool; 2],
    input: &LevelPlanes,
    y: usize,
    out: &mut [f32],
) {
    let (w, h, stride) = (g.w, g.h, g.stride);
    let gd = &g.data;
    let id = &input.data;
    let zero = _mm256_setzero_ps();
    let one = _mm256_set1_ps(1.0);
    let grow = |k: usize, yy: usize| &gd[g.row(k, yy)..g.row(k, yy) + stride];
    let irow = |k: usize, yy: usize| &id[input.row(k, yy)..input.row(k, yy) + stride];
    const GAUSS3: [f32; 3] = [0.25, 0.5, 0.25];
    for x0 in (0..w).step_by(8) {
        let c = |k: usize| load8(gd, g.row(k, y) + x0);
        let ci = |k: usize| load8(id, input.row(k, y) + x0);
        let grp = c(planes::GROUP);
        let surface = _mm256_cmp_ps::<_CMP_NEQ_OQ>(grp, zero);
        let outk = |k: usize| k * stride + x0;
        if _mm256_movemask_ps(surface) == 0 {
            // All sky (or padding): passed through.
            for k in 0..LEVEL_PLANES {
                store8(out, outk(k), ci(k));
            }
            continue;
        }
        let z = c(planes::DEPTH);
        let z_scale = c(planes::Z_SCALE);
        let z_eps = c(planes::Z_EPS);
        let (nx, ny, nz) = (c(planes::NX), c(planes::NY), c(planes::NZ));
        let spatial = c(planes::SPATIAL);
        let has_spatial = _mm256_cmp_ps::<_CMP_GT_OQ>(spatial, zero);
        let any_spatial = g.any_spatial && _mm256_movemask_ps(has_spatial) != 0;
        let sl = c(planes::SIGMA_L);
        // The 3×3-Gaussian-prefiltered variances and the luminance scales.
        let mut vsum = [zero; 2];
        let mut vw = zero;
        for (dy, wy) in GAUSS3.iter().enumerate() {
            let yy = y as isize + dy as isize - 1;
            if yy < 0 || yy >= h as isize {
                continue;
            }
            let yy = yy as usize;
            for (dx, wx) in GAUSS3.iter().enumerate() {
                let xs = x0 as isize + dx as isize - 1;
                let ok = _mm256_cmp_ps::<_CMP_NEQ_OQ>(load(grow(planes::GROUP, yy), xs, w), zero);
                let wxy = _mm256_set1_ps(wx * wy);
                for (s, sum) in vsum.iter_mut().enumerate() {
                    let v = load(irow(planes::signal(s) + planes::VAR, yy), xs, w);
                    *sum = _mm256_add_ps(*sum, _mm256_and_ps(_mm256_mul_ps(wxy, v), ok));
                }
                vw = _mm256_add_ps(vw, _mm256_and_ps(wxy, ok));
            }
        }
        let vw_pos = _mm256_cmp_ps::<_CMP_GT_OQ>(vw, zero);
        let lum = [0, 1].map(|s| ci(planes::signal(s) + planes::LUM));
        let l_scale = vsum.map(|sum| {
            let pv = _mm256_and_ps(_mm256_div_ps(sum, vw), vw_pos);
            _mm256_div_ps(
                one,
                _mm256_add_ps(_mm256_mul_ps(sl, _mm256_sqrt_ps(pv)), _mm256_set1_ps(1e-10)),
            )
        });
        // Σ w·c (r, g, b), Σ w, Σ w²·Var per signal.
        let mut acc = [[zero; 5]; 2];
        for (ky, hy) in KERNEL.iter().enumerate() {
            let dy = ky as isize - 2;
            let yy = y as isize + dy * step as isize;
            if yy < 0 || yy >= h as isize {
                continue;
            }
            let yy = yy as usize;
            for (kx, hx) in KERNEL.iter().enumerate() {
                let dx = kx as isize - 2;
                let xs = x0 as isize + dx * step as isize;
                if xs + 8 <= 0 || xs >= w as isize {
                    continue;
                }
                let q = |k: usize| load(grow(k, yy), xs, w);
                let same = _mm256_cmp_ps::<_CMP_EQ_OQ>(q(planes::GROUP), grp);
                let taps2 = (dx * dx + dy * dy) as f32;
                let dist = step as f32 * taps2.sqrt();
                let ez = _mm256_div_ps(
                    neg_abs_diff(z, q(planes::DEPTH)),
                    _mm256_add_ps(_mm256_mul_ps(z_scale, _mm256_set1_ps(dist)), z_eps),
                );
                let dot = _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(nx, q(planes::NX)),
                        _mm256_mul_ps(ny, q(planes::NY)),
                    ),
                    _mm256_mul_ps(nz, q(planes::NZ)),
                );
                let mut base = _mm256_mul_ps(_mm256_set1_ps(hx * hy), normal_weight8(dot, sigma_n));
                if any_spatial {
                    let gauss = exp_neg(_mm256_div_ps(_mm256_set1_ps(-taps2), spatial));
                    base = _mm256_mul_ps(base, _mm256_blendv_ps(one, gauss, has_spatial));
                }
                let base = _mm256_and_ps(base, same);
                for (s, a) in acc.iter_mut().enumerate() {
                    let o = planes::signal(s);
                    let qs = |k: usize| load(irow(o + k, yy), xs, w);
                    let el = _mm256_mul_ps(neg_abs_diff(lum[s], qs(planes::LUM)), l_scale[s]);
                    let wgt = _mm256_mul_ps(base, exp_neg(_mm256_add_ps(ez, el)));
                    for (ch, k) in [planes::R, planes::G, planes::B].into_iter().enumerate() {
                        a[ch] = _mm256_add_ps(a[ch], _mm256_mul_ps(qs(k), wgt));
                    }
                    a[3] = _mm256_add_ps(a[3], wgt);
                    a[4] = _mm256_add_ps(
                        a[4],
                        _mm256_mul_ps(_mm256_mul_ps(wgt, wgt), qs(planes::VAR)),
                    );
                }
            }
        }
        for (s, a) in acc.iter().enumerate() {
            let o = planes::signal(s);
            // Filtered where the sum of weights is positive (the per-pixel code's test) and
            // the pixel is no sky; the centre elsewhere.
            let take = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(a[3], zero), surface);
            let mut rgb = [zero; 3];
            for (ch, k) in [planes::R, planes::G, planes::B].into_iter().enumerate() {
                rgb[ch] = _mm256_blendv_ps(ci(o + k), _mm256_div_ps(a[ch], a[3]), take);
                store8(out, outk(o + k), rgb[ch]);
            }
            let var = if hold[s] {
                ci(o + planes::VAR)
            } else {
                _mm256_blendv_ps(
                    ci(o + planes::VAR),
                    _mm256_div_ps(a[4], _mm256_mul_ps(a[3], a[3])),
                    take,
                )
            };
            store8(out, outk(o + planes::VAR), var);
            // luminance(c) = 0.2126·r + 0.7152·g + 0.0722·b, summed left to right.
            let l = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_set1_ps(0.2126), rgb[0]),
                    _mm256_mul_ps(_mm256_set1_ps(0.7152), rgb[1]),
                ),
                _mm256_mul_ps(_mm256_set1_ps(0.0722), rgb[2]),
            );
            store8(out, outk(o + planes::LUM), l);
        }
    }
}
