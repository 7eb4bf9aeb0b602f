//! The sampler's draws ([`rt_core::sampler::draw_1d`], [`rt_core::sampler::draw_2d`]) for
//! eight samples at once with AVX2: the same integer hashes (Burley 2020's Owen scrambling of
//! shuffled Sobol' points), one lane per sample. Integer arithmetic and an exact conversion
//! to float, so every lane is the scalar draw's bits (`lanes::tests` checks it).
#![allow(unsafe_code)] // one unaligned store per output vector

use super::lanes::VertexDraws;
use rt_core::glam::Vec2;
use rt_core::sampler::SOBOL1_DIRECTIONS;
use rt_core::SampleKey;
use std::arch::x86_64::*;

/// Eight 32-bit lanes.
type U32x8 = __m256i;

#[target_feature(enable = "avx2")]
#[inline]
fn splat(x: u32) -> U32x8 {
    _mm256_set1_epi32(x as i32)
}

/// Chris Wellons' lowbias32 (`rt_core::sampler::hash_u32`).
#[target_feature(enable = "avx2")]
#[inline]
fn hash(mut x: U32x8) -> U32x8 {
    x = _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x));
    x = _mm256_mullo_epi32(x, splat(0x7feb_352d));
    x = _mm256_xor_si256(x, _mm256_srli_epi32::<15>(x));
    x = _mm256_mullo_epi32(x, splat(0x846c_a68b));
    _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x))
}

/// `hash2(a, b)`.
#[target_feature(enable = "avx2")]
#[inline]
fn hash2(a: U32x8, b: U32x8) -> U32x8 {
    hash(_mm256_xor_si256(
        a,
        hash(_mm256_add_epi32(b, splat(0x9e37_79b9))),
    ))
}

/// `x ^= x * c` for the four Laine–Karras constants after adding the seed.
#[target_feature(enable = "avx2")]
#[inline]
fn laine_karras(mut x: U32x8, seed: U32x8) -> U32x8 {
    x = _mm256_add_epi32(x, seed);
    for c in [0x6c50_b47c_u32, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6] {
        x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, splat(c)));
    }
    x
}

/// Bit reversal of every lane: bytes swapped by a shuffle, bits within bytes by two nibble
/// look-ups.
#[target_feature(enable = "avx2")]
#[inline]
fn reverse_bits(x: U32x8) -> U32x8 {
    let bswap = _mm256_setr_epi8(
        3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8,
        15, 14, 13, 12,
    );
    let x = _mm256_shuffle_epi8(x, bswap);
    // Reversed nibble values 0..15.
    let rev = _mm256_setr_epi8(
        0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15, 0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5,
        13, 3, 11, 7, 15,
    );
    let low = _mm256_set1_epi8(0x0f);
    let lo = _mm256_and_si256(x, low);
    let hi = _mm256_and_si256(_mm256_srli_epi16::<4>(x), low);
    _mm256_or_si256(
        _mm256_slli_epi16::<4>(_mm256_shuffle_epi8(rev, lo)),
        _mm256_shuffle_epi8(rev, hi),
    )
}

/// The second Sobol' dimension: the XOR of the direction numbers of the index's set bits.
#[target_feature(enable = "avx2")]
#[inline]
fn sobol_dim1(i: U32x8) -> U32x8 {
    let mut acc = _mm256_setzero_si256();
    let mut bits = i;
    for v in SOBOL1_DIRECTIONS {
        // All ones where the lowest remaining bit is set.
        let set = _mm256_sub_epi32(_mm256_setzero_si256(), _mm256_and_si256(bits, splat(1)));
        acc = _mm256_xor_si256(acc, _mm256_and_si256(set, splat(v)));
        bits = _mm256_srli_epi32::<1>(bits);
    }
    acc
}

