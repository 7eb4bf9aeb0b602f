//! The point kd-tree's queries never allocate (once their `PointQuery` and output vector
//! have grown to size), and a rebuild of no more items reuses the tree's memory. Counted by
//! a global allocator wrapper on this test's own thread; its own binary, one test, so no other
//! test's allocations are counted.

mod points_common;

use points_common::{items, queries, Kind};
use rt_accel::points::{CoverBound, PointKdTree, PointQuery};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; the counter is a
// const-initialised thread-local `Cell`, which needs no allocation and no destructor.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: the caller's contract for `alloc` is passed on unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: the caller's contract for `realloc` is passed on unchanged.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn queries_and_rebuilds_do_not_allocate() {
    let mut items = items(Kind::Clustered, 20_000, 3);
    let qs = queries(&items, 2000, 3);
    let mut tree = PointKdTree::build(&items).unwrap();
    let mut query = PointQuery::new(32);
    let mut found = Vec::with_capacity(items.len());
    let mut sum = 0u64;
    let mut run = |tree: &PointKdTree, query: &mut PointQuery| {
        for &q in &qs {
            for k in [1, 8, 32] {
                sum += tree.nearest_k(q, k, None, query).len() as u64;
                sum += tree.nearest_k(q, k, Some(0.01), query).len() as u64;
                sum += tree.nearest_k_bounded_first(q, k, 0.01, None, query).len() as u64;
            }
            tree.for_each_within(q, 0.05, query, |n| sum += u64::from(n.payload));
            tree.within(q, 0.05, query, &mut found);
            sum += found.len() as u64;
            for bound in [CoverBound::Subtree, CoverBound::Global] {
                sum += tree
                    .nearest_covering_with(q, bound, query)
                    .map_or(0, |n| n.payload) as u64;
            }
        }
    };
    let before = allocations();
    run(&tree, &mut query);
    // Rebuilding from as many items fits in the memory the tree already has.
    items.reverse();
    tree.rebuild(&mut items).unwrap();
    run(&tree, &mut query);
    let made = allocations() - before;
    assert!(sum > 0);
    assert_eq!(
        made,
        0,
        "{made} allocations in {} queries and a rebuild",
        2 * qs.len() * 14
    );
    // The counter counts: a query state made now allocates its heap.
    let q = PointQuery::new(4);
    assert_eq!(allocations() - before, 1);
    drop(q);
}
