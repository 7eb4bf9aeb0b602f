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
//! The rows read [`super::planes`] with zero margins of at least two tap steps, so every tap
//! is a whole-vector load; out of the image it reads group 0, and no tap is taken from it.
//!
//! The only `unsafe` of the crate: the call into the `#[target_feature]` row function after
//! runtime detection, the unaligned vector loads and stores on slices of checked length, and
//! the taps' loads, unchecked under the layout assertions made once per row.

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
    output.reshape(g.layout);
    output
        .data
        .par_chunks_mut(LEVEL_PLANES * g.layout.len)
        .enumerate()
        .for_each(|(y, out)| {
            #[allow(unsafe_code)]
            // SAFETY: `available()` was asserted above: the CPU has AVX2.
            unsafe {
                row(g, sigma_n, step, hold, input, y, out)
            }
        });
}

/// The 8 values at `at`.
#[target_feature(enable = "avx2")]
#[inline]
fn load8(data: &[f32], at: usize) -> __m256 {
    let v = &data[at..at + 8];
    #[allow(unsafe_code)]
    // SAFETY: `v` holds exactly 8 floats; the load is unaligned.
    unsafe {
        _mm256_loadu_ps(v.as_ptr())
    }
}

/// The 8 values at `at + k·l` for each `k` of `ks`, unchecked.
///
/// # Safety
/// `at + k·l + 8 ≤ data.len()` for every `k` of `ks`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn gather<const N: usize>(data: &[f32], at: usize, l: usize, ks: [usize; N]) -> [__m256; N] {
    let mut out = [_mm256_setzero_ps(); N];
    for (o, &k) in out.iter_mut().zip(&ks) {
        debug_assert!(at + k * l + 8 <= data.len());
        // SAFETY: in bounds by the caller's contract.
        *o = unsafe { _mm256_loadu_ps(data.as_ptr().add(at + k * l)) };
    }
    out
}

#[target_feature(enable = "avx2")]
#[inline]
fn store8(data: &mut [f32], at: usize, v: __m256) {
    let d = &mut data[at..at + 8];
    #[allow(unsafe_code)]
    // SAFETY: `d` holds exactly 8 floats; the store is unaligned.
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
    if e == 64.0 || e == 128.0 {
        let mut v = _mm256_max_ps(c, _mm256_setzero_ps());
        for _ in 0..if e == 64.0 { 6 } else { 7 } {
            v = _mm256_mul_ps(v, v);
        }
        v
    } else {
        let mut t = [0.0f32; 8];
        #[allow(unsafe_code)]
        // SAFETY: `t` holds 8 floats.
        unsafe {
            _mm256_storeu_ps(t.as_mut_ptr(), c)
        };
        for t in &mut t {
            *t = normal_weight(*t, e);
        }
        #[allow(unsafe_code)]
        // SAFETY: `t` holds 8 floats.
        unsafe {
            _mm256_loadu_ps(t.as_ptr())
        }
    }
}

/// What the luminance-independent part of one tap gives eight pixels.
#[derive(Clone, Copy)]
struct Tap {
    /// Index of the tap's 8 values in the input's plane 0.
    at: usize,
    /// `h_x·h_y·w_n` (times Eq. 6's Gaussian), 0 where no tap is taken.
    base: __m256,
    /// The depth term's exponent.
    ez: __m256,
}

/// Σ w·c (r, g, b), Σ w and (if `VAR`) Σ w²·Var of signal planes `o..` over `taps`, for
/// centre luminance `lum` and luminance scale `l_scale`.
#[target_feature(enable = "avx2")]
#[inline]
fn accumulate<const VAR: bool>(
    id: &[f32],
    l: usize,
    o: usize,
    lum: __m256,
    l_scale: __m256,
    taps: &[Tap],
) -> [__m256; 5] {
    let zero = _mm256_setzero_ps();
    let (mut sr, mut sg, mut sb, mut sw, mut sv) = (zero, zero, zero, zero, zero);
    for t in taps {
        #[allow(unsafe_code)]
        // SAFETY: `t.at` is a tap of `row` (row `0 ≤ yy < h`, offset `|dx| ≤ 2·step`), and
        // `o + LUM < LEVEL_PLANES`: in bounds by `row`'s assertions.
        let [qr, qg, qb, qv, ql] = unsafe {
            gather(
                id,
                t.at + o * l,
                l,
                [planes::R, planes::G, planes::B, planes::VAR, planes::LUM],
            )
        };
        let el = _mm256_mul_ps(neg_abs_diff(lum, ql), l_scale);
        let wgt = _mm256_mul_ps(t.base, exp_neg(_mm256_add_ps(t.ez, el)));
        sr = _mm256_add_ps(sr, _mm256_mul_ps(qr, wgt));
        sg = _mm256_add_ps(sg, _mm256_mul_ps(qg, wgt));
        sb = _mm256_add_ps(sb, _mm256_mul_ps(qb, wgt));
        sw = _mm256_add_ps(sw, wgt);
        if VAR {
            sv = _mm256_add_ps(sv, _mm256_mul_ps(_mm256_mul_ps(wgt, wgt), qv));
        }
    }
    [sr, sg, sb, sw, sv]
}

