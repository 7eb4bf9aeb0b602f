//! Runs one À-Trous level over all rows, in parallel, with the widest row code this CPU has:
//! [`super::pass::row`] compiled with AVX2 enabled when the CPU reports AVX2 (detected at run
//! time), else the portable build of the same code (SSE2 on x86-64).
//!
//! The AVX2 copy is the same source: no intrinsics, no fused multiply-adds, and lanes never
//! exchange values, so both copies compute every pixel with the same operations in the same
//! order and give the same bits (tested). The only `unsafe` in this crate is the call into the
//! `#[target_feature]` function, made after the detection that makes it sound.

use super::pass::{row, Inputs, Weights};
use super::planes::Planes;
use rayon::prelude::*;

/// Which build of the row code to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Isa {
    /// Plain Rust for the target's baseline.
    Portable,
    /// The same code with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    Avx2,
}

impl Isa {
    /// The widest this CPU supports (`Portable` when `allow_simd` is false).
    pub(crate) fn detect(allow_simd: bool) -> Self {
        #[cfg(target_arch = "x86_64")]
        if allow_simd && std::is_x86_feature_detected!("avx2") {
            return Isa::Avx2;
        }
        let _ = allow_simd;
        Isa::Portable
    }
}

/// Filters `inp.colour` into `dst` (same size) with the weights `wts`.
pub(crate) fn pass(inp: &Inputs<'_>, dst: &mut Planes, wts: Weights, isa: Isa) {
    match (wts.colour, wts.normal, wts.position) {
        (false, false, false) => rows::<false, false, false>(inp, dst, isa),
        (true, false, false) => rows::<true, false, false>(inp, dst, isa),
        (false, true, false) => rows::<false, true, false>(inp, dst, isa),
        (false, false, true) => rows::<false, false, true>(inp, dst, isa),
        (true, true, false) => rows::<true, true, false>(inp, dst, isa),
        (true, false, true) => rows::<true, false, true>(inp, dst, isa),
        (false, true, true) => rows::<false, true, true>(inp, dst, isa),
        (true, true, true) => rows::<true, true, true>(inp, dst, isa),
    }
}

fn rows<const C: bool, const N: bool, const P: bool>(inp: &Inputs<'_>, dst: &mut Planes, isa: Isa) {
    let (w, stride) = (dst.width, dst.stride);
    if w == 0 {
        return;
    }
    dst.data
        .par_chunks_mut(3 * stride)
        .enumerate()
        // One scratch row per rayon job, not per row or pixel.
        .for_each_init(
            || vec![0.0f32; w],
            |cum, (y, out)| match isa {
                Isa::Portable => row::<C, N, P>(inp, y, out, cum),
                #[cfg(target_arch = "x86_64")]
                // SAFETY: `Isa::Avx2` is only made by `Isa::detect` after
                // `is_x86_feature_detected!("avx2")` returned true.
                #[allow(unsafe_code)]
                Isa::Avx2 => unsafe { row_avx2::<C, N, P>(inp, y, out, cum) },
            },
        );
}

/// [`row`] compiled with AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn row_avx2<const C: bool, const N: bool, const P: bool>(
    inp: &Inputs<'_>,
    y: usize,
    out: &mut [f32],
    cum: &mut [f32],
) {
    row::<C, N, P>(inp, y, out, cum)
}
