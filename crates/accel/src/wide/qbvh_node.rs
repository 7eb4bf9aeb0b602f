//! The 128-byte QBVH node and its child encoding.

use super::bvh::{Isa, WideNode};
use super::traverse::Slab;
use super::Order;
use glam::Vec3;
use rt_core::Aabb;
use std::ops::Range;

/// Child code of an empty slot. Node 0 is the root, which is nobody's child, so the value is free.
pub const EMPTY: u32 = 0;
/// Bit 31 of a child code: set for a leaf.
pub const LEAF_BIT: u32 = 1 << 31;
/// Leaf codes keep `count - 1` in bits 27..=30 ...
const COUNT_SHIFT: u32 = 27;
/// ... and the first triangle's slot in bits 0..=26.
const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Most triangles one leaf code can hold.
pub const MAX_LEAF_TRIANGLES: usize = 16;
/// Packets a [`Qbvh`](super::Qbvh) can address: 27 bits of first packet.
pub const MAX_TRIANGLES: usize = 1 << COUNT_SHIFT;
/// Value of an unset split axis in [`QNode::axes`].
pub const NO_AXIS: u32 = 3;
/// `axes` word with no axis recorded.
pub(crate) const NO_AXES: u32 = NO_AXIS | (NO_AXIS << 2) | (NO_AXIS << 4);
/// `parent` of the root.
pub const NO_PARENT: u32 = u32::MAX;

/// One node of a [`Qbvh`](super::Qbvh): the boxes of up to four children in structure-of-arrays
/// layout plus their child codes, 128 bytes, aligned to a 64-byte cache line so a node spans
/// exactly two lines (Dammertz et al., "Shallow Bounding Volume Hierarchies for Fast SIMD Ray
/// Tracing of Incoherent Rays", 2008).
///
/// Layout (byte offsets):
///
/// | bytes    | field      | content                                                        |
/// |----------|------------|----------------------------------------------------------------|
/// | 0..96    | `bounds`   | `[min_x, min_y, min_z, max_x, max_y, max_z]`, each `[f32; 4]` over the four slots |
/// | 96..112  | `children` | one `u32` child code per slot                                   |
/// | 112..116 | `axes`     | bits 0-1 `axis0`, 2-3 `axis1`, 4-5 `axis2`; 3 = not recorded     |
/// | 116..120 | `parent`   | index of the parent node, `u32::MAX` for the root               |
/// | 120..128 | `orders`   | per direction octant, the slots in split-plane order (2 bits each) |
///
/// A plane is picked as `bounds[axis + 3 * max_side]`, so traversal chooses near and far planes
/// per ray without branching. Child codes:
///
/// - [`EMPTY`] (0): no child; the slot's box is inverted (`min = +inf`, `max = -inf`).
/// - bit 31 clear, nonzero: index of an inner node (always greater than the parent's index).
/// - bit 31 set ([`LEAF_BIT`]): a leaf of `((code >> 27) & 15) + 1` triangles (1 to 16) packed
///   four to a [`Tri4`](super::Tri4) from packet `code & (2^27 - 1)` on.
///
/// Split axes: `axis0` is the axis of the binary split the node was collapsed from (it separates
/// the slots that came from the binary left child from those of the right). When both binary
/// children were expanded, so the slots are `[LL, LR, RL, RR]`, `axis1` separates slots 0 and 1
/// and `axis2` slots 2 and 3, as in Dammertz's layout; otherwise they are 3. The binary BVH does
/// not store its split axes, so each is inferred as the axis along which the two child boxes'
/// centres lie farthest apart.
///
/// Split-plane ordered traversal (Dammertz §3.3.3) visits the slots as the binary splits they
/// came from would: at every split, the side the ray direction points away from first. A node
/// collapsed by largest-area expansion need not have the `[LL, LR, RL, RR]` shape the three
/// axes describe, so the order is precomputed for each of the eight direction octants (octant
/// bit `a` set when the direction is negative along axis `a`) into the spare bytes:
/// `orders[octant]` holds the nearest slot in bits 0-1, the next in 2-3, and so on.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct QNode {
    pub(crate) bounds: [[f32; 4]; 6],
    pub(crate) children: [u32; 4],
    pub(crate) axes: u32,
    pub(crate) parent: u32,
    pub(crate) orders: [u8; 8],
}

/// `orders` byte of slot order 0, 1, 2, 3.
pub(crate) const IDENTITY_ORDER: u8 = 0b11_10_01_00;

const _: () = assert!(std::mem::size_of::<QNode>() == 128);
const _: () = assert!(std::mem::align_of::<QNode>() == 64);

/// A decoded child slot of a [`QNode`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum QChild {
    /// No child in this slot.
    Empty,
    /// An inner node, by index into [`Qbvh::nodes`](super::Qbvh::nodes).
    Inner(usize),
    /// A leaf: its lane slots (`4 * packet + lane`, see [`Qbvh::reference`](super::Qbvh::reference)).
    Leaf(Range<usize>),
}

/// The child code of a leaf of `count` (1 to 16) triangles packed from packet `first`.
#[inline]
pub(crate) fn leaf_code(first: usize, count: usize) -> u32 {
    debug_assert!((1..=MAX_LEAF_TRIANGLES).contains(&count));
    debug_assert!(first < MAX_TRIANGLES);
    LEAF_BIT | (((count - 1) as u32) << COUNT_SHIFT) | first as u32
}

