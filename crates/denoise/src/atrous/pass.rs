//! One level of the edge-avoiding À-Trous transform (thesis Listing 6.3): every output pixel is
//! the edge-weighted mean of 25 taps of the previous level, `2^i` pixels apart.
//!
//! Output rows are independent, so rayon hands out rows (disjoint output slices) and every
//! pixel's taps are added in the same order whatever the thread count: the result has the
//! same bits on any number of threads. Within a row the work is done in chunks of
//! [`CHUNK`] pixels, tap by tap, so the accumulators and the 18 guide runs stay in L1 and the
//! per-tap loop over a chunk is a plain loop over equal-length slices that the compiler
//! vectorises. [`super::simd`] compiles the same row code a second time with AVX2 enabled;
//! since neither copy uses fused multiply-adds and lanes never mix, both give identical bits.

use super::kernel::{exp_neg, kernel_2d, tap_offsets};
use super::planes::Planes;

/// Pixels per chunk of a row: 22 runs of 256 floats (22 KiB) fit in L1.
const CHUNK: usize = 256;

/// Which edge-stopping weights a pass uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Weights {
    /// `c_w`, on the colour of the level being filtered.
    pub(crate) colour: bool,
    /// `n_w`, on the normal buffer.
    pub(crate) normal: bool,
    /// `p_w`, on the position buffer.
    pub(crate) position: bool,
}

impl Weights {
    /// How many weights are on (0–3).
    pub(crate) fn count(self) -> usize {
        self.colour as usize + self.normal as usize + self.position as usize
    }
}

/// The parameters of one level: its number and the reciprocal phis of Listing 6.3, the normal
/// one already divided by `stepwidth²`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Level {
    /// Level `i`: taps `2^i` apart.
    pub(crate) level: usize,
    /// `1 / c_phi` of this level.
    pub(crate) inv_c: f32,
    /// `1 / (n_phi · stepwidth²)`.
    pub(crate) inv_n: f32,
    /// `1 / p_phi`.
    pub(crate) inv_p: f32,
}

/// What one pass reads.
#[derive(Clone, Copy)]
pub(crate) struct Inputs<'a> {
    /// The previous level.
    pub(crate) colour: &'a Planes,
    /// Normals (read only when the normal weight is on).
    pub(crate) normal: &'a Planes,
    /// Positions (read only when the position weight is on).
    pub(crate) position: &'a Planes,
    pub(crate) level: Level,
}

/// The 25 B3 weights; computed once, they are exact.
struct Taps {
    h: [f32; 25],
    offsets: [isize; 5],
}

/// One tap's centre or neighbour values: colour, normal, position.
type Px = [f32; 9];

/// `h · c_w · n_w · p_w` for one tap. The three factors of Listing 6.3 are multiplied as one
/// exponential of the summed exponents: each `min(exp(−d), 1)` with `d ≥ 0` is `exp(−d)`, so
/// only rounding differs from three separate exponentials.
#[inline(always)]
fn weight<const C: bool, const N: bool, const P: bool>(
    h: f32,
    lv: &Level,
    ctr: &Px,
    src: &Px,
) -> f32 {
    if !(C || N || P) {
        return h;
    }
    let d2 = |k: usize| {
        let (a, b, c) = (
            ctr[k] - src[k],
            ctr[k + 1] - src[k + 1],
            ctr[k + 2] - src[k + 2],
        );
        a * a + b * b + c * c
    };
    let mut e = 0.0;
    if C {
        e += d2(0) * lv.inv_c;
    }
    if N {
        e += d2(3) * lv.inv_n;
    }
    if P {
        e += d2(6) * lv.inv_p;
    }
    h * exp_neg(e)
}

/// Nine runs of one row (colour, normal, position), those of weights not in use left empty.
#[derive(Clone, Copy)]
struct Runs<'a>([&'a [f32]; 9]);

/// Whether run `k` is read when the normal (`N`) and position (`P`) weights are as given.
#[inline(always)]
const fn used<const N: bool, const P: bool>(k: usize) -> bool {
    k < 3 || (N && k < 6) || (P && k >= 6)
}

impl<'a> Runs<'a> {
    #[inline(always)]
    fn of<const N: bool, const P: bool>(inp: &Inputs<'a>, y: usize) -> Self {
        let [r, g, b] = inp.colour.components(y);
        let none: [&[f32]; 3] = [&[], &[], &[]];
        let [nx, ny, nz] = if N { inp.normal.components(y) } else { none };
        let [px, py, pz] = if P { inp.position.components(y) } else { none };
        Self([r, g, b, nx, ny, nz, px, py, pz])
    }

    /// Values at `x` (unused runs read as zero).
    #[inline(always)]
    fn at<const N: bool, const P: bool>(&self, x: usize) -> Px {
        let mut v = [0.0; 9];
        for (k, (v, run)) in v.iter_mut().zip(self.0).enumerate() {
            if used::<N, P>(k) {
                *v = run[x];
            }
        }
        v
    }

