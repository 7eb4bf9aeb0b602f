//! Deterministic low-discrepancy sampling: Owen-scrambled, shuffled Sobol' points.
//!
//! This follows Burley, "Practical Hash-based Owen Scrambling" (JCGT 2020). Every request for a
//! 1D or 2D sample draws from the first two Sobol' dimensions, whose 2D projection is a (0,2)
//! sequence (perfectly stratified at every power of two). The sample index is shuffled and the
//! coordinates are Owen-scrambled with hashes of `(seed, pixel, dimension)`, which decorrelates
//! the successive dimensions of a path (padding) while keeping each pair stratified.
//!
//! Every value is a pure function of `(stream, seed, pixel, sample index, dimension)`: the image
//! does not depend on how pixels are distributed over threads, and any sample can be replayed
//! alone.

use glam::Vec2;

/// Which family of sample streams a render draws from.
///
/// The families use disjoint ranges of dimension numbers (a normal render counts from 0, GREE's
/// filter caches from 2³⁰, a reference from 2³¹), so no `(seed, pixel, index, dimension)` point
/// that any normal render uses, whatever its seed, is ever used by a reference or a cache: a
/// reference's error is independent of the image it is measured against, and a cache's samples
/// of the image its filters were run on, even when all have the same seed. A path would need
/// over a billion dimensions to reach the next range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SampleStream {
    /// Every normal render.
    #[default]
    Render,
    /// High-sample reference images (`render reference`, experiments).
    Reference,
    /// GREE's filter caches: extra samples at chosen pixels that score the filters of an
    /// image rendered from [`SampleStream::Render`], so they must not share its samples.
    Cache,
}

impl SampleStream {
    /// The first dimension number of the family.
    const fn first_dimension(self) -> u32 {
        match self {
            SampleStream::Render => 0,
            SampleStream::Reference => 1 << 31,
            SampleStream::Cache => 1 << 30,
        }
    }
}

/// Per-pixel sample stream. Create one per worker and call [`Sampler::start`] per sample.
#[derive(Clone, Debug)]
pub struct Sampler {
    seed: u32,
    pixel_hash: u32,
    /// The sample index with its bits reversed: the first step of every draw's index shuffle
    /// ([`nested_uniform_scramble`]), done once per sample instead of once per draw.
    index_reversed: u32,
    dim: u32,
    first_dim: u32,
}

impl Sampler {
    /// A sampler for the global `seed` in the normal-render family.
    pub fn new(seed: u32) -> Self {
        Self::with_stream(seed, SampleStream::Render)
    }

    /// A sampler for the global `seed` in the given family of streams.
    pub fn with_stream(seed: u32, stream: SampleStream) -> Self {
        let first_dim = stream.first_dimension();
        Self {
            seed,
            pixel_hash: 0,
            index_reversed: 0,
            dim: first_dim,
            first_dim,
        }
    }

    /// Begins sample number `index` of pixel `(x, y)`.
    #[inline]
    pub fn start(&mut self, x: u32, y: u32, index: u32) {
        self.pixel_hash = hash3(x, y, self.seed);
        self.index_reversed = index.reverse_bits();
        self.dim = self.first_dim;
    }

    /// Begins light path number `path` of sample index `index` (light-path techniques take
    /// one set of light paths per sample index). Light paths are keyed as pixels of a row no
    /// image has (`y = u32::MAX`), so their streams never coincide with a camera sample's, and
    /// path `k` of successive indices walks one scrambled sequence, as a pixel's samples do.
    #[inline]
    pub fn start_light_path(&mut self, path: u32, index: u32) {
        self.start(path, u32::MAX, index);
    }

    /// The next 1D value in [0, 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        let v = draw_1d(self.key(), self.dim);
        self.dim = self.dim.wrapping_add(1);
        v
    }

    /// The next 2D value in [0, 1)².
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let v = draw_2d(self.key(), self.dim);
        self.dim = self.dim.wrapping_add(1);
        v
    }

    /// What every draw of the current sample depends on besides its dimension.
    #[inline]
    pub fn key(&self) -> SampleKey {
        SampleKey {
            pixel_hash: self.pixel_hash,
            index_reversed: self.index_reversed,
        }
    }

    /// The dimension the next draw takes. A wavefront integrator draws a whole bounce's numbers
    /// for many samples at once with [`draw_1d`] and [`draw_2d`] from [`Sampler::key`] and
    /// this, instead of keeping one sampler per sample in flight.
    #[inline]
    pub fn dimension(&self) -> u32 {
        self.dim
    }
}