/// Decodes a leaf code (bit 31 set) into its first packet and its triangle count.
#[inline(always)]
pub(crate) fn leaf_parts(code: u32) -> (usize, usize) {
    let first = (code & FIRST_MASK) as usize;
    let count = ((code >> COUNT_SHIFT) & 15) as usize + 1;
    (first, count)
}

/// A leaf's triangles as lane slots (`4 * packet + lane`).
#[inline]
pub(crate) fn leaf_range(code: u32) -> Range<usize> {
    let (first, count) = leaf_parts(code);
    4 * first..4 * first + count
}

/// Decodes a child code (see [`QNode`]).
#[inline]
pub(crate) fn decode(code: u32) -> QChild {
    match code {
        EMPTY => QChild::Empty,
        c if c & LEAF_BIT != 0 => QChild::Leaf(leaf_range(c)),
        c => QChild::Inner(c as usize),
    }
}

/// Writes box `b` into lane `slot` of structure-of-arrays `bounds`.
#[inline]
pub(crate) fn set_bounds<const W: usize>(bounds: &mut [[f32; W]; 6], slot: usize, b: Aabb) {
    let v = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
    for (plane, value) in bounds.iter_mut().zip(v) {
        plane[slot] = value;
    }
}

/// Reads lane `slot` of structure-of-arrays `bounds`.
#[inline]
pub(crate) fn get_bounds<const W: usize>(bounds: &[[f32; W]; 6], slot: usize) -> Aabb {
    let b = bounds;
    Aabb::new(
        Vec3::new(b[0][slot], b[1][slot], b[2][slot]),
        Vec3::new(b[3][slot], b[4][slot], b[5][slot]),
    )
}

/// Boxes of `W` empty slots: inverted, so no ray enters them.
pub(crate) fn empty_bounds<const W: usize>() -> [[f32; W]; 6] {
    let (lo, hi) = ([f32::INFINITY; W], [f32::NEG_INFINITY; W]);
    [lo, lo, lo, hi, hi, hi]
}

impl QNode {
    /// The raw child codes (see the type's documentation).
    #[inline]
    pub fn child_codes(&self) -> [u32; 4] {
        self.children
    }

    /// `[axis0, axis1, axis2]`, each 0, 1, 2 or [`NO_AXIS`].
    #[inline]
    pub fn axes(&self) -> [u32; 3] {
        [self.axes & 3, (self.axes >> 2) & 3, (self.axes >> 4) & 3]
    }

    /// The slots in split-plane order, nearest first, for a direction in `octant` (bit `a` set
    /// when the direction is negative along axis `a`).
    #[inline]
    pub fn slot_order(&self, octant: usize) -> [usize; 4] {
        std::array::from_fn(|rank| self.slot_at(octant, rank))
    }
}

impl WideNode for QNode {
    const WIDTH: usize = 4;
    const NAME: &'static str = "qbvh";
    const DEFAULT_ORDER: Order = Order::SplitPlane;
    // The QBVH stays Dammertz's (its benchmarks and the on-demand build compare with it).
    const PLANNED_COLLAPSE: bool = false;
    const DEFAULT_TSTACK: bool = false;
    const ORDER_BITS: u32 = 2;
    const IDENTITY_ORDER: u32 = IDENTITY_ORDER as u32;
    type Dists = [f32; 4];

    fn empty(parent: u32) -> Self {
        Self {
            bounds: empty_bounds(),
            children: [EMPTY; 4],
            axes: NO_AXES,
            parent,
            orders: [IDENTITY_ORDER; 8],
        }
    }

    fn set(&mut self, slot: usize, b: Aabb, code: u32) {
        set_bounds(&mut self.bounds, slot, b);
        self.children[slot] = code;
    }

    fn set_orders(&mut self, orders: [u32; 8]) {
        self.orders = orders.map(|o| o as u8);
    }

    fn set_axes(&mut self, axes: u32) {
        self.axes = axes;
    }

    #[inline(always)]
    fn code(&self, slot: usize) -> u32 {
        self.children[slot]
    }

    #[inline(always)]
    fn order(&self, octant: usize) -> u32 {
        u32::from(self.orders[octant])
    }

    #[inline(always)]
    fn parent_code(&self) -> u32 {
        self.parent
    }

    #[inline(always)]
    fn hit<I: Isa>(&self, slab: &Slab, t_max: f32, _isa: I) -> (u32, [f32; 4]) {
        slab.hit4(&self.bounds, t_max)
    }

    #[inline]
    fn child_aabb(&self, slot: usize) -> Aabb {
        get_bounds(&self.bounds, slot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip() {
        for (first, count) in [(0, 1), (5, 16), (MAX_TRIANGLES - 16, 16), (123_456, 7)] {
            let c = leaf_code(first, count);
            assert_ne!(c, EMPTY);
            assert_eq!(leaf_parts(c), (first, count));
            assert_eq!(leaf_range(c), 4 * first..4 * first + count);
        }
        let mut n = QNode::empty(NO_PARENT);
        n.set_axes(1 | (2 << 2) | (NO_AXIS << 4));
        let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        n.set(2, b, leaf_code(9, 3));
        n.set(0, b, 17);
        assert_eq!(n.child_aabb(2), b);
        assert_eq!(n.child(2), QChild::Leaf(36..39));
        assert_eq!(n.child(0), QChild::Inner(17));
        assert_eq!(n.child(1), QChild::Empty);
        assert!(n.child_aabb(1).is_empty());
        assert_eq!(n.occupied(), 2);
        assert_eq!(n.axes(), [1, 2, NO_AXIS]);
        assert_eq!(n.parent(), None);
    }
}
