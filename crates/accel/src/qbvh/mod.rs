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
mod shadow_cache;
mod traverse;
mod tri4;
mod validate;

pub use node::{QChild, QNode, EMPTY, LEAF_BIT, MAX_LEAF_TRIANGLES, MAX_TRIANGLES, NO_AXIS};
pub use options::{Order, QbvhOptions, TriangleTest, DEFAULT_INTERSECTION_COST, DEFAULT_LEAF_SIZE};
pub use tri4::Tri4;

use crate::traversal::{Counter, NoCount};
use crate::{BuildParams, Bvh2};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};
use traverse::{DISTANCE, SPLIT_PLANE, UNSORTED};

/// A four-wide bounding volume hierarchy over triangles.
#[derive(Clone, Debug)]
pub struct Qbvh {
    nodes: Vec<QNode>,
    packets: Vec<Tri4>,
    packet_ids: Vec<[u32; 4]>,
    references: usize,
    /// Built from split references: a leaf box may bound only a piece of a triangle.
    split: bool,
    bounds: Aabb,
    /// The CPU has AVX2: traversal runs a copy compiled for it.
    avx2: bool,
    /// Tags this structure's entries in the per-thread shadow-cache tables.
    id: u64,
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
        let c = collapse::collapse(bvh.nodes(), bvh.triangles(), bvh.prim_ids());
        Self {
            nodes: c.nodes,
            packets: c.packets,
            packet_ids: c.packet_ids,
            references: bvh.triangles().len(),
            split: bvh.is_split(),
            bounds: bvh.bounds(),
            #[cfg(target_arch = "x86_64")]
            avx2: std::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            avx2: false,
            id: shadow_cache::new_id(),
            options: QbvhOptions::default(),
        }
    }

    /// The nodes, root first; empty for an empty scene. The root always has a node, even when
    /// the whole scene is one leaf.
    pub fn nodes(&self) -> &[QNode] {
        &self.nodes
    }

    /// The leaf triangles, four to a packet, in leaf order.
    pub fn packets(&self) -> &[Tri4] {
        &self.packets
    }

    /// The triangle and caller's index in lane slot `slot` (`4 * packet + lane`, as in
    /// [`QChild::Leaf`]).
    pub fn reference(&self, slot: usize) -> ([Vec3; 3], u32) {
        let (p, lane) = (slot / 4, slot % 4);
        (self.packets[p].triangle(lane), self.packet_ids[p][lane])
    }

    /// Number of triangle references in the leaves (the triangle count, unless the build split
    /// triangles).
    pub fn reference_count(&self) -> usize {
        self.references
    }

    /// Runs the traversal variant the options select, compiled for AVX2 when the CPU has it.
    #[inline]
    fn query<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when `is_x86_feature_detected!("avx2")` said so.
            #[allow(unsafe_code)]
            return unsafe { self.query_avx2::<ANY_HIT, C>(ray, t_max, c) };
        }
        self.query_any::<ANY_HIT, C>(ray, t_max, c)
    }

    /// [`Qbvh::query_any`] compiled with AVX2 enabled: the same SSE2 code, VEX-encoded.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn query_avx2<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        self.query_any::<ANY_HIT, C>(ray, t_max, c)
    }

    #[inline(always)]
    fn query_any<const ANY_HIT: bool, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        match (self.options.order, self.options.t_stack) {
            (Order::SplitPlane, false) => {
                self.traverse::<ANY_HIT, SPLIT_PLANE, false, C>(ray, t_max, c)
            }
            (Order::SplitPlane, true) => {
                self.traverse::<ANY_HIT, SPLIT_PLANE, true, C>(ray, t_max, c)
            }
            (Order::Distance, false) => self.traverse::<ANY_HIT, DISTANCE, false, C>(ray, t_max, c),
            (Order::Distance, true) => self.traverse::<ANY_HIT, DISTANCE, true, C>(ray, t_max, c),
            (Order::Unsorted, false) => self.traverse::<ANY_HIT, UNSORTED, false, C>(ray, t_max, c),
            (Order::Unsorted, true) => self.traverse::<ANY_HIT, UNSORTED, true, C>(ray, t_max, c),
        }
    }
}

impl Accel for Qbvh {
    fn name(&self) -> &str {
        "qbvh"
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.query::<false, _>(ray, t_max, &mut NoCount)
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.query::<true, _>(ray, t_max, &mut NoCount).is_some()
    }

    fn occluded_toward(&self, ray: &Ray, t_max: f32, target: Vec3) -> bool {
        if self.options.shadow_cache {
            self.occluded_cached(ray, t_max, target, &mut NoCount)
        } else {
            self.occluded(ray, t_max)
        }
    }

    fn occluded_toward_counted(
        &self,
        ray: &Ray,
        t_max: f32,
        target: Vec3,
        counters: &mut TraversalCounters,
    ) -> bool {
        if self.options.shadow_cache {
            self.occluded_cached(ray, t_max, target, counters)
        } else {
            self.query::<true, _>(ray, t_max, counters).is_some()
        }
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.packets.as_slice())
            + std::mem::size_of_val(self.packet_ids.as_slice())
    }

    fn intersect_counted(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut TraversalCounters,
    ) -> Option<Hit> {
        self.query::<false, _>(ray, t_max, counters)
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}
