//! The seam between the point sets and everything else: a [`Discretisation`] enumerates the
//! cached points around a position. Selection, the table and the Shepard reconstruction are
//! written once against it, so an A/B test of implicit points against the fixed grid changes
//! nothing but the point set.

use crate::key::{Key, KeyKind};
use glam::{IVec3, Vec3};

/// Which neighbouring voxels (or grid cells) the selection scans besides the one holding the
/// query: none, the 6 face neighbours, the 18 face and edge neighbours, or all 26.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Connectivity {
    /// The query's own voxel only.
    C0,
    /// Plus the 6 face neighbours.
    C6,
    /// Plus the 12 edge neighbours.
    C18,
    /// Plus the 8 corner neighbours: 27 voxels, the thesis' choice.
    C26,
}

impl Connectivity {
    /// From the number of neighbours (0, 6, 18 or 26).
    pub fn from_neighbours(n: u32) -> Option<Self> {
        Some(match n {
            0 => Connectivity::C0,
            6 => Connectivity::C6,
            18 => Connectivity::C18,
            26 => Connectivity::C26,
            _ => return None,
        })
    }

    /// The number of neighbours.
    pub fn neighbours(self) -> u32 {
        match self {
            Connectivity::C0 => 0,
            Connectivity::C6 => 6,
            Connectivity::C18 => 18,
            Connectivity::C26 => 26,
        }
    }

    /// True if offset `d` (each component in -1..=1) belongs to the neighbourhood.
    #[inline]
    pub fn contains(self, d: IVec3) -> bool {
        let manhattan = d.x.abs() + d.y.abs() + d.z.abs();
        match self {
            Connectivity::C0 => manhattan == 0,
            Connectivity::C6 => manhattan <= 1,
            Connectivity::C18 => manhattan <= 2,
            Connectivity::C26 => true,
        }
    }
}

/// A set of implicit or explicit points, each with an exact [`Key`], that a cache stores
/// values at.
pub trait Discretisation: Send + Sync {
    /// Which key space the points use.
    fn kind(&self) -> KeyKind;

    /// Mean distance between neighbouring points (world units): one point per cube of this
    /// edge.
    fn spacing(&self) -> f32;

    /// Edge of the voxels (or cells) the points are generated in.
    fn voxel_edge(&self) -> f32;

    /// Calls `f(position, key)` for every point of the voxel holding `x` and of its
    /// neighbours under `c`.
    fn for_each_candidate<F: FnMut(Vec3, Key)>(&self, x: Vec3, c: Connectivity, f: F);

    /// Like [`Discretisation::for_each_candidate`], nearest voxels first, but `f` returns a
    /// squared distance beyond which it wants no more points, and voxels (cells) that lie
    /// wholly beyond it are skipped: the same result for a k-nearest search, at a fraction
    /// of the point generation.
    fn for_each_candidate_pruned<F: FnMut(Vec3, Key) -> f32>(&self, x: Vec3, c: Connectivity, f: F);

    /// Calls `f(position, key)` for the points of the voxels (cells) that can hold a point
    /// within `distance` of `x`: every such point, and some farther ones, which callers cull.
    fn for_each_near<F: FnMut(Vec3, Key)>(&self, x: Vec3, distance: f32, f: F);
}

/// The integer voxel of edge `edge` holding `x`.
#[inline]
pub(crate) fn voxel_of(x: Vec3, edge: f32) -> IVec3 {
    (x / edge).floor().as_ivec3()
}

/// Calls `f(d)` for every offset `d` of the cube `[-ring, ring]^3`.
#[inline]
pub(crate) fn for_each_offset(ring: i32, mut f: impl FnMut(IVec3)) {
    for dz in -ring..=ring {
        for dy in -ring..=ring {
            for dx in -ring..=ring {
                f(IVec3::new(dx, dy, dz));
            }
        }
    }
}

/// Calls `f(v)` for every `v` with `lo <= v <= hi` componentwise.
#[inline]
pub(crate) fn for_each_in_range(lo: IVec3, hi: IVec3, mut f: impl FnMut(IVec3)) {
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                f(IVec3::new(x, y, z));
            }
        }
    }
}

/// The 27 offsets of a voxel's 26-neighbourhood, the voxel itself first, then faces, edges
/// and corners: near voxels first, so a k-nearest search tightens its bound early.
pub(crate) const OFFSETS_NEAR_FIRST: [[i32; 3]; 27] = {
    let mut out = [[0i32; 3]; 27];
    let mut n = 0;
    let mut manhattan = 0i32;
    while manhattan <= 3 {
        let mut i = 0;
        while i < 27 {
            let d: [i32; 3] = [i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1];
            if d[0].abs() + d[1].abs() + d[2].abs() == manhattan {
                out[n] = d;
                n += 1;
            }
            i += 1;
        }
        manhattan += 1;
    }
    out
};

/// Visits the voxels (edge `edge`) of `x`'s neighbourhood under `c`, nearest first, calling
/// `visit(voxel)` only for voxels whose squared distance from `x` is below the bound the
/// previous visit returned (infinite at first).
#[inline]
pub(crate) fn visit_pruned(
    x: Vec3,
    edge: f32,
    c: Connectivity,
    mut visit: impl FnMut(IVec3) -> f32,
) {
    let v = voxel_of(x, edge);
    let f = x / edge - v.as_vec3();
    // Squared distance from x to the neighbour below (index 0) and above (2) on each axis.
    let below = (f * edge) * (f * edge);
    let above = ((Vec3::ONE - f) * edge) * ((Vec3::ONE - f) * edge);
    let mut bound = f32::INFINITY;
    for d in OFFSETS_NEAR_FIRST {
        let d = IVec3::from_array(d);
        if !c.contains(d) {
            continue;
        }
        let axis = |k: usize| match d[k] {
            -1 => below[k],
            1 => above[k],
            _ => 0.0,
        };
        if axis(0) + axis(1) + axis(2) >= bound {
            continue;
        }
        bound = visit(v + d);
    }
}
