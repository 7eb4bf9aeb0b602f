//! The shadow cache of Dammertz §5.3: occlusion queries toward a light start at the node where
//! the last occluder toward the same light region was found, and backtrack through parent
//! indices.
//!
//! Consecutive shadow rays toward one light sample region tend to be blocked by the same or
//! neighbouring triangles, so starting in the subtree that held the last occluder often finds
//! an occluder after a handful of boxes. If the subtree has none, the search moves to the
//! parent and searches its other children, and so on up to the root; the subtree plus the
//! siblings of every ancestor are the whole tree, so the answer is always the same as a query
//! from the root. When nothing was cached the entry is the root, so there is no special case.
//!
//! The table (4096 node indices keyed by a hash of the light-side endpoint, as in the thesis)
//! is per thread: it is written on every occluded query, and sharing it would mean contention.
//! It is tagged with the structure it belongs to, so a thread that queries several structures
//! never uses another's node index. The thesis hashes positions on a fixed 1/16-unit grid;
//! here the grid has 256 cells along the scene's largest extent, so it does not depend on the
//! scene's units.

use super::bvh::{Avx2, Baseline, Isa, WideNode};
use super::qbvh_node::{EMPTY, LEAF_BIT, NO_PARENT};
use super::traverse::{octant, Slab, STACK_SIZE};
use super::tri4::RayPrecomp4;
use super::WideBvh;
use crate::traversal::{Closest, Counter};
use glam::Vec3;
use rt_core::Ray;
use std::cell::RefCell;
use std::mem::MaybeUninit;
use std::sync::atomic::{AtomicU64, Ordering};

const HASH_SIZE: usize = 4096;
/// Grid cells along the scene's largest extent.
const CELLS: f32 = 256.0;

/// Source of [`WideBvh`] identities for tagging tables.
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

pub(crate) fn new_id() -> u64 {
    NEXT_ID.fetch_add(1, Ordering::Relaxed)
}

struct Table {
    owner: u64,
    entry: [u32; HASH_SIZE],
}

thread_local! {
    static TABLE: RefCell<Table> = const {
        RefCell::new(Table { owner: 0, entry: [0; HASH_SIZE] })
    };
}

impl<N: WideNode> WideBvh<N> {
    /// Table slot of the light-side endpoint `p`.
    fn shadow_hash(&self, p: Vec3) -> usize {
        let extent = self.bounds.max - self.bounds.min;
        let scale = CELLS / extent.max_element();
        let cell = ((p - self.bounds.min) * scale).to_array().map(|c| {
            // Saturating float-to-int casts: NaN becomes 0, anything outside the range clamps.
            c as i32 as u32
        });
        let h = cell[0].wrapping_mul(73_856_093)
            ^ cell[1].wrapping_mul(19_349_663)
            ^ cell[2].wrapping_mul(83_492_791);
        h as usize & (HASH_SIZE - 1)
    }

    /// Occlusion of `ray` over `(0, t_max]` through the calling thread's shadow cache, keyed by
    /// the light-side endpoint `target`.
    pub(crate) fn occluded_cached<C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        target: Vec3,
        counter: &mut C,
    ) -> bool {
        // As in the traversal: a ray with a NaN hits nothing (and must not descend forever).
        if !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            // SAFETY: `Avx2::detect` made `avx2`, so the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.occluded_cached_avx2(ray, t_max, target, avx2, counter) };
        }
        self.occluded_cached_on(ray, t_max, target, Baseline, counter)
    }

    /// [`WideBvh::occluded_cached_on`] compiled with AVX2 enabled.
    ///
    /// # Safety
    ///
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn occluded_cached_avx2<C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        target: Vec3,
        avx2: Avx2,
        counter: &mut C,
    ) -> bool {
        self.occluded_cached_on(ray, t_max, target, avx2, counter)
    }

    #[inline(always)]
    fn occluded_cached_on<I: Isa, C: Counter>(
        &self,
        ray: &Ray,
        t_max: f32,
        target: Vec3,
        isa: I,
        counter: &mut C,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let slab = Slab::new(ray);
        counter.boxes(1);
        if slab.hit_box(&self.bounds, t_max).is_none() {
            return false;
        }
        let pre = RayPrecomp4::new(ray);
        let oct = octant(ray);
        let h = self.shadow_hash(target);
        TABLE.with(|table| {
            let mut table = table.borrow_mut();
            if table.owner != self.id {
                table.owner = self.id;
                table.entry = [0; HASH_SIZE];
            }
            let mut entry = table.entry[h];
            let mut done = EMPTY;
            loop {
                let found = self.any_hit_below(entry, done, &slab, &pre, oct, t_max, isa, counter);
                if let Some(owner) = found {
                    table.entry[h] = owner;
                    return true;
                }
                let parent = self.nodes[entry as usize].parent_code();
                if parent == NO_PARENT {
                    return false;
                }
                done = entry;
                entry = parent;
            }
        })
    }

    /// Any-hit search of the subtree of node `entry`, leaving out its child `done` (a subtree
    /// already searched, or [`EMPTY`]). Returns the node whose child slot held the occluding
    /// leaf.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn any_hit_below<I: Isa, C: Counter>(
        &self,
        entry: u32,
        done: u32,
        slab: &Slab,
        pre: &RayPrecomp4,
        oct: usize,
        t_max: f32,
        isa: I,
        counter: &mut C,
    ) -> Option<u32> {
        // (child code, node holding it)
        // Uninitialised, like the main traversal's stack, because zeroing it costs more than a
        // short query.
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK_SIZE];
        let mut sp = 0;
        let mut closest = Closest::new(t_max);
        let mut expand = Some(entry);
        loop {
            if let Some(index) = expand.take() {
                let node = &self.nodes[index as usize];
                counter.boxes(node.occupied() as u64);
                let (mask, _) = node.hit(slab, t_max, isa);
                for rank in (0..N::WIDTH).rev() {
                    let slot = node.slot_at(oct, rank);
                    let code = node.code(slot);
                    if mask & (1 << slot) != 0 && code != done {
                        stack[sp].write((code, index));
                        sp += 1;
                    }
                }
            }
            if sp == 0 {
                return None;
            }
            sp -= 1;
            // SAFETY: every slot below the old `sp` was written just before `sp` passed it.
            #[allow(unsafe_code)]
            let (code, owner) = unsafe { stack[sp].assume_init() };
            if code & LEAF_BIT != 0 {
                if self.test_leaf::<true, I, C>(pre, code, t_max, &mut closest, isa, counter) {
                    return Some(owner);
                }
            } else {
                expand = Some(code);
            }
        }
    }
}
