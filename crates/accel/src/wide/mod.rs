//! Wide BVHs made by collapsing a [`Bvh2`]: the four-wide QBVH of Dammertz et al., "Shallow
//! Bounding Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays" (EGSR 2008), and
//! its eight-wide sibling.
//!
//! Each [`QNode`] holds the boxes of up to four children in structure-of-arrays layout, so one
//! ray is tested against all four with one SIMD slab test (SSE2 on x86_64, a scalar loop
//! elsewhere); a [`Node8`] holds eight, tested with one AVX2 instruction per plane where the CPU
//! has AVX2 (two SSE2 halves otherwise). Leaves are encoded inline in the child codes and hold
//! the binary BVH's leaf-ordered triangles, swizzled four to a [`Tri4`] packet.
//!
//! [`WideBvh`] is generic over the node ([`WideNode`]): [`Qbvh`] and [`Bvh8`] share the
//! collapse, the traversal loop, the shadow cache and the validator.

mod bvh;
mod bvh8_node;
mod collapse;
mod options;
#[cfg(target_arch = "x86_64")]
mod packet;
mod qbvh_node;
mod shadow_cache;
mod stream;
mod traverse;
pub(crate) mod tri4;
mod validate;

pub use bvh::{Avx2, Baseline, Isa, WideNode};
pub use bvh8_node::Node8;
pub use options::{Order, TriangleTest, WideOptions, DEFAULT_INTERSECTION_COST, DEFAULT_LEAF_SIZE};
pub use qbvh_node::{QChild, QNode, EMPTY, LEAF_BIT, MAX_LEAF_TRIANGLES, MAX_TRIANGLES, NO_AXIS};
pub(crate) use traverse::Slab;
pub use tri4::Tri4;

use crate::traversal::{with_counter, Counter};
use crate::{BuildParams, Bvh2};
use glam::Vec3;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};
pub use traverse::PreparedRay;
use traverse::{DISTANCE, SPLIT_PLANE, UNSORTED};

/// A four-wide bounding volume hierarchy over triangles (Dammertz's QBVH).
pub type Qbvh = WideBvh<QNode>;

/// An eight-wide bounding volume hierarchy over triangles.
pub type Bvh8 = WideBvh<Node8>;

/// Scenes up to this many triangles get a [`Bvh8`] collapsed from one-triangle binary leaves.
///
/// Why: the SAH does not model a closest-hit ray stopping at its first hit. In a closed room
/// (the Cornell box) every split leaves boxes almost as large as their parent, so the SAH keeps
/// leaves of 16 large triangles and every ray tests 13 to 16 of them; from single-triangle
/// leaves the planned collapse makes a tree in which the ordered traversal stops after 3 to 6,
/// and the path tracer executes 15 % fewer instructions there (callgrind, `docs/benchmarks.md`).
/// Such a structure is small enough (64 bytes a triangle) to stay in the first two cache
/// levels; above a few thousand triangles fine leaves cost more in nodes than they save (the
/// teapot, 6k triangles: 5 % slower uniform rays).
pub const FINE_LEAVES_MAX_TRIANGLES: usize = 1024;

/// A bounding volume hierarchy whose nodes have up to `N::WIDTH` children: [`Qbvh`] or [`Bvh8`].
#[derive(Clone, Debug)]
pub struct WideBvh<N: WideNode> {
    nodes: Vec<N>,
    packets: Vec<Tri4>,
    packet_ids: Vec<[u32; 4]>,
    references: usize,
    /// Built from split references: a leaf box may bound only a piece of a triangle.
    split: bool,
    bounds: Aabb,
    /// Set when the CPU has AVX2: traversal then runs a copy compiled for it.
    avx2: Option<Avx2>,
    /// Tags this structure's entries in the per-thread shadow-cache tables.
    id: u64,
    options: WideOptions,
}

impl<N: WideNode> WideBvh<N> {
    /// Builds a [`Bvh2`] over `triangles` with `params` and collapses it.
    ///
    /// # Panics
    ///
    /// If there are [`MAX_TRIANGLES`] (2^27) or more triangles.
    /// A [`Bvh8`] over at most [`FINE_LEAVES_MAX_TRIANGLES`] triangles starts from a binary
    /// tree of one-triangle leaves, whatever `params.max_leaf_size` says: its collapse then
    /// chooses every leaf.
    pub fn build(triangles: &[[Vec3; 3]], params: &BuildParams) -> Self {
        let mut params = *params;
        if N::PLANNED_COLLAPSE && triangles.len() <= FINE_LEAVES_MAX_TRIANGLES {
            params.max_leaf_size = 1;
        }
        Self::from_bvh2(&Bvh2::build(triangles, &params))
    }

