//! Four-wide BVH (QBVH) made by collapsing a [`Bvh2`], after Dammertz et al., "Shallow Bounding
//! Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays" (EGSR 2008).
//!
//! Each [`QNode`] holds the boxes of up to four children in structure-of-arrays layout, so one
//! ray is tested against all four with one SIMD slab test (SSE2 on x86_64, a scalar loop
//! elsewhere). Leaves are encoded inline in the child codes and refer to the binary BVH's
//! leaf-ordered triangle copy; a binary leaf becomes a QBVH leaf unchanged.

mod collapse;
mod node;
mod options;
mod traverse;
mod validate;

pub use node::{QChild, QNode, EMPTY, LEAF_BIT, MAX_LEAF_TRIANGLES, MAX_TRIANGLES, NO_AXIS};
pub use options::{Order, QbvhOptions, TriangleTest, DEFAULT_LEAF_SIZE};

use crate::traversal::NoCount;
use crate::{BuildParams, Bvh2};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};

/// A four-wide bounding volume hierarchy over triangles.
#[derive(Clone, Debug)]
pub struct Qbvh {
    nodes: Vec<QNode>,
    triangles: Vec<[Vec3; 3]>,
    prim_ids: Vec<u32>,
    bounds: Aabb,
    options: QbvhOptions,
}

impl Qbvh {
    /// Builds a [`Bvh2`] over `triangles` with `params` and collapses it.
    ///
    /// # Panics
    ///
    /// If there are [`MAX_TRIANGLES`] (2^27) or more triangles.
    pub fn build(triangles: &[[Vec3; 3]], params: &BuildParams) -> Self {
        Self::from_bvh2(&Bvh2::build(triangles, params))
    }

    /// Builds with `params` and traverses with `options`.
    ///
    /// # Panics
    ///
    /// If there are [`MAX_TRIANGLES`] (2^27) or more triangles.
    pub fn build_with(
        triangles: &[[Vec3; 3]],
        params: &BuildParams,
        options: &QbvhOptions,
    ) -> Self {
        let mut q = Self::build(triangles, params);
        q.options = *options;
        q
    }

    /// The traversal options.
    pub fn options(&self) -> &QbvhOptions {
        &self.options
    }

    /// Collapses `bvh`: every node takes the two children of its binary node and then
    /// repeatedly replaces the inner child of largest surface area by that child's two
    /// children, until it has four children or only leaves. Triangles and prim ids are copied.
    ///
    /// # Panics
    ///
    /// If `bvh` has [`MAX_TRIANGLES`] (2^27) or more triangles.
    pub fn from_bvh2(bvh: &Bvh2) -> Self {
        assert!(
            bvh.triangles().len() < MAX_TRIANGLES,
            "Qbvh supports fewer than 2^27 triangles, got {}",
            bvh.triangles().len()
        );
        Self {
            nodes: collapse::collapse(bvh.nodes(), bvh.triangles()),
            triangles: bvh.triangles().to_vec(),
            prim_ids: bvh.prim_ids().to_vec(),
            bounds: bvh.bounds(),
            options: QbvhOptions::default(),
        }
    }

    /// The nodes, root first; empty for an empty scene. The root always has a node, even when
    /// the whole scene is one leaf.
    pub fn nodes(&self) -> &[QNode] {
        &self.nodes
    }

    /// The triangles in leaf order.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The caller's index of each triangle in [`Qbvh::triangles`].
    pub fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }
}

impl Accel for Qbvh {
    fn name(&self) -> &str {
        "qbvh"
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.traverse::<false, _>(ray, t_max, &mut NoCount)
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.traverse::<true, _>(ray, t_max, &mut NoCount).is_some()
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.prim_ids.as_slice())
    }

    fn intersect_counted(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
    ) -> Option<Hit> {
        self.traverse::<false, _>(ray, t_max, counters)
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
