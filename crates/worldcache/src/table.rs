//! The persistent table: open addressing with linear probing (the thesis uses D. Farrell's
//! simple GPU hash table), key → (value, count), and the thesis' temporal merge (Eq. 2).
//!
//! One [`Entry`] is 24 bytes: the full 64-bit key (so distinct points never share an entry),
//! RGB as three `f32` and the count as `f32`. The capacity is a power of two. A full table
//! refuses new keys ([`TableFull`]): existing keys still merge and every probe sequence is
//! bounded by the capacity, so nothing panics or loops forever.
//!
//! Merge (thesis §3.2, Eq. 2.1–2.3; equations lost, read from the prose): with stored value
//! `v`, stored count `sc`, this pass's sum `Σ` of `ac` samples, `n = sc + ac`,
//! `v' = (v·sc + Σ) / n` and stored count `κ·n`. With `ac = m` every pass the count converges
//! to `κm / (1 − κ)` and the weight of new data to `1 − κ`: an exponential moving average.

use crate::hash::mix64;
use crate::key::Key;
use thiserror::Error;

/// One entry of the persistent table, as read back.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Entry {
    /// Full key (0 marks an empty slot).
    pub key: u64,
    /// Mean value (linear RGB).
    pub value: [f32; 3],
    /// Effective sample count (scaled by κ at every merge).
    pub count: f32,
}

/// Bytes per persistent entry (key array + value array).
pub const ENTRY_BYTES: usize = std::mem::size_of::<Entry>();

/// A new key found every slot taken.
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
#[error("world cache table is full ({capacity} entries); raise `capacity`")]
pub struct TableFull {
    /// The table's capacity.
    pub capacity: usize,
}

/// A capacity that is not a power of two (or is zero).
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
#[error("table capacity {0} is not a power of two of at least 2")]
pub struct BadCapacity(pub usize);

/// Key → (value, count), linear probing. Keys and values live in separate arrays (same
/// 24 bytes per entry in all): probes touch only the 8-byte keys, so a probe sequence stays
/// in fewer cache lines, and a lookup reads a value only on a hit.
#[derive(Clone, Debug)]
pub struct PersistentTable {
    keys: Vec<u64>,
    values: Vec<Value>,
    len: usize,
}

/// The value half of an [`Entry`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Value {
    value: [f32; 3],
    count: f32,
}

impl PersistentTable {
    /// An empty table of `capacity` slots (a power of two, at least 2).
    pub fn new(capacity: usize) -> Result<Self, BadCapacity> {
        if capacity < 2 || !capacity.is_power_of_two() {
            return Err(BadCapacity(capacity));
        }
        Ok(Self {
            keys: vec![0; capacity],
            values: vec![Value::default(); capacity],
            len: 0,
        })
    }

    /// Slots.
    pub fn capacity(&self) -> usize {
        self.keys.len()
    }

    /// Occupied slots.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if no key is stored.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bytes of the slots.
    pub fn bytes(&self) -> usize {
        self.keys.len() * (std::mem::size_of::<u64>() + std::mem::size_of::<Value>())
    }

    /// Forgets every key.
    pub fn clear(&mut self) {
        self.keys.fill(0);
        self.values.fill(Value::default());
        self.len = 0;
    }

    /// The slot holding `key`, or the empty slot where it would go; `None` if the key is
    /// absent and the table full.
    #[inline]
    fn probe(&self, key: Key) -> Option<usize> {
        let mask = self.keys.len() - 1;
        let start = mix64(key.0) as usize & mask;
        (0..self.keys.len())
            .map(|i| (start + i) & mask)
            .find(|&s| self.keys[s] == key.0 || self.keys[s] == 0)
    }

    /// The entry of `key`, if stored.
    #[inline]
    pub fn get(&self, key: Key) -> Option<Entry> {
        let s = self.probe(key)?;
        (self.keys[s] == key.0).then(|| Entry {
            key: key.0,
            value: self.values[s].value,
            count: self.values[s].count,
        })
    }

    /// Merges a pass's `sum` of `count` samples into `key`'s entry with decay `kappa`
    /// (inserting the key if new).
    pub fn merge(
        &mut self,
        key: Key,
        sum: [f64; 3],
        count: f64,
        kappa: f32,
    ) -> Result<(), TableFull> {
        let capacity = self.capacity();
        let slot = self.probe(key).ok_or(TableFull { capacity })?;
        if self.keys[slot] == 0 {
            self.keys[slot] = key.0;
            self.len += 1;
        }
        let e = &mut self.values[slot];
        let sc = f64::from(e.count);
        let n = sc + count;
        if n > 0.0 {
            for (c, s) in e.value.iter_mut().zip(sum) {
                *c = ((f64::from(*c) * sc + s) / n) as f32;
            }
        }
        e.count = (f64::from(kappa) * n) as f32;
        Ok(())
    }

    /// Occupied entries in slot order.
    pub fn entries(&self) -> impl Iterator<Item = Entry> + '_ {
        self.keys
            .iter()
            .zip(&self.values)
            .filter(|(k, _)| **k != 0)
            .map(|(&key, v)| Entry {
                key,
                value: v.value,
                count: v.count,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_is_24_bytes() {
        // The target is at most 40 bytes per entry.
        assert_eq!(std::mem::size_of::<Entry>(), 24);
        assert_eq!(ENTRY_BYTES, 24);
        let t = PersistentTable::new(1024).unwrap();
        assert_eq!(t.bytes(), 1024 * 24);
    }

    #[test]
    fn a_full_table_refuses_new_keys_but_merges_old_ones() {
        let mut t = PersistentTable::new(4).unwrap();
        for k in 1..=4u64 {
            t.merge(Key(1 << 63 | k), [1.0; 3], 1.0, 0.9).unwrap();
        }
        assert_eq!(t.len(), 4);
        assert_eq!(
            t.merge(Key(1 << 63 | 99), [1.0; 3], 1.0, 0.9),
            Err(TableFull { capacity: 4 })
        );
        assert!(t.get(Key(1 << 63 | 99)).is_none());
        t.merge(Key(1 << 63 | 2), [3.0; 3], 1.0, 0.9).unwrap();
        assert_eq!(
            t.get(Key(1 << 63 | 2)).unwrap().value,
            [(0.9 + 3.0) as f32 / 1.9; 3]
        );
        assert!(PersistentTable::new(6).is_err());
    }
}
