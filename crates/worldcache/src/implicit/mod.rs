//! Implicit progressive points (Delaere 2021, §3.1): a virtual octree whose voxels at level
//! `l` have edge `s0 / 2^l`. Each voxel hashes its centre to a seed; the seed drives a 1D→3D
//! hash that places 8 points, one in each octant (jittered sampling at half-voxel
//! resolution). Points are never stored: every query regenerates them.
//!
//! Seeding, as the thesis prescribes: the voxel *centre* in fixed point (units of
//! `s0 / 2^(MAX_LEVEL+1)`, so every level's centres are integers), each axis folded to a 32-bit
//! sign-magnitude word, then the nested PCG 3D→1D hash of Jarzynski & Olano 2020. Point `q`
//! uses seed `seed + q`. Centres of different levels never coincide (a level-`l` centre is an
//! odd multiple of `2^(MAX_LEVEL-l)`), corners do (the corner of a voxel is the corner of its
//! first child), which is why the thesis calls the centre offset mandatory; [`Anchor::Corner`]
//! exists only as the negative control of that claim.
//!
//! Deviations from the thesis: keys are the exact 64-bit [`Key`]s of `crate::key` (level,
//! voxel, octant) rather than the 32-bit `seed + q`, so two points never share a table entry;
//! the seed only places points. The fixed-point words fold a 64-bit coordinate into 31 bits
//! instead of limiting the world to 31 bits. The cross-LOD variant (Appendix A) is not built
//! (the thesis rejects it as 3× slower).

use crate::discretisation::{
    for_each_in_range, for_each_offset, visit_pruned, voxel_of, Connectivity, Discretisation,
};
use crate::hash::{pcg, pcg3_to_1, unit3_of_hash};
use crate::key::{Key, KeyKind, KeyParts, MAX_LEVEL};
use glam::{I64Vec3, IVec3, Vec3};

/// Which voxel point the seed hashes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Anchor {
    /// The voxel centre (the thesis' method).
    #[default]
    Centre,
    /// The voxel's minimum corner: shared between levels, so seeds repeat (negative control).
    Corner,
}

/// The implicit points of one level of the octree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitPoints {
    /// Edge of a level-0 voxel (world units).
    pub s0: f32,
    /// Level of detail (voxel edge `s0 / 2^lod`).
    pub lod: u32,
    /// What the seeds hash.
    pub anchor: Anchor,
}

impl ImplicitPoints {
    /// Points at level `lod` of an octree with level-0 edge `s0`, seeded by voxel centres.
    pub fn new(s0: f32, lod: u32) -> Self {
        Self {
            s0,
            lod: lod.min(MAX_LEVEL),
            anchor: Anchor::Centre,
        }
    }

    /// Edge of a voxel at this level.
    #[inline]
    pub fn edge(&self) -> f32 {
        self.s0 / (1u64 << self.lod) as f32
    }

    /// The seed's anchor of voxel `v` at level `level` in fixed point: units of
    /// `s0 / 2^(MAX_LEVEL + 1)`, exact integers for every level.
    pub fn anchor_fixed(anchor: Anchor, v: IVec3, level: u32) -> I64Vec3 {
        let shift = MAX_LEVEL - level.min(MAX_LEVEL);
        let v = v.as_i64vec3();
        let twice = match anchor {
            Anchor::Centre => v * 2 + I64Vec3::ONE,
            Anchor::Corner => v * 2,
        };
        twice * (1i64 << shift)
    }

    /// The seed of voxel `v` at level `level`.
    #[inline]
    pub fn voxel_seed(&self, v: IVec3, level: u32) -> u32 {
        let f = Self::anchor_fixed(self.anchor, v, level);
        pcg3_to_1(fixed_word(f.x), fixed_word(f.y), fixed_word(f.z))
    }

    /// The 8 points of voxel `v` with their keys, point `q` in octant `q` (bit 0 x, bit 1 y,
    /// bit 2 z); `None`: the voxel is outside the key range.
    pub fn voxel_points(&self, v: IVec3) -> Option<[(Vec3, Key); 8]> {
        let mut out = [(Vec3::ZERO, Key(0)); 8];
        let mut n = 0;
        self.visit(v, &mut |p, k| {
            out[n] = (p, k);
            n += 1;
        });
        (n == 8).then_some(out)
    }

