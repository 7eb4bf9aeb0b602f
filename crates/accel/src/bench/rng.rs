//! The one random number generator of the benchmark ray sets.

use rt_core::glam::Vec2;

/// Deterministic random numbers for one ray: SplitMix64 seeded by (seed, set, ray index).
///
/// ```
/// use rt_accel::bench::RayRng;
/// let a = RayRng::new(1, 2, 3).f32();
/// assert_eq!(a, RayRng::new(1, 2, 3).f32());
/// assert!((0.0..1.0).contains(&a));
/// ```
#[derive(Clone, Debug)]
pub struct RayRng(u64);

impl RayRng {
    /// The stream of ray `index` of set number `set` for `seed`.
    pub fn new(seed: u64, set: u64, index: u64) -> Self {
        let mut r = RayRng(seed ^ set.wrapping_mul(0xd6e8_feb8_6659_fd93));
        r.0 ^= r
            .next_u64()
            .wrapping_add(index.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        r
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), 24 bits.
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Two values uniform in [0, 1).
    pub fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_numbers_are_a_function_of_seed_set_and_index() {
        let a: Vec<f32> = (0..4).map(|_| RayRng::new(1, 2, 3).f32()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        let mut r = RayRng::new(1, 2, 3);
        let first = r.f32();
        assert_ne!(first, r.f32());
        assert_ne!(RayRng::new(1, 2, 4).f32(), first);
        assert_ne!(RayRng::new(1, 3, 3).f32(), first);
        assert_ne!(RayRng::new(2, 2, 3).f32(), first);
    }
}
