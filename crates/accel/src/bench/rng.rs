//! The one random number generator of the benchmark ray sets.

use rt_core::rng::SplitMix64;

/// The random numbers of one ray: rt-core's SplitMix64, its state derived from (seed, set, ray
/// index), so any ray can be regenerated alone.
pub type RayRng = SplitMix64;

/// The stream of ray `index` of set number `set` for `seed`.
///
/// ```
/// let a = rt_accel::bench::ray_rng(1, 2, 3).f32();
/// assert_eq!(a, rt_accel::bench::ray_rng(1, 2, 3).f32());
/// assert!((0.0..1.0).contains(&a));
/// ```
pub fn ray_rng(seed: u64, set: u64, index: u64) -> RayRng {
    let mut r = SplitMix64::from_state(seed ^ set.wrapping_mul(0xd6e8_feb8_6659_fd93));
    let mixed = r
        .next_u64()
        .wrapping_add(index.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    SplitMix64::from_state(r.state() ^ mixed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_numbers_are_a_function_of_seed_set_and_index() {
        let a: Vec<f32> = (0..4).map(|_| ray_rng(1, 2, 3).f32()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        let mut r = ray_rng(1, 2, 3);
        let first = r.f32();
        assert_ne!(first, r.f32());
        assert_ne!(ray_rng(1, 2, 4).f32(), first);
        assert_ne!(ray_rng(1, 3, 3).f32(), first);
        assert_ne!(ray_rng(2, 2, 3).f32(), first);
    }
}
