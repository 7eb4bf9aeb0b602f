//! The 32-byte BVH node.

use glam::Vec3;
use rt_core::Aabb;
use std::ops::Range;

/// One node of a [`Bvh2`](super::Bvh2): 24 bytes of bounds plus two `u32`s, so two nodes fill
/// half a 64-byte cache line. The two children of an inner node are stored next to each other,
/// which lets ordered traversal test both boxes from memory it has already fetched.
///
/// The bounds are kept as `[min.x, min.y, min.z, max.x, max.y, max.z]` so the traversal can pick
/// the near and far plane of an axis by index (`axis + 3 * sign`) instead of branching.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Node {
    pub(crate) bounds: [f32; 6],
    /// Inner node: index of the first child (the second is at `index + 1`). Leaf: index of the
    /// first triangle in leaf order.
    pub(crate) index: u32,
    /// Number of triangles in a leaf; zero marks an inner node. Leaves are never empty, because
    /// the build only makes a leaf from a non-empty range.
    pub(crate) count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

impl Node {
    pub(crate) fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        debug_assert!(count > 0);
        Self {
            bounds: pack(bounds),
            index: first,
            count,
        }
    }

    pub(crate) fn inner(bounds: Aabb, first_child: u32) -> Self {
        Self {
            bounds: pack(bounds),
            index: first_child,
            count: 0,
        }
    }

    /// The node's bounding box.
    #[inline]
    pub fn aabb(&self) -> Aabb {
        let b = &self.bounds;
        Aabb::new(Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]))
    }

    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count != 0
    }

    /// For an inner node, the indices of its two children in [`Bvh2::nodes`](super::Bvh2::nodes).
    #[inline]
    pub fn children(&self) -> Option<[usize; 2]> {
        (!self.is_leaf()).then(|| [self.index as usize, self.index as usize + 1])
    }

    /// For a leaf, its range in [`Bvh2::triangles`](super::Bvh2::triangles) and
    /// [`Bvh2::prim_ids`](super::Bvh2::prim_ids).
    #[inline]
    pub fn prims(&self) -> Option<Range<usize>> {
        self.is_leaf()
            .then(|| self.index as usize..self.index as usize + self.count as usize)
    }
}

fn pack(b: Aabb) -> [f32; 6] {
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accessors_round_trip() {
        let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        let leaf = Node::leaf(b, 7, 3);
        assert_eq!(leaf.aabb(), b);
        assert_eq!(leaf.prims(), Some(7..10));
        assert_eq!(leaf.children(), None);
        let inner = Node::inner(b, 5);
        assert_eq!(inner.children(), Some([5, 6]));
        assert_eq!(inner.prims(), None);
    }
}