/// The part of a sample's stream that does not change from draw to draw: the hash of
/// `(seed, pixel)` and the bit-reversed sample index. With a dimension it fixes a draw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SampleKey {
    /// Hash of the pixel and the seed.
    pub pixel_hash: u32,
    /// The sample index, bits reversed.
    pub index_reversed: u32,
}

/// The 1D value of dimension `dim` of the sample `key`: what [`Sampler::next_1d`] returns when
/// its next dimension is `dim`. Pure integer arithmetic, so a loop over many keys vectorises
/// and gives the same bits.
#[inline(always)]
pub fn draw_1d(key: SampleKey, dim: u32) -> f32 {
    let h = hash2(key.pixel_hash, dim);
    let i = laine_karras_permutation(key.index_reversed, h).reverse_bits();
    // nested_uniform_scramble(sobol_dim0(i)) with the two bit reversals that cancel removed.
    to_unit_float(laine_karras_permutation(i, hash_u32(h ^ 0x68bc_21eb)).reverse_bits())
}

/// The 2D value of dimension `dim` of the sample `key` ([`Sampler::next_2d`]).
#[inline(always)]
pub fn draw_2d(key: SampleKey, dim: u32) -> Vec2 {
    let h = hash2(key.pixel_hash, dim);
    let i = laine_karras_permutation(key.index_reversed, h).reverse_bits();
    let x = laine_karras_permutation(i, hash_u32(h ^ 0x68bc_21eb)).reverse_bits();
    let y = nested_uniform_scramble(sobol_dim1(i), hash_u32(h ^ 0x02e5_be93));
    Vec2::new(to_unit_float(x), to_unit_float(y))
}

/// 32-bit integer hash with good avalanche (Chris Wellons' "lowbias32").
#[inline]
pub fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hash of two words.
#[inline]
pub fn hash2(a: u32, b: u32) -> u32 {
    hash_u32(a ^ hash_u32(b.wrapping_add(0x9e37_79b9)))
}

/// Hash of three words.
#[inline]
pub fn hash3(a: u32, b: u32, c: u32) -> u32 {
    hash2(hash2(a, b), c)
}

#[inline]
fn to_unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Laine–Karras style hash that is an Owen scramble when applied to bit-reversed values.
#[inline]
fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

#[inline]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// First Sobol' dimension: the van der Corput sequence. (Only the tests call it: the sampler
/// folds its bit reversal into the scramble.)
#[cfg(test)]
fn sobol_dim0(i: u32) -> u32 {
    i.reverse_bits()
}

/// Direction numbers of the second Sobol' dimension (primitive polynomial x + 1):
/// `v[k] = v[k-1] ^ (v[k-1] >> 1)`, starting from the top bit.
/// Public for vectorised copies of the draws, which the tests pin to [`draw_2d`].
pub const SOBOL1_DIRECTIONS: [u32; 32] = {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        k += 1;
    }
    v
};

/// The generator matrix applied a byte at a time: `SOBOL1_BYTES[b][x]` is the XOR of the
/// direction numbers selected by the bits of byte value `x` at byte position `b`. The shuffled
/// index is a random 32-bit value, so a bit-serial loop would always run 32 iterations.
const SOBOL1_BYTES: [[u32; 256]; 4] = {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            let mut r = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if x & (1 << bit) != 0 {
                    r ^= SOBOL1_DIRECTIONS[8 * b + bit];
                }
                bit += 1;
            }
            t[b][x] = r;
            x += 1;
        }
        b += 1;
    }
    t
};

