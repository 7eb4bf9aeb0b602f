//! The 256-byte eight-wide node.

use super::bvh::{Isa, WideNode};
use super::qbvh_node::{empty_bounds, get_bounds, set_bounds, EMPTY};
use super::traverse::Slab;
use super::Order;
use rt_core::Aabb;

/// One node of a [`Bvh8`](super::Bvh8): the boxes of up to eight children in
/// structure-of-arrays layout, their child codes, the parent's index and the split-plane orders,
/// 256 bytes, aligned to a cache line so a node spans exactly four lines. The eight-wide
/// counterpart of [`QNode`](super::QNode), after the eight-wide BVHs of Embree and tinybvh:
/// on a CPU with AVX2 one 256-bit slab test covers all eight boxes.
///
/// | bytes    | field      | content                                                        |
/// |----------|------------|----------------------------------------------------------------|
/// | 0..192   | `bounds`   | `[min_x, min_y, min_z, max_x, max_y, max_z]`, each `[f32; 8]` over the eight slots |
/// | 192..224 | `children` | one `u32` child code per slot, encoded as in [`QNode`](super::QNode) |
/// | 224..248 | `orders`   | per direction octant, the slots in split-plane order (3 bits each, 3 bytes per octant) |
/// | 248..252 | `parent`   | index of the parent node, `u32::MAX` for the root               |
///
/// There is no room for split axes and traversal does not need them: the orders are
/// precomputed from the binary splits, as for the four-wide node.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Node8 {
    pub(crate) bounds: [[f32; 8]; 6],
    pub(crate) children: [u32; 8],
    pub(crate) orders: [[u8; 3]; 8],
    pub(crate) parent: u32,
}

const _: () = assert!(std::mem::size_of::<Node8>() == 256);
const _: () = assert!(std::mem::align_of::<Node8>() == 64);

impl Node8 {
    /// The raw child codes.
    #[inline]
    pub fn child_codes(&self) -> [u32; 8] {
        self.children
    }
}

impl WideNode for Node8 {
    const WIDTH: usize = 8;
    const NAME: &'static str = "bvh8";
    // Sorting the usually two or three hit slots of eight by distance costs less than ranking
    // all eight by a precomputed order, and visits fewer boxes.
    const DEFAULT_ORDER: Order = Order::Distance;
    // Greedy collapse leaves many nodes half empty above the leaves (4.3 of 8 slots on
    // the dragon); the plan fills 5.8 and was 14 % faster on primary and 18 % on uniform rays.
    const PLANNED_COLLAPSE: bool = true;
    // Skipping popped slots that begin beyond the closest hit saves a node fetch each: 6 %
    // faster on the dragon's primary rays, 9 % on diffuse bounces (uniform: unchanged).
    const DEFAULT_TSTACK: bool = true;
    const ORDER_BITS: u32 = 3;
    const IDENTITY_ORDER: u32 = 0o76543210;
    type Dists = [f32; 8];

    fn empty(parent: u32) -> Self {
        let identity = Self::IDENTITY_ORDER.to_le_bytes();
        Self {
            bounds: empty_bounds(),
            children: [EMPTY; 8],
            orders: [[identity[0], identity[1], identity[2]]; 8],
            parent,
        }
    }

    fn set(&mut self, slot: usize, b: Aabb, code: u32) {
        set_bounds(&mut self.bounds, slot, b);
        self.children[slot] = code;
    }

    fn set_orders(&mut self, orders: [u32; 8]) {
        self.orders = orders.map(|o| {
            let b = o.to_le_bytes();
            [b[0], b[1], b[2]]
        });
    }

    fn set_axes(&mut self, _axes: u32) {}

    #[inline(always)]
    fn code(&self, slot: usize) -> u32 {
        self.children[slot]
    }

    #[inline(always)]
    fn order(&self, octant: usize) -> u32 {
        let [a, b, c] = self.orders[octant];
        u32::from_le_bytes([a, b, c, 0])
    }

    #[inline(always)]
    fn parent_code(&self) -> u32 {
        self.parent
    }

    #[inline(always)]
    fn hit<I: Isa>(&self, slab: &Slab, t_max: f32, _isa: I) -> (u32, [f32; 8]) {
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 {
            // SAFETY: a value of an `Isa` whose `AVX2` is true is made only by
            // `Avx2::detect`, after run-time detection found AVX2.
            #[allow(unsafe_code)]
            return unsafe { slab.hit8_avx2(&self.bounds, t_max) };
        }
        slab.hit8(&self.bounds, t_max)
    }

    #[inline]
    fn child_aabb(&self, slot: usize) -> Aabb {
        get_bounds(&self.bounds, slot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wide::bvh::order_word;
    use crate::wide::qbvh_node::{leaf_code, QChild, NO_PARENT};
    use glam::Vec3;

    #[test]
    fn slots_round_trip() {
        let mut n = Node8::empty(NO_PARENT);
        assert_eq!(
            Node8::IDENTITY_ORDER,
            order_word(&[0, 1, 2, 3, 4, 5, 6, 7], 3)
        );
        let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        n.set(7, b, leaf_code(9, 3));
        n.set(0, b, 17);
        assert_eq!(n.child_aabb(7), b);
        assert_eq!(n.child(7), QChild::Leaf(36..39));
        assert_eq!(n.child(0), QChild::Inner(17));
        assert_eq!(n.child(3), QChild::Empty);
        assert!(n.child_aabb(3).is_empty());
        assert_eq!(n.occupied(), 2);
        assert_eq!(n.parent(), None);
        let order = order_word(&[7, 6, 5, 4, 3, 2, 1, 0], 3);
        n.set_orders([order; 8]);
        assert_eq!(n.slot_at(5, 0), 7);
        assert_eq!(n.slot_at(5, 7), 0);
    }
}