    /// Builds with `params` and traverses with `options`.
    ///
    /// # Panics
    ///
    /// If there are [`MAX_TRIANGLES`] (2^27) or more triangles.
    pub fn build_with(
        triangles: &[[Vec3; 3]],
        params: &BuildParams,
        options: &WideOptions,
    ) -> Self {
        let mut q = Self::build(triangles, params);
        q.options = *options;
        q
    }

    /// The traversal options.
    pub fn options(&self) -> &WideOptions {
        &self.options
    }

    /// Collapses `bvh`. A [`Bvh8`] takes the collapse of least SAH cost, in which a slot may
    /// also be a whole binary subtree of up to [`MAX_LEAF_TRIANGLES`] triangles made one leaf
    /// (Ylitie et al. 2017, see `collapse.rs`). A [`Qbvh`] keeps Dammertz's greedy collapse:
    /// every node takes the two children of its binary node and then repeatedly replaces the
    /// inner child of largest surface area by that child's two children, until it has
    /// `N::WIDTH` children or only leaves. Triangles and prim ids are copied.
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
        let sah = N::PLANNED_COLLAPSE.then_some(collapse::PLAN_COSTS);
        let c = collapse::collapse::<N>(bvh.nodes(), bvh.triangles(), bvh.prim_ids(), sah);
        Self {
            nodes: c.nodes,
            packets: c.packets,
            packet_ids: c.packet_ids,
            references: bvh.triangles().len(),
            split: bvh.is_split(),
            bounds: bvh.bounds(),
            avx2: Avx2::detect(),
            id: shadow_cache::new_id(),
            options: WideOptions::defaults_for::<N>(),
        }
    }

    /// The nodes, root first; empty for an empty scene. The root always has a node, even when
    /// the whole scene is one leaf.
    pub fn nodes(&self) -> &[N] {
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

    /// Closest hit within the subtree of child code `entry` (an inner node's index or a leaf
    /// code, as [`WideBvh::entry_points`] gives them; 0 is the root): what a two-level
    /// structure whose top level ends at entry points continues with.
    pub fn closest_hit_from(
        &self,
        entry: u32,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        if entry == 0 {
            return self.closest_hit(ray, t_max, counters);
        }
        with_counter!(counters, |c| self.query::<false, _>(entry, ray, t_max, c))
    }

    /// True if anything in the subtree of child code `entry` is hit within `t_max`.
    pub fn any_hit_from(
        &self,
        entry: u32,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        with_counter!(counters, |c| self
            .query::<true, _>(entry, ray, t_max, c)
            .is_some())
    }

    /// `ray` set up for [`WideBvh::closest_hit_prepared`] and [`WideBvh::any_hit_prepared`].
    pub fn prepare(ray: &Ray) -> PreparedRay {
        PreparedRay::new(ray)
    }

    /// [`WideBvh::closest_hit_from`] with the ray's setup made by [`WideBvh::prepare`] and
    /// kept there for the next call: a clustered top level enters several entry points of
    /// one object in a row with the same object-space ray.
    pub fn closest_hit_prepared(
        &self,
        entry: u32,
        ray: &mut PreparedRay,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        with_counter!(counters, |c| self
            .query_prepared::<false, _>(entry, ray, t_max, c))
    }

    /// [`WideBvh::any_hit_from`] with the ray's setup kept (see
    /// [`WideBvh::closest_hit_prepared`]).
    pub fn any_hit_prepared(
        &self,
        entry: u32,
        ray: &mut PreparedRay,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        with_counter!(counters, |c| self
            .query_prepared::<true, _>(entry, ray, t_max, c)
            .is_some())
    }

    /// [`WideBvh::query`] on a prepared ray.
    #[inline]
    fn query_prepared<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &mut PreparedRay,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.query_prepared_avx2::<ANY_HIT, C>(start, ray, t_max, avx2, c) };
        }
        self.query_any::<ANY_HIT, _, C>(start, ray, t_max, Baseline, c)
    }

    /// [`WideBvh::query_prepared`] compiled with AVX2 enabled.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn query_prepared_avx2<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &mut PreparedRay,
        t_max: f32,
        avx2: Avx2,
        c: &mut C,
    ) -> Option<Hit> {
        self.query_any::<ANY_HIT, _, C>(start, ray, t_max, avx2, c)
    }

    /// The cut of the tree into entry points for rigid-body clustering (Dammertz §4.5): the
    /// children, top down from the root's, whose boxes are smaller than `size` (longest side)
    /// or that are leaves, with their boxes. The root is never one (the thesis' t = 1 gives
    /// four entries per QBVH: the root's children); one entry per object is `two-level`.
    pub fn entry_points(&self, size: f32) -> Vec<(u32, Aabb)> {
        let longest = |b: &Aabb| (b.max - b.min).max_element();
        if self.nodes.is_empty() {
            return Vec::new();
        }
        let mut out = Vec::new();
        let mut pending = vec![0usize];
        while let Some(n) = pending.pop() {
            let node = &self.nodes[n];
            for slot in 0..N::WIDTH {
                match node.child(slot) {
                    QChild::Empty => {}
                    QChild::Inner(i) if longest(&node.child_aabb(slot)) >= size => pending.push(i),
                    _ => out.push((node.code(slot), node.child_aabb(slot))),
                }
            }
        }
        out
    }

    /// Runs the traversal variant the options select, compiled for AVX2 when the CPU has it.
    #[inline]
    fn query<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &Ray,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            return self.query_isa::<ANY_HIT, C>(start, ray, t_max, avx2, c);
        }
        self.query_baseline::<ANY_HIT, C>(start, ray, t_max, c)
    }

    /// [`WideBvh::query`] for a CPU with AVX2, in the compilation [`Avx2::evex_for`] picks.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn query_isa<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &Ray,
        t_max: f32,
        avx2: Avx2,
        c: &mut C,
    ) -> Option<Hit> {
        // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2, and AVX-512F and
        // AVX-512VL where `evex_for` says so.
        #[allow(unsafe_code)]
        unsafe {
            if avx2.evex_for(ANY_HIT) {
                self.query_avx512::<ANY_HIT, C>(start, ray, t_max, avx2, c)
            } else {
                self.query_avx2::<ANY_HIT, C>(start, ray, t_max, avx2, c)
            }
        }
    }

    /// [`WideBvh::query_avx2`] compiled with AVX-512F and AVX-512VL too (see
    /// [`Avx2::avx512vl`]).
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2, AVX-512F and AVX-512VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    unsafe fn query_avx512<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &Ray,
        t_max: f32,
        avx2: Avx2,
        c: &mut C,
    ) -> Option<Hit> {
        self.query_any::<ANY_HIT, _, C>(start, &mut PreparedRay::new(ray), t_max, avx2, c)
    }

    /// [`WideBvh::query_any`] without AVX2. Kept out of line so that [`WideBvh::query`] stays a
    /// branch, not a second 6 KB stack frame set up for every ray.
    #[inline(never)]
    fn query_baseline<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &Ray,
        t_max: f32,
        c: &mut C,
    ) -> Option<Hit> {
        self.query_any::<ANY_HIT, _, C>(start, &mut PreparedRay::new(ray), t_max, Baseline, c)
    }

    /// [`WideBvh::query_any`] compiled with AVX2 enabled: the eight-wide box test in one
    /// register, and the four-wide code VEX-encoded.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn query_avx2<const ANY_HIT: bool, C: Counter>(
        &self,
        start: u32,
        ray: &Ray,
        t_max: f32,
        avx2: Avx2,
        c: &mut C,
    ) -> Option<Hit> {
        self.query_any::<ANY_HIT, _, C>(start, &mut PreparedRay::new(ray), t_max, avx2, c)
    }

    #[inline(always)]
    fn query_any<const ANY_HIT: bool, I: Isa, C: Counter>(
        &self,
        start: u32,
        ray: &mut PreparedRay,
        t_max: f32,
        isa: I,
        c: &mut C,
    ) -> Option<Hit> {
        // An any-hit query stops at its first hit, so the culling distance never shrinks and
        // entry distances on the stack would cull nothing.
        match (self.options.order, self.options.t_stack && !ANY_HIT) {
            (Order::SplitPlane, false) => {
                self.traverse::<ANY_HIT, SPLIT_PLANE, false, I, C>(start, ray, t_max, isa, c)
            }
            (Order::SplitPlane, true) => {
                self.traverse::<ANY_HIT, SPLIT_PLANE, true, I, C>(start, ray, t_max, isa, c)
            }
            (Order::Distance, false) => {
                self.traverse::<ANY_HIT, DISTANCE, false, I, C>(start, ray, t_max, isa, c)
            }
            (Order::Distance, true) => {
                self.traverse::<ANY_HIT, DISTANCE, true, I, C>(start, ray, t_max, isa, c)
            }
            (Order::Unsorted, false) => {
                self.traverse::<ANY_HIT, UNSORTED, false, I, C>(start, ray, t_max, isa, c)
            }
            (Order::Unsorted, true) => {
                self.traverse::<ANY_HIT, UNSORTED, true, I, C>(start, ray, t_max, isa, c)
            }
        }
    }
}

