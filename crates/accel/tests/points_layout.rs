//! The point kd-tree's layout, checked from outside through `PointKdTree::node`: the heap is
//! complete (items at exactly 1..=n), holds exactly the input items, every node's left
//! subtree lies at or below its split value and its right subtree at or above it, and each
//! node splits its subtree's widest axis. A property test over many random sets of every
//! size up to 70 and some larger ones (seeded, so failures reproduce).

mod points_common;

use glam::Vec3;
use points_common::{items, Kind, Rng, KINDS};
use rt_accel::points::{PointItem, PointKdTree};

/// The items of the subtree rooted at `h`, in heap order.
fn subtree(tree: &PointKdTree, h: usize, out: &mut Vec<PointItem>) {
    if let Some((item, _)) = tree.node(h) {
        out.push(item);
        subtree(tree, 2 * h, out);
        subtree(tree, 2 * h + 1, out);
    }
}

/// A sortable identity of an item, bit for bit.
fn ident(it: &PointItem) -> (u32, [u32; 3], u32) {
    (
        it.payload,
        it.point.to_array().map(f32::to_bits),
        it.radius.to_bits(),
    )
}

fn check_layout(items: &[PointItem], what: &str) {
    let tree = PointKdTree::build(items).unwrap();
    let n = items.len();
    assert_eq!(tree.len(), n, "{what}");
    assert!(
        tree.node(0).is_none() && tree.node(n + 1).is_none(),
        "{what}"
    );
    let mut stored: Vec<PointItem> = (1..=n)
        .map(|h| {
            tree.node(h)
                .unwrap_or_else(|| panic!("{what}: hole at {h}"))
                .0
        })
        .collect();
    let mut input = items.to_vec();
    stored.sort_by_key(ident);
    input.sort_by_key(ident);
    assert!(
        stored.iter().map(ident).eq(input.iter().map(ident)),
        "{what}: items differ"
    );
    let max_radius = items.iter().map(|it| it.radius).fold(0.0, f32::max);
    assert_eq!(tree.max_radius(), max_radius, "{what}");

    let (mut left, mut right, mut all) = (Vec::new(), Vec::new(), Vec::new());
    for h in 1..=n {
        let (item, axis) = tree.node(h).unwrap();
        assert!(axis < 3, "{what}: node {h} axis {axis}");
        let split = item.point[axis];
        left.clear();
        right.clear();
        subtree(&tree, 2 * h, &mut left);
        subtree(&tree, 2 * h + 1, &mut right);
        for it in &left {
            assert!(
                it.point[axis] <= split,
                "{what}: node {h} left {it:?} > {split}"
            );
        }
        for it in &right {
            assert!(
                it.point[axis] >= split,
                "{what}: node {h} right {it:?} < {split}"
            );
        }
        all.clear();
        subtree(&tree, h, &mut all);
        let (lo, hi) = all.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), it| (lo.min(it.point), hi.max(it.point)),
        );
        let extent = (hi - lo).to_array();
        let widest = (0..3).fold(0, |best, a| if extent[a] > extent[best] { a } else { best });
        assert_eq!(
            axis, widest,
            "{what}: node {h} splits {axis}, extents {extent:?}"
        );
    }
    tree.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
}

#[test]
fn layout_is_a_complete_kd_tree_for_every_small_size() {
    for kind in KINDS {
        for n in 0..=70 {
            for seed in 0..5 {
                check_layout(
                    &items(kind, n, seed),
                    &format!("{kind:?} n={n} seed={seed}"),
                );
            }
        }
    }
}

#[test]
fn layout_is_a_complete_kd_tree_for_random_larger_sizes() {
    let mut rng = Rng::new(99);
    for round in 0..40 {
        let n = 71 + rng.below(3000);
        let kind = KINDS[rng.below(KINDS.len())];
        check_layout(
            &items(kind, n, round),
            &format!("{kind:?} n={n} round={round}"),
        );
    }
    for n in [1023, 1024, 1025, 4095, 4096] {
        check_layout(&items(Kind::Uniform, n, 1), &format!("n={n}"));
    }
}

/// Rebuilding reuses the tree's memory and gives the tree a fresh build gives.
#[test]
fn rebuild_equals_build_and_keeps_memory() {
    let mut tree = PointKdTree::build(&items(Kind::Clustered, 5000, 1)).unwrap();
    let bytes = tree.memory_bytes();
    for (seed, n) in [(2, 5000), (3, 4000), (4, 0), (5, 5000)] {
        let mut work = items(Kind::Clustered, n, seed);
        let fresh = PointKdTree::build(&work).unwrap();
        tree.rebuild(&mut work).unwrap();
        assert_eq!(tree.len(), n);
        for h in 0..=n + 1 {
            assert_eq!(tree.node(h), fresh.node(h), "seed {seed} node {h}");
        }
        assert_eq!(tree.memory_bytes(), bytes);
    }
}
