//! Exact 64-bit keys of cached points.
//!
//! A key packs, without hashing, everything that identifies a point: which discretisation made
//! it (implicit points or the fixed grid), its level, its voxel (three signed 17-bit integer
//! coordinates), its octant and an optional normal bin. Two different points therefore never
//! share a key, and the table stores the full key, so there are no silent collisions (the
//! thesis' 32-bit seeds could collide, seed digest §1.5 and §6). Bit layout, high to low:
//!
//! | bits  | field                                   |
//! |-------|-----------------------------------------|
//! | 63    | always 1 (0 marks an empty table slot)  |
//! | 62    | discretisation: 0 implicit, 1 grid      |
//! | 57–61 | level (0..=31)                          |
//! | 54–56 | octant (0..8; 0 for grid cells)         |
//! | 51–53 | normal bin (0: none, 1..=6: ±x, ±y, ±z) |
//! | 0–50  | voxel x, y, z, 17 bits each, offset by 2^16 |
//!
//! Voxels outside `[-2^16, 2^16)` on some axis have no key: such points are skipped (not
//! cached), which bounds the world a level can address to 2^17 voxels per axis.

use glam::IVec3;

/// Bits per voxel coordinate.
pub const COORD_BITS: u32 = 17;
/// Smallest voxel coordinate a key can hold.
pub const COORD_MIN: i32 = -(1 << (COORD_BITS - 1));
/// Largest voxel coordinate a key can hold.
pub const COORD_MAX: i32 = (1 << (COORD_BITS - 1)) - 1;
/// Highest level a key can hold.
pub const MAX_LEVEL: u32 = 31;

/// Which point set a key belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KeyKind {
    /// Implicit progressive points (Delaere 2021).
    Implicit,
    /// Fixed-grid cell centres (Binder et al. 2019).
    Grid,
}

/// An exact point key (never 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Key(pub u64);

/// The fields a [`Key`] packs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct KeyParts {
    /// Point set.
    pub kind: KeyKind,
    /// Level of detail.
    pub level: u32,
    /// Voxel (implicit) or cell (grid) integer coordinates.
    pub voxel: IVec3,
    /// Octant 0..8 (0 for grid cells).
    pub octant: u32,
    /// Normal bin 0..=6 (0: normals not in keys).
    pub normal_bin: u32,
}

impl Key {
    /// Packs `parts`; `None` if the voxel lies outside the addressable range or a field is
    /// out of range.
    #[inline]
    pub fn pack(parts: KeyParts) -> Option<Key> {
        let v = parts.voxel;
        let in_range = |c: i32| (COORD_MIN..=COORD_MAX).contains(&c);
        if !(in_range(v.x) && in_range(v.y) && in_range(v.z))
            || parts.level > MAX_LEVEL
            || parts.octant > 7
            || parts.normal_bin > 6
        {
            return None;
        }
        let off = |c: i32| (c - COORD_MIN) as u64;
        let kind = match parts.kind {
            KeyKind::Implicit => 0u64,
            KeyKind::Grid => 1u64,
        };
        Some(Key(1 << 63
            | kind << 62
            | u64::from(parts.level) << 57
            | u64::from(parts.octant) << 54
            | u64::from(parts.normal_bin) << 51
            | off(v.x) << (2 * COORD_BITS)
            | off(v.y) << COORD_BITS
            | off(v.z)))
    }

    /// The fields of the key.
    pub fn unpack(self) -> KeyParts {
        let k = self.0;
        let mask = (1u64 << COORD_BITS) - 1;
        let coord = |shift: u32| ((k >> shift) & mask) as i32 + COORD_MIN;
        KeyParts {
            kind: if (k >> 62) & 1 == 0 {
                KeyKind::Implicit
            } else {
                KeyKind::Grid
            },
            level: ((k >> 57) & 31) as u32,
            voxel: IVec3::new(coord(2 * COORD_BITS), coord(COORD_BITS), coord(0)),
            octant: ((k >> 54) & 7) as u32,
            normal_bin: ((k >> 51) & 7) as u32,
        }
    }
}

/// The normal bin of unit normal `n`: its dominant axis and sign, 1..=6.
#[inline]
pub fn normal_bin(n: glam::Vec3) -> u32 {
    let a = n.abs();
    let (axis, c) = if a.x >= a.y && a.x >= a.z {
        (0, n.x)
    } else if a.y >= a.z {
        (1, n.y)
    } else {
        (2, n.z)
    };
    1 + 2 * axis + u32::from(c < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip_at_the_range_ends() {
        for voxel in [
            IVec3::new(COORD_MIN, 0, COORD_MAX),
            IVec3::new(-1, 1, 0),
            IVec3::splat(COORD_MAX),
        ] {
            let parts = KeyParts {
                kind: KeyKind::Grid,
                level: 31,
                voxel,
                octant: 7,
                normal_bin: 6,
            };
            let k = Key::pack(parts).unwrap();
            assert_ne!(k.0, 0);
            assert_eq!(k.unpack(), parts);
        }
        let out = KeyParts {
            kind: KeyKind::Implicit,
            level: 0,
            voxel: IVec3::new(COORD_MAX + 1, 0, 0),
            octant: 0,
            normal_bin: 0,
        };
        assert_eq!(Key::pack(out), None);
    }

    #[test]
    fn normal_bins_cover_six_directions() {
        use glam::Vec3;
        let bins: Vec<u32> = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
            .iter()
            .map(|&n| normal_bin(n))
            .collect();
        assert_eq!(bins, vec![1, 2, 3, 4, 5, 6]);
    }
}