/// Second Sobol' dimension.
#[inline]
fn sobol_dim1(i: u32) -> u32 {
    SOBOL1_BYTES[0][(i & 0xff) as usize]
        ^ SOBOL1_BYTES[1][((i >> 8) & 0xff) as usize]
        ^ SOBOL1_BYTES[2][((i >> 16) & 0xff) as usize]
        ^ SOBOL1_BYTES[3][(i >> 24) as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_values_and_streams_differ_across_pixels() {
        let mut a = Sampler::new(7);
        let mut b = Sampler::new(7);
        a.start(3, 4, 5);
        b.start(3, 4, 5);
        assert_eq!(a.next_2d(), b.next_2d());
        assert_eq!(a.next_1d(), b.next_1d());
        b.start(4, 4, 5);
        let mut c = Sampler::new(7);
        c.start(3, 4, 5);
        assert_ne!(c.next_2d(), b.next_2d());
    }

    #[test]
    fn reference_streams_differ_from_render_streams_of_every_seed_tried() {
        // Same seed, pixel and index: different points. And the reference stream is still a
        // stratified (0,2)-sequence, so references converge as fast as normal renders.
        let first = |seed, stream| {
            let mut s = Sampler::with_stream(seed, stream);
            s.start(3, 4, 5);
            (s.next_2d(), s.next_1d())
        };
        let reference = first(7, SampleStream::Reference);
        for seed in 0..1000 {
            assert_ne!(first(seed, SampleStream::Render), reference, "seed {seed}");
        }
        assert_eq!(first(7, SampleStream::Render), {
            let mut s = Sampler::new(7);
            s.start(3, 4, 5);
            (s.next_2d(), s.next_1d())
        });
        let mut s = Sampler::with_stream(1, SampleStream::Reference);
        let mut grid = [0u32; 64];
        for i in 0..64 {
            s.start(10, 20, i);
            let p = s.next_2d();
            grid[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
        }
        assert!(grid.iter().all(|&c| c == 1), "{grid:?}");
    }

    #[test]
    fn two_d_points_are_stratified() {
        // 256 samples of one pixel and dimension: each of the 16x16 strata holds exactly one
        // point, the (0,2)-sequence property that Owen scrambling preserves.
        let mut s = Sampler::new(1);
        let mut grid = [0u32; 256];
        for i in 0..256 {
            s.start(10, 20, i);
            s.next_1d();
            let p = s.next_2d();
            assert!(p.x < 1.0 && p.y < 1.0 && p.x >= 0.0 && p.y >= 0.0);
            grid[(p.y * 16.0) as usize * 16 + (p.x * 16.0) as usize] += 1;
        }
        assert!(grid.iter().all(|&c| c == 1), "{grid:?}");
    }

    #[test]
    fn table_driven_sobol_matches_the_bit_serial_definition() {
        for i in [0u32, 1, 2, 3, 255, 256, 12345, 0xdead_beef, u32::MAX] {
            let mut r = 0;
            for (k, v) in SOBOL1_DIRECTIONS.iter().enumerate() {
                if i >> k & 1 != 0 {
                    r ^= v;
                }
            }
            assert_eq!(sobol_dim1(i), r);
        }
        // The first points of the second dimension: 0, 1/2, 3/4, 1/4.
        assert_eq!([1, 2, 3].map(sobol_dim1), [1 << 31, 3 << 30, 1 << 30]);
    }

    #[test]
    fn folded_first_dimension_equals_the_scrambled_van_der_corput_point() {
        for (i, seed) in [(0u32, 1u32), (7, 99), (12345, 0xdead_beef), (u32::MAX, 3)] {
            let folded = laine_karras_permutation(i, seed).reverse_bits();
            assert_eq!(folded, nested_uniform_scramble(sobol_dim0(i), seed));
        }
    }

    #[test]
    fn mean_is_unbiased() {
        let mut s = Sampler::new(3);
        let n = 4096;
        let mut sum = 0.0f64;
        for i in 0..n {
            s.start(i % 13, i / 13, i);
            sum += s.next_1d() as f64;
        }
        // Uniform variance is 1/12; stratification only makes the error smaller than this bound.
        let tol = 4.0 * (1.0 / 12.0f64 / n as f64).sqrt();
        assert!((sum / n as f64 - 0.5).abs() < tol);
    }
}