    /// The used runs' elements `start..start + n`, each exactly `n` long, which lets the
    /// compiler drop the bounds checks of a loop over `0..n`.
    #[inline(always)]
    fn window<const N: bool, const P: bool>(&self, start: usize, n: usize) -> Self {
        let mut out: [&[f32]; 9] = [&[]; 9];
        for (k, (o, run)) in out.iter_mut().zip(self.0).enumerate() {
            if used::<N, P>(k) {
                *o = &run[start..start + n];
            }
        }
        Self(out)
    }
}

/// Accumulators of one chunk: Σ w·c per component and Σ w.
struct Acc<'a> {
    rgb: [&'a mut [f32]; 3],
    cum: &'a mut [f32],
}

/// Adds tap `h` for the `n` pixels whose centres are `ctr` and neighbours `src` (both windows
/// of length `n`).
#[inline(always)]
fn span<const C: bool, const N: bool, const P: bool>(
    h: f32,
    lv: &Level,
    ctr: Runs<'_>,
    src: Runs<'_>,
    acc: &mut Acc<'_>,
    n: usize,
) {
    let [ar, ag, ab] = &mut acc.rgb;
    let (ar, ag, ab, cum) = (&mut ar[..n], &mut ag[..n], &mut ab[..n], &mut acc.cum[..n]);
    for i in 0..n {
        let c = ctr.at::<N, P>(i);
        let s = src.at::<N, P>(i);
        let w = weight::<C, N, P>(h, lv, &c, &s);
        ar[i] += w * s[0];
        ag[i] += w * s[1];
        ab[i] += w * s[2];
        cum[i] += w;
    }
}

/// [`span`] for pixels whose neighbour is clamped to one border pixel `s`.
#[inline(always)]
fn span_clamped<const C: bool, const N: bool, const P: bool>(
    h: f32,
    lv: &Level,
    ctr: Runs<'_>,
    s: &Px,
    acc: &mut Acc<'_>,
    n: usize,
) {
    let [ar, ag, ab] = &mut acc.rgb;
    let (ar, ag, ab, cum) = (&mut ar[..n], &mut ag[..n], &mut ab[..n], &mut acc.cum[..n]);
    for i in 0..n {
        let c = ctr.at::<N, P>(i);
        let w = weight::<C, N, P>(h, lv, &c, s);
        ar[i] += w * s[0];
        ag[i] += w * s[1];
        ab[i] += w * s[2];
        cum[i] += w;
    }
}

/// Filters output row `y` into `out` (`3·stride` values) with `cum` (`width` values) as scratch.
#[inline(always)]
pub(crate) fn row<const C: bool, const N: bool, const P: bool>(
    inp: &Inputs<'_>,
    y: usize,
    out: &mut [f32],
    cum: &mut [f32],
) {
    let taps = Taps {
        h: kernel_2d(),
        offsets: tap_offsets(inp.level.level),
    };
    let lv = inp.level;
    let (w, h) = (inp.colour.width, inp.colour.height);
    let stride = inp.colour.stride;
    out.fill(0.0);
    cum.fill(0.0);
    let (or, rest) = out.split_at_mut(stride);
    let (og, ob) = rest.split_at_mut(stride);
    let (or, og, ob) = (&mut or[..w], &mut og[..w], &mut ob[..w]);
    let centre = Runs::of::<N, P>(inp, y);
    let mut x0 = 0;
    while x0 < w {
        let x1 = (x0 + CHUNK).min(w);
        for (ky, &dy) in taps.offsets.iter().enumerate() {
            let sy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
            let source = Runs::of::<N, P>(inp, sy);
            for (kx, &dx) in taps.offsets.iter().enumerate() {
                let hk = taps.h[5 * ky + kx];
                // Pixels x with x + dx < 0 read column 0, with x + dx ≥ w column w − 1
                // (clamp to edge, as the GPU's texture fetch).
                let lo = (-dx).clamp(x0 as isize, x1 as isize) as usize;
                let hi = (w as isize - dx).clamp(lo as isize, x1 as isize) as usize;
                macro_rules! acc {
                    ($a:expr, $b:expr) => {
                        &mut Acc {
                            rgb: [&mut or[$a..$b], &mut og[$a..$b], &mut ob[$a..$b]],
                            cum: &mut cum[$a..$b],
                        }
                    };
                }
                if lo > x0 {
                    let s = source.at::<N, P>(0);
                    let ctr = centre.window::<N, P>(x0, lo - x0);
                    span_clamped::<C, N, P>(hk, &lv, ctr, &s, acc!(x0, lo), lo - x0);
                }
                if hi > lo {
                    let n = hi - lo;
                    let ctr = centre.window::<N, P>(lo, n);
                    let src = source.window::<N, P>((lo as isize + dx) as usize, n);
                    span::<C, N, P>(hk, &lv, ctr, src, acc!(lo, hi), n);
                }
                if x1 > hi {
                    let s = source.at::<N, P>(w - 1);
                    let ctr = centre.window::<N, P>(hi, x1 - hi);
                    span_clamped::<C, N, P>(hk, &lv, ctr, &s, acc!(hi, x1), x1 - hi);
                }
            }
        }
        x0 = x1;
    }
    // The centre tap always has weight h·exp(0) = 9/64 > 0, so the sum of weights is positive.
    for x in 0..w {
        or[x] /= cum[x];
        og[x] /= cum[x];
        ob[x] /= cum[x];
    }
}
