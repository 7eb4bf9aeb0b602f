//! Integer hashes: the PCG hash of Jarzynski & Olano ("Hash Functions for GPU Rendering",
//! JCGT 9(3), 2020), nested for 3D→1D as they recommend, a 1D→3D expansion for point
//! offsets, and a 64-bit finaliser for table slots.

/// The 1D PCG hash (Jarzynski & Olano 2020, `pcg`): one LCG step and an RXS-M-XS output.
#[inline]
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Nested 3D→1D PCG: `pcg(x + pcg(y + pcg(z)))`.
#[inline]
pub fn pcg3_to_1(x: u32, y: u32, z: u32) -> u32 {
    pcg(x.wrapping_add(pcg(y.wrapping_add(pcg(z)))))
}

/// 1D→3D: one PCG output split into 11, 11 and 10 bits, each mapped to [0, 1) (exact in f32,
/// never 1). One hash per point instead of three: point generation is the cache's hot loop
/// (216 points per 27-voxel query), and 1/1024 of a half-voxel is finer than any use needs.
#[inline]
pub fn unit3(seed: u32) -> [f32; 3] {
    unit3_of_hash(pcg(seed)).to_array()
}

/// The split of [`unit3`] applied to an already hashed `h`.
#[inline]
pub fn unit3_of_hash(h: u32) -> glam::Vec3 {
    glam::Vec3::new(
        (h & 0x7ff) as f32 * (1.0 / 2048.0),
        ((h >> 11) & 0x7ff) as f32 * (1.0 / 2048.0),
        (h >> 22) as f32 * (1.0 / 1024.0),
    )
}

/// The top 24 bits of `h` as a number in [0, 1).
#[inline]
pub fn unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The splitmix64 finaliser: a bijective 64-bit mix, used to spread keys over table slots.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A per-sample hash of (pixel, frame) for callers that need one: what the thesis' selection
/// pass draws ξ from.
#[inline]
pub fn pixel_frame_hash(x: u32, y: u32, frame: u32) -> u32 {
    pcg3_to_1(x, y, frame)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg_matches_the_reference_values() {
        // pcg(0) by hand: state = 2891336453; (state >> 28) + 4 = 14; ...
        let state: u32 = 2_891_336_453;
        let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
        assert_eq!(pcg(0), (word >> 22) ^ word);
        assert_ne!(pcg(1), pcg(0));
    }

    #[test]
    fn unit_is_below_one() {
        assert!(unit(u32::MAX) < 1.0);
        assert_eq!(unit(0), 0.0);
    }
}