    #[inline]
    fn visit<F: FnMut(Vec3, Key)>(&self, v: IVec3, f: &mut F) {
        let Some(base) = Key::pack(KeyParts {
            kind: KeyKind::Implicit,
            level: self.lod,
            voxel: v,
            octant: 0,
            normal_bin: 0,
        }) else {
            return;
        };
        let seed = self.voxel_seed(v, self.lod);
        // The hot loop of every query: hash all 8 points first (a loop the compiler can
        // vectorise), then place them; the far-face clamps are computed once per voxel.
        let hashes: [u32; 8] = std::array::from_fn(|q| pcg(seed.wrapping_add(q as u32)));
        let half = self.edge() * 0.5;
        let lo = v.as_vec3() * self.edge();
        let mid = lo + Vec3::splat(half);
        let hi = [mid, mid + Vec3::splat(half)]
            .map(|b| Vec3::from_array(b.to_array().map(f32::next_down)));
        for (q, h) in hashes.into_iter().enumerate() {
            let u = unit3_of_hash(h);
            let o = [q & 1, (q >> 1) & 1, (q >> 2) & 1];
            let start = Vec3::new(
                if o[0] == 1 { mid.x } else { lo.x },
                if o[1] == 1 { mid.y } else { lo.y },
                if o[2] == 1 { mid.z } else { lo.z },
            );
            let cap = Vec3::new(hi[o[0]].x, hi[o[1]].y, hi[o[2]].z);
            let p = (start + u * half).min(cap);
            f(p, Key(base.0 | (q as u64) << 54));
        }
    }
}

/// A signed fixed-point coordinate as a 32-bit sign-magnitude word (sign in the MSB, the
/// thesis' Fig. 3); magnitudes above 31 bits are folded in by hashing the high part.
#[inline]
fn fixed_word(c: i64) -> u32 {
    let sign = u32::from(c < 0) << 31;
    let mag = c.unsigned_abs();
    let low = mag as u32 & 0x7fff_ffff;
    let high = (mag >> 31) as u32;
    let folded = if high == 0 {
        low
    } else {
        (low ^ pcg(high)) & 0x7fff_ffff
    };
    sign | folded
}

impl Discretisation for ImplicitPoints {
    fn kind(&self) -> KeyKind {
        KeyKind::Implicit
    }

    fn spacing(&self) -> f32 {
        self.edge() * 0.5
    }

    fn voxel_edge(&self) -> f32 {
        self.edge()
    }

    #[inline]
    fn for_each_candidate<F: FnMut(Vec3, Key)>(&self, x: Vec3, c: Connectivity, mut f: F) {
        let v = voxel_of(x, self.edge());
        for_each_offset(1, |d| {
            if c.contains(d) {
                self.visit(v + d, &mut f);
            }
        });
    }

    #[inline]
    fn for_each_candidate_pruned<F: FnMut(Vec3, Key) -> f32>(
        &self,
        x: Vec3,
        c: Connectivity,
        mut f: F,
    ) {
        let mut bound = f32::INFINITY;
        visit_pruned(x, self.edge(), c, |v| {
            self.visit(v, &mut |p, k| bound = f(p, k));
            bound
        });
    }

    #[inline]
    fn for_each_near<F: FnMut(Vec3, Key)>(&self, x: Vec3, distance: f32, mut f: F) {
        // The voxels that meet the ball of radius `distance` around x: every point within
        // `distance` lies in one of them.
        let edge = self.edge();
        let lo = voxel_of(x - Vec3::splat(distance), edge);
        let hi = voxel_of(x + Vec3::splat(distance), edge);
        let d2 = distance * distance;
        for_each_in_range(lo, hi, |v| {
            // Skip voxels of the box that miss the ball: no point of theirs is near enough.
            let min = v.as_vec3() * edge;
            let gap = (min - x).max(x - (min + Vec3::splat(edge))).max(Vec3::ZERO);
            if gap.length_squared() < d2 {
                self.visit(v, &mut f)
            }
        });
    }
}
