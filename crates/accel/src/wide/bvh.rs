//! What building and traversal need from a node of a wide BVH, so that one collapse, one
//! traversal loop, one shadow cache and one validator serve the four-wide [`QNode`] and the
//! eight-wide [`Node8`](super::Node8).
//!
//! [`Isa`] selects the instruction set a traversal is compiled for. A value of [`Avx2`] exists
//! only after run-time detection found AVX2, so code holding one may call AVX2 kernels; the
//! eight-wide box test then tests all eight boxes in one 256-bit register.

use super::qbvh_node::{QChild, QNode};
use super::traverse::Slab;
use super::Order;
use rt_core::Aabb;
use std::fmt::Debug;
use std::ops::Index;

/// The instruction set a traversal is compiled for (see the module documentation).
pub trait Isa: Copy + sealed::Sealed {
    /// True if AVX2 kernels may run.
    const AVX2: bool;
}

/// Baseline: SSE2 on x86_64, scalar code elsewhere.
#[derive(Clone, Copy, Debug)]
pub struct Baseline;

/// Proof that the CPU has AVX2: made only by [`Avx2::detect`].
#[derive(Clone, Copy, Debug)]
pub struct Avx2 {
    avx512vl: bool,
}

impl Avx2 {
    /// `Some` if the CPU running this has AVX2.
    pub fn detect() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            return Some(Self {
                avx512vl: std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl"),
            });
        }
        None
    }

    /// True if the CPU also has AVX-512F and AVX-512VL. The traversal's AVX2 code, compiled
    /// with them enabled, is EVEX-encoded and gets 32 vector registers instead of 16: the
    /// ray's constants stay in registers across node visits instead of being reloaded
    /// (`docs/benchmarks.md`, "AVX-512VL registers"). The operations, and so the answers,
    /// are the same.
    pub fn avx512vl(self) -> bool {
        self.avx512vl
    }

    /// Whether a query of this kind runs in the AVX-512VL compilation: closest-hit queries
    /// where the CPU has it; any-hit queries never, as they measured 2–9 % slower there
    /// (`docs/benchmarks.md`, "AVX-512VL registers"). The one rule for single rays and streams.
    #[inline(always)]
    pub fn evex_for(self, any_hit: bool) -> bool {
        !any_hit && self.avx512vl
    }

    /// The same proof with AVX-512VL left unused (tests compare the two compilations).
    #[cfg(test)]
    pub(crate) fn without_avx512vl(self) -> Self {
        Self { avx512vl: false }
    }
}

impl Isa for Baseline {
    const AVX2: bool = false;
}

impl Isa for Avx2 {
    const AVX2: bool = true;
}

/// A node of a wide BVH: the boxes of up to [`WideNode::WIDTH`] children, their child codes
/// (empty, inner node or leaf, see [`QNode`]), the parent's index and, per direction octant,
/// the slots in split-plane order. Implemented by [`QNode`] and [`Node8`](super::Node8) only.
pub trait WideNode: Copy + Debug + PartialEq + Send + Sync + sealed::Sealed + 'static {
    /// Children per node.
    const WIDTH: usize;
    /// Name of the structure in reports and specs.
    const NAME: &'static str;
    /// The child order traversal uses unless told otherwise: the fastest measured
    /// (`docs/benchmarks.md`).
    const DEFAULT_ORDER: Order;
    /// Whether traversal keeps entry distances on the stack unless told otherwise
    /// ([`WideOptions::t_stack`](super::WideOptions::t_stack)).
    const DEFAULT_TSTACK: bool;
    /// Collapse with the SAH-optimal plan rather than greedily by area (see
    /// [`WideBvh::from_bvh2`](super::WideBvh::from_bvh2)).
    #[doc(hidden)]
    const PLANNED_COLLAPSE: bool;
    /// Bits per slot in an order word.
    #[doc(hidden)]
    const ORDER_BITS: u32;
    /// The order word that visits the slots in index order.
    #[doc(hidden)]
    const IDENTITY_ORDER: u32;
    /// Entry distances of all slots.
    #[doc(hidden)]
    type Dists: Copy + Index<usize, Output = f32>;

    /// A node with every slot empty.
    #[doc(hidden)]
    fn empty(parent: u32) -> Self;
    /// Fills slot `slot`.
    #[doc(hidden)]
    fn set(&mut self, slot: usize, b: Aabb, code: u32);
    /// Sets the order words, one per octant (only the low `WIDTH * ORDER_BITS` bits count).
    #[doc(hidden)]
    fn set_orders(&mut self, orders: [u32; 8]);
    /// Records the split axes where the node type has room for them.
    #[doc(hidden)]
    fn set_axes(&mut self, axes: u32);
    /// The child code in slot `slot`.
    #[doc(hidden)]
    fn code(&self, slot: usize) -> u32;
    /// The order word of `octant`: the nearest slot in the lowest `ORDER_BITS` bits, and so on.
    #[doc(hidden)]
    fn order(&self, octant: usize) -> u32;
    /// The parent's index, `u32::MAX` for the root.
    #[doc(hidden)]
    fn parent_code(&self) -> u32;
    /// Mask of the slots whose boxes the ray enters within `[0, t_max]`, and every slot's entry
    /// distance (meaningful where the mask is set).
    #[doc(hidden)]
    fn hit<I: Isa>(&self, slab: &Slab, t_max: f32, isa: I) -> (u32, Self::Dists);

    /// The box of slot `slot` (inverted for an empty slot).
    fn child_aabb(&self, slot: usize) -> Aabb;

    /// The decoded child in slot `slot`.
    fn child(&self, slot: usize) -> QChild {
        super::qbvh_node::decode(self.code(slot))
    }

    /// Number of non-empty slots.
    fn occupied(&self) -> usize {
        (0..Self::WIDTH)
            .filter(|&s| self.code(s) != super::qbvh_node::EMPTY)
            .count()
    }

    /// Index of the parent node, `None` for the root.
    fn parent(&self) -> Option<usize> {
        (self.parent_code() != super::qbvh_node::NO_PARENT).then_some(self.parent_code() as usize)
    }

    /// The slot of rank `rank` (0 = nearest) in split-plane order for a direction in `octant`
    /// (bit `a` set when the direction is negative along axis `a`).
    fn slot_at(&self, octant: usize, rank: usize) -> usize {
        slot_of(self.order(octant), Self::ORDER_BITS, rank)
    }
}

/// The slot of rank `rank` in an order word with `bits` bits per slot.
#[inline(always)]
pub(crate) fn slot_of(order: u32, bits: u32, rank: usize) -> usize {
    ((order >> (bits * rank as u32)) & ((1 << bits) - 1)) as usize
}

/// The order word listing `slots` (nearest first) with `bits` bits per slot.
pub(crate) fn order_word(slots: &[usize], bits: u32) -> u32 {
    slots
        .iter()
        .enumerate()
        .fold(0, |o, (rank, &s)| o | ((s as u32) << (bits * rank as u32)))
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Baseline {}
    impl Sealed for super::Avx2 {}
    impl Sealed for super::QNode {}
    impl Sealed for super::super::Node8 {}
}
