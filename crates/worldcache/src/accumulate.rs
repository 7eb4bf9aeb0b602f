//! One pass's samples, summed in fixed point so the sums do not depend on the order threads
//! add them (thesis §3.2 uses 32-bit integer atomics for the same reason).
//!
//! Each slot is a key and four `AtomicU64` (R, G, B, count): 40 bytes. A channel is clamped to
//! [0, [`MAX_RECORD`]] and stored as `round(v · 2^24)`: a resolution of 6·10⁻⁸ and, with
//! values ≤ 2^16, room for 2^24 samples per key per pass before the 64-bit sum could wrap.
//! HDR radiance above 65536 is clamped (a firefly limit); NaN, infinite or negative values
//! drop the sample. Keys are inserted by compare-and-swap with linear probing; a full
//! accumulator drops the sample and counts it ([`PassAccumulator::dropped`]).

use crate::hash::mix64;
use crate::key::Key;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// Fixed-point scale of accumulated values.
pub const FIXED_SCALE: f64 = (1u64 << 24) as f64;
/// Largest value per channel of one sample; larger ones are clamped.
pub const MAX_RECORD: f32 = 65_536.0;

/// `v` in fixed point, clamped; `None` for NaN, infinite or negative values.
#[inline]
pub fn to_fixed(v: f32) -> Option<u64> {
    if !(v.is_finite() && v >= 0.0) {
        return None;
    }
    Some((f64::from(v.min(MAX_RECORD)) * FIXED_SCALE).round() as u64)
}

#[derive(Default)]
struct Slot {
    key: AtomicU64,
    rgb: [AtomicU64; 3],
    count: AtomicU64,
}

/// One key's sums for a pass, as drained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassSum {
    /// The key.
    pub key: Key,
    /// Sum of the samples (linear RGB).
    pub sum: [f64; 3],
    /// Number of samples.
    pub count: u64,
}

/// Concurrent per-pass sums, key → (Σ RGB, count).
pub struct PassAccumulator {
    slots: Vec<Slot>,
    dropped: AtomicU64,
}

impl PassAccumulator {
    /// Bytes per slot.
    pub const SLOT_BYTES: usize = std::mem::size_of::<Slot>();

    /// An empty accumulator of `capacity` slots (a power of two, at least 2).
    pub fn new(capacity: usize) -> Result<Self, crate::table::BadCapacity> {
        if capacity < 2 || !capacity.is_power_of_two() {
            return Err(crate::table::BadCapacity(capacity));
        }
        Ok(Self {
            slots: (0..capacity).map(|_| Slot::default()).collect(),
            dropped: AtomicU64::new(0),
        })
    }

    /// Slots.
    pub fn capacity(&self) -> usize {
        self.slots.len()
    }

    /// Samples dropped since the last drain (accumulator full or value not finite).
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Relaxed)
    }

    /// Adds one sample `rgb` to `key`. False if it was dropped.
    #[inline]
    pub fn add(&self, key: Key, rgb: [f32; 3]) -> bool {
        let (Some(r), Some(g), Some(b)) = (to_fixed(rgb[0]), to_fixed(rgb[1]), to_fixed(rgb[2]))
        else {
            self.dropped.fetch_add(1, Relaxed);
            return false;
        };
        let mask = self.slots.len() - 1;
        let start = mix64(key.0) as usize & mask;
        for i in 0..self.slots.len() {
            let slot = &self.slots[(start + i) & mask];
            let mut k = slot.key.load(Relaxed);
            if k == 0 {
                k = match slot.key.compare_exchange(0, key.0, Relaxed, Relaxed) {
                    Ok(_) => key.0,
                    Err(current) => current,
                };
            }
            if k == key.0 {
                for (sum, v) in slot.rgb.iter().zip([r, g, b]) {
                    let before = sum.fetch_add(v, Relaxed);
                    // Atomics wrap whatever the overflow checks say: this is what
                    // `[profile.ci]` (debug assertions on) sees of a wrapped sum.
                    debug_assert!(before.checked_add(v).is_some(), "fixed-point sum wrapped");
                }
                slot.count.fetch_add(1, Relaxed);
                return true;
            }
        }
        self.dropped.fetch_add(1, Relaxed);
        false
    }

    /// The pass's sums sorted by key, and the accumulator emptied. Needs `&mut`, so no add
    /// can race with it.
    pub fn drain(&mut self) -> Vec<PassSum> {
        let mut out: Vec<PassSum> = self
            .slots
            .iter_mut()
            .filter_map(|s| {
                let key = std::mem::take(s.key.get_mut());
                let rgb = s.rgb.each_mut().map(|c| std::mem::take(c.get_mut()));
                let count = std::mem::take(s.count.get_mut());
                (key != 0).then(|| PassSum {
                    key: Key(key),
                    sum: rgb.map(|c| c as f64 / FIXED_SCALE),
                    count,
                })
            })
            .collect();
        *self.dropped.get_mut() = 0;
        out.sort_unstable_by_key(|s| s.key);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slot_is_40_bytes() {
        assert_eq!(PassAccumulator::SLOT_BYTES, 40);
    }

    #[test]
    fn full_accumulator_drops_and_counts() {
        let mut a = PassAccumulator::new(2).unwrap();
        assert!(a.add(Key(1 << 63 | 1), [1.0; 3]));
        assert!(a.add(Key(1 << 63 | 2), [1.0; 3]));
        assert!(!a.add(Key(1 << 63 | 3), [1.0; 3]));
        assert!(!a.add(Key(1 << 63 | 1), [f32::NAN, 0.0, 0.0]));
        assert_eq!(a.dropped(), 2);
        let d = a.drain();
        assert_eq!(d.len(), 2);
        assert_eq!(a.dropped(), 0);
        assert!(a.drain().is_empty());
    }
}
