//! Uniform and irregular grids: the two grid baselines that seed 002 (Nilsson & Ottedag,
//! "Real-time path tracing of small scenes using WebGL", MSc thesis, Chalmers 2018) compares
//! against BVHs.
//!
//! - [`UniformGrid`]: one level of equal cells whose count follows Cleary's rule (Cleary, Wyvill,
//!   Birtwistle and Vatti, "Multiprocessor ray tracing", CGF 1986): `N_i = d_i · ∛(λN / V)`,
//!   with λ = 3 as in the thesis. Each cell lists the triangles that overlap it; the lists are
//!   one flat index array with per-cell offsets. Rays walk the cells with the 3D-DDA of
//!   Amanatides & Woo ("A fast voxel traversal algorithm for ray tracing", Eurographics 1987)
//!   and stop at the first cell whose exit lies beyond the closest hit so far.
//! - [`IrregularGrid`]: Pérard-Gayot, Kalojanov and Slusallek, "GPU Ray Tracing using Irregular
//!   Grids", CGF 36(2), 2017. A two-level grid is built at a fine virtual resolution, its cells
//!   are merged where the SAH says it pays, then expanded over neighbours whose triangles they
//!   already hold, and rays walk it by looking up the cell that owns the virtual cell at the
//!   current point and jumping to the exit of that cell's (expanded) box.
//!
//! Both keep a copy of the triangles in the caller's order (lists hold caller indices) and
//! intersect them with the watertight test of `rt-core`, so a hit is bit-identical to
//! [`crate::BruteForce`]'s.
//!
//! # Robustness
//!
//! Grids accept a hit found in a cell only once the walk has passed the hit's distance, so a
//! triangle hit beyond the current cell is kept as a candidate and a closer triangle in a later
//! cell still wins. Rounding makes the computed cell faces, entry points and hit points differ
//! from the exact ones by a few ulps; triangles are therefore binned against cells grown by a
//! margin (10⁻³ of a cell, and never less than 16 ulps of the domain's coordinates), so that a
//! hit point within the margin of a cell is always tested there. The exact overlap test is
//! conservative in the same way for triangles whose computed hits may stray from their plane:
//! the watertight test's distance of a sliver (area small against its longest edge squared)
//! carries a relative error of about `ε L² / |e₁ × e₂|`, so such triangles are binned against
//! cells grown by that much of the domain's diagonal, which for true slivers degenerates to
//! binning by bounding box (see [`Binning::Exact`]). Rays with a NaN or infinite component, or a
//! zero direction, hit nothing.
//!
//! # Deviations from seed 002 and the paper
//!
//! Uniform grid:
//! - Cleary's rule is applied to the scene box padded by 10⁻³ of its largest extent on every
//!   side, so flat scenes (all triangles in one plane) get a non-zero volume; per-axis counts
//!   are rounded to nearest and clamped to `[1, max_resolution]` (512 by default).
//! - Seed 002 did not say how it decided overlap; we use the triangle–box separating axis test
//!   (Akenine-Möller, "Fast 3D triangle-box overlap testing", JGT 2001) in double precision,
//!   with the margins above. [`Binning::Boxes`] bins by bounding box instead.
//! - Fujimoto's 3D-DDA in the thesis; we use Amanatides & Woo's, computing each next face
//!   distance from the face plane itself rather than by accumulating `tDelta`, so errors do not
//!   build up along long walks.
//!
//! Irregular grid (where the digest of seed 002 and the seed are silent we follow the paper as
//! we know it):
//! - The second level is a per-top-cell grid of `2^d` cells per axis (as seed 002 did; the
//!   paper used an octree, which subdivides space identically), with `d` from Cleary's rule
//!   with λ₂ on the top cell's triangle count (`2^d` the power of two nearest to `∛(λ₂ n)`
//!   in log scale, so a top cell gets about `λ₂ n` cells), capped by `max_depth` and so
//!   that the virtual grid has at most 1024 cells per axis (the seed's 10-bit packing) and
//!   `2^24` cells in all. λ₁ = 0.12 and λ₂ = 2.4 by default: our choice, of the order the paper
//!   used; seed 002's values are not stated.
//! - The SAH cost of a cell is `A (C_t + C_i n)` with its surface area `A` and `n` triangles
//!   (`C_t = C_i = 1` by default). Two neighbours merge if the cost of their union (counting the
//!   triangles they share once) is at most the sum of theirs. Merging is sequential: passes
//!   along x, y, z in turn, each pairing every cell with at most one `+axis` neighbour of the
//!   same cross-section, repeated until a round of three passes merges nothing; a chain of `n`
//!   mergeable cells thus takes about `log₂ n` passes, as with the paper's parallel chain
//!   merging, but the pairing is greedy in cell order rather than the paper's.
//! - Expansion runs `expansion_passes` (3, where the paper saw the gains end) rounds over
//!   x, y, z and both directions; a cell grows toward a side only if every cell across the
//!   face of its current (expanded) box holds a subset of its triangles, and then up to the
//!   nearest far face of those neighbours. Cells expand one after another and see the
//!   expansions made before them (the paper expands in parallel from the previous pass's
//!   boxes). The virtual grid keeps mapping every virtual cell to the cell it was merged into;
//!   only the box a ray leaves a cell by grows.
//! - Layout: a `u32` per virtual cell indexing a cell array (the expanded box as six `u16`
//!   virtual indices plus the list range), not the seed's copy of the cell's data into every
//!   virtual cell: on a CPU the second, cache-resident fetch is cheaper than four times the
//!   virtual grid's memory.
//! - The lookup after leaving a cell takes the exit face's virtual index exactly and clamps
//!   the other coordinates into the cell left (never moving backwards along the ray), so every
//!   step advances and the walk terminates whatever the rounding.
//!
//! Neither grid uses mailboxing: a triangle in several cells along a ray is tested once per
//! cell, and the counters count every test. Counters: `nodes_visited` counts the cells
//! visited (plus one for the grid's box), `leaves_visited` the non-empty ones.

mod domain;
mod irregular;
mod lists;
mod overlap;
mod uniform;

pub use irregular::{IrregularCell, IrregularGrid, IrregularGridParams};
pub use overlap::triangle_box_overlap;
pub use uniform::{UniformGrid, UniformGridParams};

/// How triangles are assigned to cells.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Binning {
    /// The triangle–box separating axis test, conservative by the margins explained in the
    /// module documentation (so slivers fall back to their bounding box).
    #[default]
    Exact,
    /// Every cell the triangle's bounding box overlaps.
    Boxes,
}

/// Why a grid could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// More triangles than `u32` indices can name.
    #[error("{0} triangles: grids index triangles with u32")]
    TooManyTriangles(usize),
    /// The cell lists would hold more than `u32::MAX` references.
    #[error("more than u32::MAX triangle references in the cell lists")]
    TooManyReferences,
    /// A parameter outside its range.
    #[error("grid parameter {name} = {value} is out of range ({expected})")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
}

fn check_positive(name: &'static str, value: f32) -> Result<(), GridError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GridError::BadParameter {
            name,
            value: value as f64,
            expected: "finite and positive",
        })
    }
}

fn check_count(n: usize) -> Result<(), GridError> {
    if n > u32::MAX as usize {
        Err(GridError::TooManyTriangles(n))
    } else {
        Ok(())
    }
}

/// True for rays the grids can walk: finite origin and finite, non-zero direction.
#[inline(always)]
fn walkable(ray: &rt_core::Ray) -> bool {
    ray.origin.is_finite() && ray.dir.is_finite() && ray.dir != glam::Vec3::ZERO
}