/// Output row `y` (all planes of the row: `LEVEL_PLANES · len` floats, margins untouched).
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
    let lay = g.layout;
    let (w, h) = (lay.w, lay.h);
    // What makes every `gather` in bounds: plane `k < planes` of row `0 ≤ yy < h` at column
    // `x0 + dx` with `0 ≤ x0 ≤ stride − 8` and `|dx| ≤ 2·step ≤ margin` is a run of 8 inside
    // the row's `len = margin + stride + margin` floats, and the data holds `planes·h` rows.
    assert!(lay.margin >= 2 * step && lay.len == lay.stride + 2 * lay.margin);
    assert!(input.layout == lay && lay.stride.is_multiple_of(8) && lay.stride >= lay.w);
    assert!(g.data.len() >= planes::GUIDE_PLANES * lay.h * lay.len);
    assert!(input.data.len() >= LEVEL_PLANES * lay.h * lay.len);
    let gd = &g.data;
    let id = &input.data;
    let zero = _mm256_setzero_ps();
    let one = _mm256_set1_ps(1.0);
    const GAUSS3: [f32; 3] = [0.25, 0.5, 0.25];
    let l = lay.len;
    let mut taps = [Tap {
        at: 0,
        base: zero,
        ez: zero,
    }; 25];
    for x0 in (0..w).step_by(8) {
        // Centre values; `at(k)` is the index of this vector in guide or level plane `k`'s
        // row `yy`, shifted by `dx` (the margins make every tap's load in bounds).
        let gat = |k: usize, yy: usize, dx: isize| (g.row(k, yy) + x0).wrapping_add_signed(dx);
        let iat = |k: usize, yy: usize, dx: isize| (input.row(k, yy) + x0).wrapping_add_signed(dx);
        let grp = load8(gd, gat(planes::GROUP, y, 0));
        let centre = iat(0, y, 0);
        let surface = _mm256_cmp_ps::<_CMP_NEQ_OQ>(grp, zero);
        let outk = |k: usize| k * lay.len + lay.margin + x0;
        if _mm256_movemask_ps(surface) == 0 {
            // All sky (or padding): passed through.
            for k in 0..LEVEL_PLANES {
                store8(out, outk(k), load8(id, iat(k, y, 0)));
            }
            continue;
        }
        // The luminance-independent part of every tap.
        let mut n_taps = 0;
        {
            use planes::{DEPTH, GROUP, NX, NY, NZ, SPATIAL, Z_EPS, Z_SCALE};
            #[allow(unsafe_code)]
            // SAFETY: `row`'s assertions (the centre: `y < h`, `dx = 0`).
            let [z, z_scale, z_eps, nx, ny, nz, spatial] = unsafe {
                gather(
                    gd,
                    gat(0, y, 0),
                    l,
                    [DEPTH, Z_SCALE, Z_EPS, NX, NY, NZ, SPATIAL],
                )
            };
            let has_spatial = _mm256_cmp_ps::<_CMP_GT_OQ>(spatial, zero);
            let any_spatial = g.any_spatial && _mm256_movemask_ps(has_spatial) != 0;
            for (ky, hy) in KERNEL.iter().enumerate() {
                let dy = ky as isize - 2;
                let yy = y as isize + dy * step as isize;
                if yy < 0 || yy >= h as isize {
                    continue;
                }
                let yy = yy as usize;
                for (kx, hx) in KERNEL.iter().enumerate() {
                    let dx = (kx as isize - 2) * step as isize;
                    let xs = x0 as isize + dx;
                    if xs + 8 <= 0 || xs >= w as isize {
                        continue;
                    }
                    #[allow(unsafe_code)]
                    // SAFETY: `row`'s assertions; `0 ≤ yy < h` and `|dx| ≤ 2·step`.
                    let [q_group, q_depth, q_nx, q_ny, q_nz] =
                        unsafe { gather(gd, gat(0, yy, dx), l, [GROUP, DEPTH, NX, NY, NZ]) };
                    let same = _mm256_cmp_ps::<_CMP_EQ_OQ>(q_group, grp);
                    let taps2 = ((kx as isize - 2).pow(2) + dy * dy) as f32;
                    let dist = step as f32 * taps2.sqrt();
                    let ez = _mm256_div_ps(
                        neg_abs_diff(z, q_depth),
                        _mm256_add_ps(_mm256_mul_ps(z_scale, _mm256_set1_ps(dist)), z_eps),
                    );
                    let dot = _mm256_add_ps(
                        _mm256_add_ps(_mm256_mul_ps(nx, q_nx), _mm256_mul_ps(ny, q_ny)),
                        _mm256_mul_ps(nz, q_nz),
                    );
                    let mut base =
                        _mm256_mul_ps(_mm256_set1_ps(hx * hy), normal_weight8(dot, sigma_n));
                    if any_spatial {
                        let gauss = exp_neg(_mm256_div_ps(_mm256_set1_ps(-taps2), spatial));
                        base = _mm256_mul_ps(base, _mm256_blendv_ps(one, gauss, has_spatial));
                    }
                    let base = _mm256_and_ps(base, same);
                    if _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_NEQ_OQ>(base, zero)) == 0 {
                        // Weight 0 in every lane: it would add +0 everywhere.
                        continue;
                    }
                    taps[n_taps] = Tap {
                        at: iat(0, yy, dx),
                        base,
                        ez,
                    };
                    n_taps += 1;
                }
            }
        }
        // The 3×3-Gaussian-prefiltered variances' weights.
        let mut vw = zero;
        let mut oks = [zero; 9];
        for (dy, wy) in GAUSS3.iter().enumerate() {
            let yy = y as isize + dy as isize - 1;
            if yy < 0 || yy >= h as isize {
                continue;
            }
            for (dx, wx) in GAUSS3.iter().enumerate() {
                let q = load8(gd, gat(planes::GROUP, yy as usize, dx as isize - 1));
                let ok = _mm256_cmp_ps::<_CMP_NEQ_OQ>(q, zero);
                oks[3 * dy + dx] = ok;
                vw = _mm256_add_ps(vw, _mm256_and_ps(_mm256_set1_ps(wx * wy), ok));
            }
        }
        let vw_pos = _mm256_cmp_ps::<_CMP_GT_OQ>(vw, zero);
        let sl = load8(gd, gat(planes::SIGMA_L, y, 0));
        for (s, &held) in hold.iter().enumerate() {
            let o = planes::signal(s);
            let mut vsum = zero;
            for (dy, wy) in GAUSS3.iter().enumerate() {
                let yy = y as isize + dy as isize - 1;
                if yy < 0 || yy >= h as isize {
                    continue;
                }
                for (dx, wx) in GAUSS3.iter().enumerate() {
                    let v = load8(id, iat(o + planes::VAR, yy as usize, dx as isize - 1));
                    let wv = _mm256_mul_ps(_mm256_set1_ps(wx * wy), v);
                    vsum = _mm256_add_ps(vsum, _mm256_and_ps(wv, oks[3 * dy + dx]));
                }
            }
            let pv = _mm256_and_ps(_mm256_div_ps(vsum, vw), vw_pos);
            let l_scale = _mm256_div_ps(
                one,
                _mm256_add_ps(_mm256_mul_ps(sl, _mm256_sqrt_ps(pv)), _mm256_set1_ps(1e-10)),
            );
            let lum = load8(id, centre + (o + planes::LUM) * l);
            let [sr, sg, sb, sw, sv] = if held {
                accumulate::<false>(id, l, o, lum, l_scale, &taps[..n_taps])
            } else {
                accumulate::<true>(id, l, o, lum, l_scale, &taps[..n_taps])
            };
            // Filtered where the sum of weights is positive (the per-pixel code's test) and
            // the pixel is no sky; the centre elsewhere.
            let ci = |k: usize| load8(id, centre + (o + k) * l);
            let take = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(sw, zero), surface);
            let r = _mm256_blendv_ps(ci(planes::R), _mm256_div_ps(sr, sw), take);
            let gr = _mm256_blendv_ps(ci(planes::G), _mm256_div_ps(sg, sw), take);
            let b = _mm256_blendv_ps(ci(planes::B), _mm256_div_ps(sb, sw), take);
            let var = if held {
                ci(planes::VAR)
            } else {
                _mm256_blendv_ps(
                    ci(planes::VAR),
                    _mm256_div_ps(sv, _mm256_mul_ps(sw, sw)),
                    take,
                )
            };
            // luminance(c) = 0.2126·r + 0.7152·g + 0.0722·b, summed left to right.
            let l = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_set1_ps(0.2126), r),
                    _mm256_mul_ps(_mm256_set1_ps(0.7152), gr),
                ),
                _mm256_mul_ps(_mm256_set1_ps(0.0722), b),
            );
            store8(out, outk(o + planes::R), r);
            store8(out, outk(o + planes::G), gr);
            store8(out, outk(o + planes::B), b);
            store8(out, outk(o + planes::VAR), var);
            store8(out, outk(o + planes::LUM), l);
        }
    }
}