impl<N: WideNode> Accel for WideBvh<N> {
    fn name(&self) -> &str {
        N::NAME
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        with_counter!(counters, |c| self.query::<false, _>(0, ray, t_max, c))
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        counters: Option<&mut TraversalCounters>,
    ) -> bool {
        match toward {
            Some(target) if self.options.shadow_cache => {
                with_counter!(counters, |c| self.occluded_cached(ray, t_max, target, c))
            }
            _ => with_counter!(counters, |c| self
                .query::<true, _>(0, ray, t_max, c)
                .is_some()),
        }
    }

    /// One dispatch per stream, the single-ray traversal inlined into the loop over the rays
    /// (`stream.rs`): the same answers as [`Accel::intersect`] ray by ray.
    fn intersect_stream(&self, rays: &[Ray], t_max: &[f32], hits: &mut [Option<Hit>]) {
        self.closest_stream(rays, t_max, hits);
    }

    /// As [`Accel::intersect_stream`], for occlusion: the same answers as
    /// [`Accel::occluded_toward`] (or [`Accel::occluded`]) ray by ray.
    fn occluded_stream(&self, rays: &[Ray], t_max: &[f32], toward: &[Vec3], occluded: &mut [bool]) {
        self.occluded_stream_impl(rays, t_max, toward, occluded);
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.packets.as_slice())
            + std::mem::size_of_val(self.packet_ids.as_slice())
    }

    /// Nodes, triangle ids and the packets' unused lanes: the packets less 36 bytes per
    /// reference (a reference split into several leaves counts once per leaf).
    fn structure_bytes(&self) -> Option<usize> {
        let vertices = self.references * std::mem::size_of::<[Vec3; 3]>();
        Some(self.memory_bytes().saturating_sub(vertices))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod evex_tests {
    use super::*;
    use rt_core::rng::SplitMix64;
    use rt_core::sampling::uniform_sphere;

    /// The traversal compiled with AVX-512VL answers exactly what the AVX2-only compilation
    /// answers, for single rays and packet streams. Only a CPU with both compiles both; on any
    /// other the one that runs is checked against brute force by the integration tests.
    #[test]
    fn the_avx512vl_compilation_gives_the_avx2_answers() {
        let mut rng = SplitMix64::new(9);
        let mut point = |s: f32| Vec3::new(rng.f32(), rng.f32(), rng.f32()) * s;
        let tris: Vec<[Vec3; 3]> = (0..3000)
            .map(|_| {
                let c = point(20.0);
                [c, c + point(1.5), c + point(1.5)]
            })
            .collect();
        let mut bvh = Bvh8::build(&tris, &BuildParams::default());
        let Some(avx2) = bvh.avx2.filter(|a| a.avx512vl()) else {
            eprintln!("no AVX-512VL here: one compilation only");
            return;
        };
        let mut rng = SplitMix64::new(10);
        // Random rays, and runs of eight from one origin into one octant (packets).
        let rays: Vec<Ray> = (0..4000)
            .map(|i| {
                let o = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 20.0;
                let d = uniform_sphere(rng.vec2());
                let d = if i % 16 < 8 { d.abs() } else { d };
                Ray::new(if i % 16 < 8 { Vec3::splat(-1.0) } else { o }, d)
            })
            .collect();
        let t_max = vec![f32::INFINITY; rays.len()];
        let toward = vec![Vec3::splat(f32::INFINITY); rays.len()];
        let answers = |bvh: &Bvh8| {
            let single: Vec<_> = rays
                .iter()
                .map(|r| bvh.intersect(r, f32::INFINITY))
                .collect();
            let mut stream = vec![None; rays.len()];
            bvh.intersect_stream(&rays, &t_max, &mut stream);
            let mut occluded = vec![false; rays.len()];
            bvh.occluded_stream(&rays, &t_max, &toward, &mut occluded);
            let bits = |h: &Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits()));
            (
                single.iter().map(bits).collect::<Vec<_>>(),
                stream.iter().map(bits).collect::<Vec<_>>(),
                occluded,
            )
        };
        let evex = answers(&bvh);
        bvh.avx2 = Some(avx2.without_avx512vl());
        let vex = answers(&bvh);
        assert!(evex.0.iter().filter(|h| h.is_some()).count() > 500);
        assert_eq!(evex, vex);
    }
}
