//! World-space reconstruction: modified Shepard interpolation (Bikker & Reijerse 2009, as the
//! thesis uses it, §3.2 Eq. 3) over the cached points near a position. Each stored point `i`
//! at distance `d_i < sd` weighs `sd − d_i` (a linear tent; the exact form was lost from the
//! text, seed digest §1.7 \[recon\]); `F = Σ w_i v_i / Σ w_i`. Points are culled by distance
//! before the table is probed (digest §6), and the search distance is a multiple of the point
//! spacing, so it follows the level of detail. No normals, depths or edge-stopping weights,
//! as in the thesis.

use crate::discretisation::Discretisation;
use crate::key::Key;
use crate::table::PersistentTable;
use glam::Vec3;

/// A reconstructed value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lookup {
    /// Shepard-weighted mean of the stored values.
    pub value: Vec3,
    /// Sum of the stored counts of the points that contributed.
    pub samples: f32,
    /// Points that contributed.
    pub points: u32,
}

/// The Shepard reconstruction at `x` with search distance `sd`, reading keys with normal bin
/// `bin` (0: none). `None` where no stored point lies within `sd`.
#[inline]
pub fn shepard<D: Discretisation>(
    points: &D,
    table: &PersistentTable,
    x: Vec3,
    sd: f32,
    bin: u32,
) -> Option<Lookup> {
    let (mut num, mut den, mut samples, mut n) = (Vec3::ZERO, 0.0f32, 0.0f32, 0u32);
    let sd2 = sd * sd;
    points.for_each_near(x, sd, |p, k| {
        let d2 = (p - x).length_squared();
        if d2 >= sd2 {
            return;
        }
        let Some(e) = table.get(with_bin(k, bin)) else {
            return;
        };
        let w = sd - d2.sqrt();
        num += w * Vec3::from_array(e.value);
        den += w;
        samples += e.count;
        n += 1;
    });
    (den > 0.0).then(|| Lookup {
        value: num / den,
        samples,
        points: n,
    })
}

/// `k` with normal bin `bin`.
#[inline]
pub fn with_bin(k: Key, bin: u32) -> Key {
    Key(k.0 | u64::from(bin) << 51)
}
