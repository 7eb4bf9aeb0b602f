//! SplitMix64 (Steele, Lea and Flood 2014): the workspace's one seeded pseudo-random stream
//! for everything that is not a rendering sample (those come from the scrambled Sobol' sampler):
//! procedural scenes, benchmark ray sets, tests and validation cases. Deterministic, tiny, and
//! no `rand` dependency.

use glam::{Vec2, Vec3};

/// A SplitMix64 stream.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A stream from `seed`, mixed first so that small seeds (0, 1, 2, ...) start far apart.
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x6a09_e667_f3bc_c909)
    }

    /// A stream whose state is exactly `state` (no mixing).
    pub fn from_state(state: u64) -> Self {
        Self(state)
    }

    /// The current state (the next output is a function of it alone).
    pub fn state(&self) -> u64 {
        self.0
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// The next 32 random bits (the high half of [`SplitMix64::next_u64`]).
    pub fn u32(&mut self) -> u32 {
        (self.next_u64() >> 32) as u32
    }

    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Two uniforms in [0, 1)².
    pub fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    /// Uniform in `0..n` (Lemire's multiply-shift; 0 for `n = 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.u32() as u64 * n as u64) >> 32) as usize
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.f32() < p
    }

    /// Uniform in the cube [lo, hi)³.
    pub fn vec_in(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }

    /// Uniform in the cube [-1, 1)³.
    pub fn cube(&mut self) -> Vec3 {
        self.vec_in(-1.0, 1.0)
    }

    /// Uniform on the unit sphere (rejection from the cube).
    pub fn unit_vec(&mut self) -> Vec3 {
        loop {
            let v = self.cube();
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }

    /// Barycentric weights (b1, b2) uniform over a triangle.
    pub fn barycentric(&mut self) -> (f32, f32) {
        let (u, v) = (self.f32(), self.f32());
        if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_values_and_ranges() {
        // SplitMix64's published first output for state 0.
        assert_eq!(SplitMix64::from_state(0).next_u64(), 0xe220_a839_7b1d_cdaf);
        let mut r = SplitMix64::new(7);
        for _ in 0..1000 {
            assert!((0.0..1.0).contains(&r.f32()));
            assert!(r.below(5) < 5);
            assert!((r.unit_vec().length() - 1.0).abs() < 1e-5);
        }
        assert_eq!(SplitMix64::new(1).next_u64(), SplitMix64::new(1).next_u64());
        assert_ne!(SplitMix64::new(1).next_u64(), SplitMix64::new(2).next_u64());
    }
}