/// `(x >> 8) * 2⁻²⁴`: exact, as the scalar conversion.
#[target_feature(enable = "avx2")]
#[inline]
fn to_unit(x: U32x8) -> __m256 {
    _mm256_mul_ps(
        _mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(x)),
        _mm256_set1_ps(1.0 / (1u32 << 24) as f32),
    )
}

/// Eight values as one vector.
#[target_feature(enable = "avx2")]
#[inline]
fn lanes(v: [u32; 8]) -> U32x8 {
    _mm256_setr_epi32(
        v[0] as i32,
        v[1] as i32,
        v[2] as i32,
        v[3] as i32,
        v[4] as i32,
        v[5] as i32,
        v[6] as i32,
        v[7] as i32,
    )
}

/// The eight lanes of `v`.
#[target_feature(enable = "avx2")]
#[inline]
fn store(v: __m256) -> [f32; 8] {
    let mut a = [0.0f32; 8];
    // SAFETY: `a` holds eight f32s, the 32 bytes the unaligned store writes.
    unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
    a
}

/// The first coordinate of every draw, and the shuffled index and dimension hash the second
/// coordinate of a 2D draw needs.
#[target_feature(enable = "avx2")]
#[inline]
fn draw_x(pixel: U32x8, index_reversed: U32x8, dim: U32x8) -> (__m256, U32x8, U32x8) {
    let h = hash2(pixel, dim);
    let i = reverse_bits(laine_karras(index_reversed, h));
    let x = reverse_bits(laine_karras(
        i,
        hash(_mm256_xor_si256(h, splat(0x68bc_21eb))),
    ));
    (to_unit(x), i, h)
}

#[target_feature(enable = "avx2")]
#[inline]
fn draw_1d(pixel: U32x8, index_reversed: U32x8, dim: U32x8) -> __m256 {
    draw_x(pixel, index_reversed, dim).0
}

#[target_feature(enable = "avx2")]
#[inline]
fn draw_2d(pixel: U32x8, index_reversed: U32x8, dim: U32x8) -> (__m256, __m256) {
    let (x, i, h) = draw_x(pixel, index_reversed, dim);
    let seed = hash(_mm256_xor_si256(h, splat(0x02e5_be93)));
    let y = reverse_bits(laine_karras(reverse_bits(sobol_dim1(i)), seed));
    (x, to_unit(y))
}

/// The five draws of the vertices of eight samples: `keys[k]` at first dimension `dims[k]`.
///
/// Only callable where AVX2 is known to be there (`lanes::draw_vertices` checks at run time).
#[target_feature(enable = "avx2")]
pub(super) fn draw_vertices8(keys: &[SampleKey; 8], dims: &[u32; 8], out: &mut [VertexDraws; 8]) {
    let pixel = lanes(std::array::from_fn(|k| keys[k].pixel_hash));
    let index = lanes(std::array::from_fn(|k| keys[k].index_reversed));
    let dim = lanes(*dims);
    let light_sel = draw_1d(pixel, index, dim);
    let (light_x, light_y) = draw_2d(pixel, index, _mm256_add_epi32(dim, splat(1)));
    let layer = draw_1d(pixel, index, _mm256_add_epi32(dim, splat(2)));
    let (bsdf_x, bsdf_y) = draw_2d(pixel, index, _mm256_add_epi32(dim, splat(3)));
    let rr = draw_1d(pixel, index, _mm256_add_epi32(dim, splat(4)));
    let (light_sel, light_x, light_y) = (store(light_sel), store(light_x), store(light_y));
    let (layer, bsdf_x, bsdf_y, rr) = (store(layer), store(bsdf_x), store(bsdf_y), store(rr));
    for (k, o) in out.iter_mut().enumerate() {
        *o = VertexDraws {
            light_sel: light_sel[k],
            light: Vec2::new(light_x[k], light_y[k]),
            layer: layer[k],
            bsdf: Vec2::new(bsdf_x[k], bsdf_y[k]),
            rr: rr[k],
        };
    }
}
