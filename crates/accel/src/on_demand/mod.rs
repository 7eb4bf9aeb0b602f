//! On-demand (lazy) QBVH construction (Dammertz §3.4): subtrees are built the first time a ray
//! reaches them, thread-safely.
//!
//! # Design: two levels
//!
//! [`OnDemandQbvh::new`] copies the triangles (they must outlive the caller's slice) and
//! builds only a shallow binary *top tree* whose leaves are *groups* of at most `G` triangles.
//! Each group records its bounds (in the leaf), its range of a permutation of the triangle
//! indices, and an empty [`OnceLock<Qbvh>`](OnceLock). The top tree is a binned surface area
//! heuristic tree (16 bins on the largest centroid axis), made cheaply in four passes:
//!
//! 1. the split planes are chosen on a strided sample of at most 2^16 triangles (all of them in
//!    smaller scenes), splitting until a set holds the sample's share of `G`; Dammertz §3.2
//!    likewise estimates the SAH from a fraction of the primitives at the high levels;
//! 2. every triangle is classified through those planes (in parallel);
//! 3. a counting sort orders the triangle indices by group;
//! 4. the groups the sample underestimated (more than `G` triangles) are split exactly (binned
//!    SAH on all their triangles, or halving by count where the centroids cannot be binned, as
//!    always below depth 32 so that the depth stays bounded), and the boxes are computed from
//!    the bottom up.
//!
//! A query walks the top tree front to back (nearest entry distance first, fixed-size stack,
//! the same robust slab test as the binary BVH, far distances widened by `FAR_SCALE`). At a
//! group it calls [`OnceLock::get_or_init`], which, the first time any thread gets there,
//! gathers the group's triangles into a temporary vector and builds the group's [`Qbvh`] over
//! them. It then queries that QBVH with the closest distance found so far as `t_max` and maps
//! its [`Hit::prim`] (an index into the gathered triangles) back to the caller's index.
//! Occlusion queries stop at the first group that reports a hit. Every group's QBVH answers
//! exactly as a QBVH over all triangles would for its triangles (same triangle test, same exact
//! `<` between candidates), so the closest hit is the same as
//! [`BruteForce`](crate::BruteForce)'s up to the ties and degenerate-triangle cases described
//! at the other structures.
//!
//! The [`WideOptions`] apply to every group. The per-thread shadow-cache table is tagged with
//! the QBVH it belongs to, so with many groups it stays correct but is reset whenever a thread
//! moves to another group, which takes most of its benefit away.
//!
//! # Deviation from the thesis
//!
//! The thesis marks an unbuilt subtree inside the QBVH itself: a negative child code with bit 30
//! set indexes a `[start, end)` record, and the traversal builds the subtree in place when it
//! meets one. Our [`Qbvh`] is immutable and shared through `&self` by all rendering threads;
//! patching child codes and appending nodes during traversal would need interior mutability of
//! the node array (locks or atomics on every node, or reallocation under readers), so we keep
//! the QBVH untouched and put the laziness one level up, in a separate top tree whose leaves are
//! whole QBVHs. The consequences: the top levels of the hierarchy are binary and scalar rather
//! than four-wide; the top splits come from a coarse, sampled 16-bin SAH instead of the full
//! binned build (so the tree differs from the eager one); and the granularity of laziness is a
//! group of up to `G` triangles rather than any subtree.
//!
//! # Group size
//!
//! `G = max(2048, ceil(n / 512))` ([`default_group_size`]). Large scenes get 512 to about 1000
//! groups (sets are split until they fit, so groups average about two thirds of `G`: 766 groups
//! for 1.3M triangles), so the top tree stays about ten levels deep and costs a couple of dozen
//! scalar box tests per ray even when everything is built, and it is small enough to build in a
//! few passes. `G` is at least 2048 so that a group build, a few milliseconds, is large against
//! its fixed costs (allocations, the collapse, the lock) and building every group costs about
//! as much as the eager build. And `G` is small enough that a view of part of a big scene
//! builds only the groups it sees. [`OnDemandQbvh::with_group_size`] takes any other size.
//!
//! # Threads
//!
//! [`OnceLock::get_or_init`] runs the build once; other threads reaching the same group block
//! (idle, for the few milliseconds of the build) until it is done, and then everyone shares the
//! result. Group builds always run with [`BuildParams::parallel`] off, whatever the caller
//! passed: a parallel build calls `rayon::join` while holding the `OnceLock`, and a rayon worker
//! waiting in `join` may steal another job, such as a ray query that reaches the same group and
//! then waits for the lock its own thread holds, a deadlock. Different groups still build in
//! parallel, one per thread. The top tree itself is built in parallel when `parallel` is on (no
//! lock is held then). The binary builder's tree does not depend on `parallel`, so neither do
//! the answers.
//!
//! # Memory
//!
//! [`Accel::memory_bytes`] counts the top tree, the group records, the triangle copy and index
//! permutation kept for building groups later (40 bytes a triangle), and the QBVHs of the groups
//! built so far. Once every group is built the triangle copy is redundant with the QBVHs' own
//! copies, but it cannot be freed through `&self`.

use crate::traversal::{inside, walk_binary, BinaryNode, Step};
use crate::wide::{WideOptions, MAX_TRIANGLES};
use crate::{BuildParams, Qbvh};
use glam::Vec3;
use rayon::prelude::*;
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// Smallest group of the default group size ([`default_group_size`]).
pub const MIN_GROUP_SIZE: usize = 2048;

/// Number of groups the default group size aims at for large scenes.
pub const TARGET_GROUPS: usize = 512;

/// Depth below which the top tree splits by SAH; deeper sets are halved by count, so the top
/// tree is at most `SAH_DEPTH + 32` levels deep for up to 2^32 triangles.
const SAH_DEPTH: usize = 32;

/// Traversal stack size (see [`SAH_DEPTH`]).
const MAX_DEPTH: usize = SAH_DEPTH + 33;

/// The default group size for `n` triangles: `max(2048, ceil(n / 512))` (see the
/// [module documentation](self)).
pub fn default_group_size(n: usize) -> usize {
    MIN_GROUP_SIZE.max(n.div_ceil(TARGET_GROUPS))
}

mod build;

/// A top-tree node: bounds packed as `[min.x, min.y, min.z, max.x, max.y, max.z]`; an inner node
/// (`count == 0`) has its children at `index` and `index + 1`, a leaf has group `index` of
/// `count` triangles.
#[derive(Clone, Copy, Debug)]
struct TopNode {
    bounds: [f32; 6],
    index: u32,
    count: u32,
}

impl TopNode {
    const PLACEHOLDER: TopNode = TopNode {
        bounds: [0.0; 6],
        index: 0,
        count: 0,
    };

    fn new(b: &Aabb, index: u32, count: u32) -> Self {
        Self {
            bounds: [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z],
            index,
            count,
        }
    }

    fn aabb(&self) -> Aabb {
        let b = &self.bounds;
        Aabb::new(Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]))
    }

    fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// The triangles `order[first..first + count]` and their QBVH, once built.
#[derive(Debug)]
struct Group {
    first: u32,
    count: u32,
    tree: OnceLock<Qbvh>,
}

impl Group {
    fn range(&self) -> std::ops::Range<usize> {
        self.first as usize..(self.first + self.count) as usize
    }
}

/// A QBVH whose subtrees are built the first time a ray reaches them: a binary top tree over
/// groups of triangles, each group's [`Qbvh`] built on first use. See the
/// [module documentation](self) for the design and how it departs from the thesis.
#[derive(Debug)]
pub struct OnDemandQbvh {
    nodes: Vec<TopNode>,
    groups: Vec<Group>,
    /// The caller's triangles, in the caller's order.
    triangles: Vec<[Vec3; 3]>,
    /// Caller indices of the triangles, group by group.
    order: Vec<u32>,
    bounds: Aabb,
    /// The caller's parameters with `parallel` off.
    params: BuildParams,
    options: WideOptions,
    group_size: usize,
    builds: AtomicUsize,
}

impl OnDemandQbvh {
    /// Prepares the structure over `triangles` with the default group size
    /// ([`default_group_size`]); nothing is built below the top tree yet. Groups are built with
    /// `params` (but never in parallel) and traversed with `options`.
    ///
    /// # Panics
    ///
    /// If there are more than `u32::MAX` triangles.
    pub fn new(triangles: &[[Vec3; 3]], params: &BuildParams, options: &WideOptions) -> Self {
        Self::with_group_size(
            triangles,
            params,
            options,
            default_group_size(triangles.len()),
        )
    }

    /// Like [`OnDemandQbvh::new`] with groups of at most `group_size` triangles (clamped to
    /// `1..2^27`).
    ///
    /// # Panics
    ///
    /// If there are more than `u32::MAX` triangles.
    pub fn with_group_size(
        triangles: &[[Vec3; 3]],
        params: &BuildParams,
        options: &WideOptions,
        group_size: usize,
    ) -> Self {
        assert!(
            triangles.len() <= u32::MAX as usize,
            "OnDemandQbvh supports at most 2^32 - 1 triangles, got {}",
            triangles.len()
        );
        let group_size = group_size.clamp(1, MAX_TRIANGLES - 1);
        let (mut nodes, order) = build::build_top(triangles, group_size, params.parallel);
        // Leaves hold their first slot of `order` until here; give them group ids.
        let mut groups = Vec::new();
        for node in nodes.iter_mut().filter(|n| n.is_leaf()) {
            groups.push(Group {
                first: node.index,
                count: node.count,
                tree: OnceLock::new(),
            });
            node.index = groups.len() as u32 - 1;
        }
        let bounds = nodes.first().map_or(Aabb::EMPTY, TopNode::aabb);
        Self {
            nodes,
            groups,
            triangles: copy(triangles, params.parallel),
            order,
            bounds,
            params: BuildParams {
                parallel: false,
                ..*params
            },
            options: *options,
            group_size,
            builds: AtomicUsize::new(0),
        }
    }

    /// Number of groups (leaves of the top tree), built or not.
    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// Number of groups whose QBVH has been built.
    pub fn built_groups(&self) -> usize {
        self.groups
            .iter()
            .filter(|g| g.tree.get().is_some())
            .count()
    }

    /// Number of group builds run so far. Equals [`OnDemandQbvh::built_groups`] unless a build
    /// panicked (a group whose build panics stays unbuilt and is tried again by the next ray);
    /// more would mean a group was built twice.
    pub fn build_count(&self) -> usize {
        self.builds.load(Ordering::Relaxed)
    }

    /// Largest number of triangles in a group.
    pub fn group_size(&self) -> usize {
        self.group_size
    }

    /// Builds every group not built yet, in parallel on the rayon pool (e.g. to turn a preview
    /// structure into a complete one).
    pub fn build_all(&self) {
        self.groups.par_iter().for_each(|g| {
            self.tree(g);
        });
    }

    /// The triangles, in the caller's order (a copy, kept for building groups).
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The caller's indices of the triangles, group by group (each group's indices are
    /// contiguous and ascending).
    pub fn group_order(&self) -> &[u32] {
        &self.order
    }

    /// Checks that the top tree's boxes nest and bound their groups' triangles, that the groups
    /// are non-empty, no larger than the group size and cover every triangle exactly once, that
    /// [`OnDemandQbvh::group_order`] is a permutation, that the depth fits the traversal stack, and
    /// that the QBVHs built so far lie in their leaves' boxes. Returns the first violation found.
    pub fn validate(&self) -> Result<(), crate::ValidationError> {
        self.find_problem()
            .map_err(|problem| crate::ValidationError {
                structure: rt_core::Accel::name(self).to_string(),
                problem,
            })
    }

    fn find_problem(&self) -> Result<(), String> {
        let n = self.triangles.len();
        if self.order.len() != n {
            return Err(format!("{} indices for {n} triangles", self.order.len()));
        }
        let mut seen = vec![false; n];
        for &id in &self.order {
            match seen.get_mut(id as usize) {
                Some(s @ false) => *s = true,
                Some(true) => return Err(format!("triangle {id} appears twice")),
                None => return Err(format!("triangle {id} out of range")),
            }
        }
        if self.nodes.is_empty() {
            return if n == 0 && self.groups.is_empty() {
                Ok(())
            } else {
                Err(format!("no top tree for {n} triangles"))
            };
        }
        if self.nodes[0].aabb() != self.bounds {
            return Err("root box is not the bounds".into());
        }
        let mut reached = vec![false; self.nodes.len()];
        let mut group_reached = vec![false; self.groups.len()];
        let mut covered = vec![false; n];
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            if std::mem::replace(&mut reached[i], true) {
                return Err(format!("node {i} reached twice"));
            }
            if depth >= MAX_DEPTH {
                return Err(format!("node {i} at depth {depth} overflows the stack"));
            }
            let node = &self.nodes[i];
            let outer = node.aabb();
            if !node.is_leaf() {
                let first = node.index as usize;
                if first <= i || first + 1 >= self.nodes.len() {
                    return Err(format!("node {i} has children {first} out of order"));
                }
                for c in [first, first + 1] {
                    if !inside(&self.nodes[c].aabb(), &outer) {
                        return Err(format!("node {c} sticks out of its parent {i}"));
                    }
                    stack.push((c, depth + 1));
                }
                continue;
            }
            let g = node.index as usize;
            let Some(group) = self.groups.get(g) else {
                return Err(format!("leaf {i} has group {g} of {}", self.groups.len()));
            };
            if std::mem::replace(&mut group_reached[g], true) {
                return Err(format!("group {g} reached twice"));
            }
            if group.count != node.count || group.count == 0 {
                return Err(format!("group {g} has {} triangles", group.count));
            }
            if group.count as usize > self.group_size {
                return Err(format!("group {g} has more than {}", self.group_size));
            }
            let Some(ids) = self.order.get(group.range()) else {
                return Err(format!("group {g} range out of bounds"));
            };
            for (k, c) in covered[group.range()].iter_mut().enumerate() {
                if std::mem::replace(c, true) {
                    return Err(format!(
                        "triangle slot {} in two groups",
                        group.first as usize + k
                    ));
                }
            }
            for &id in ids {
                if !inside(&Aabb::from_points(&self.triangles[id as usize]), &outer) {
                    return Err(format!("a triangle of group {g} sticks out of leaf {i}"));
                }
            }
            // The QBVH's own structure is its own tests' business; only what we rely on here.
            if let Some(tree) = group.tree.get() {
                if !tree.bounds().is_empty() && !inside(&tree.bounds(), &outer) {
                    return Err(format!("group {g}'s QBVH sticks out of leaf {i}"));
                }
            }
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return Err(format!("node {i} unreachable"));
        }
        if let Some(g) = group_reached.iter().position(|r| !r) {
            return Err(format!("group {g} unreachable"));
        }
        if let Some(k) = covered.iter().position(|c| !c) {
            return Err(format!("triangle slot {k} in no group"));
        }
        Ok(())
    }

    /// The group's QBVH, built now if no thread has built it yet.
    #[inline]
    fn tree<'a>(&'a self, group: &'a Group) -> &'a Qbvh {
        group.tree.get_or_init(|| {
            self.builds.fetch_add(1, Ordering::Relaxed);
            // Gathered for the build only: the QBVH keeps its own copy.
            let tris: Vec<[Vec3; 3]> = self.order[group.range()]
                .iter()
                .map(|&i| self.triangles[i as usize])
                .collect();
            Qbvh::build_with(&tris, &self.params, &self.options)
        })
    }

    /// Walks the top tree front to back and calls `visit` on each group the ray reaches within
    /// the current culling distance, building it first if needed; `visit` gets the group, its
    /// QBVH and that distance. Counts top-tree boxes tested into `boxes`.
    #[inline(always)]
    fn walk(
        &self,
        ray: &Ray,
        t_max: f32,
        boxes: &mut u64,
        mut visit: impl FnMut(&Group, &Qbvh, f32) -> Step,
    ) {
        let mut top = TraversalCounters::default();
        walk_binary::<_, _, MAX_DEPTH>(&self.nodes, ray, t_max, &mut top, |node, cull_t, _| {
            let group = &self.groups[node.index as usize];
            visit(group, self.tree(group), cull_t)
        });
        *boxes += top.nodes_visited;
    }

    /// Closest hit; `counters`, if given, also gets the groups' work.
    #[inline(always)]
    fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        boxes: &mut u64,
        mut counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        self.walk(ray, t_max, boxes, |group, tree, cull_t| {
            let hit = match counters.as_deref_mut() {
                Some(c) => tree.closest_hit(ray, cull_t, Some(c)),
                None => tree.intersect(ray, cull_t),
            };
            match hit {
                // `<`, as within a QBVH: of equal distances the first found stays.
                Some(h) if best.is_none_or(|b| h.t < b.t) => {
                    best = Some(Hit {
                        prim: self.order[group.first as usize + h.prim as usize],
                        ..h
                    });
                    Step::Closer(h.t)
                }
                _ => Step::Miss,
            }
        });
        best
    }
}

/// `triangles.to_vec()`, in parallel for large scenes if asked to: the page faults of a fresh
/// allocation can cost more than the copy itself.
fn copy(triangles: &[[Vec3; 3]], parallel: bool) -> Vec<[Vec3; 3]> {
    if parallel && triangles.len() >= 1 << 15 {
        let mut v = Vec::new();
        triangles.par_iter().copied().collect_into_vec(&mut v);
        v
    } else {
        triangles.to_vec()
    }
}

impl BinaryNode for TopNode {
    #[inline(always)]
    fn planes(&self) -> &[f32; 6] {
        &self.bounds
    }
    #[inline(always)]
    fn first_child(&self) -> Option<usize> {
        (self.count == 0).then_some(self.index as usize)
    }
}

impl Accel for OnDemandQbvh {
    fn name(&self) -> &str {
        "qbvh-lazy"
    }

    fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: Option<&mut TraversalCounters>,
    ) -> Option<Hit> {
        let Some(counters) = counters else {
            return self.closest(ray, t_max, &mut 0, None);
        };
        let mut work = TraversalCounters::default();
        let mut boxes = 0;
        let hit = self.closest(ray, t_max, &mut boxes, Some(&mut work));
        work.nodes_visited += boxes;
        *counters += work;
        hit
    }

    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        mut counters: Option<&mut TraversalCounters>,
    ) -> bool {
        let mut hit = false;
        let mut boxes = 0;
        self.walk(ray, t_max, &mut boxes, |_, tree, _| {
            if tree.any_hit(ray, t_max, toward, counters.as_deref_mut()) {
                hit = true;
                Step::Done
            } else {
                Step::Miss
            }
        });
        if let Some(c) = counters {
            c.nodes_visited += boxes;
        }
        hit
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.groups.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.order.as_slice())
            + self
                .groups
                .iter()
                .filter_map(|g| g.tree.get())
                .map(Qbvh::memory_bytes)
                .sum::<usize>()
    }

    /// Everything but the caller-order triangles (the groups' trees keep packed copies).
    fn structure_bytes(&self) -> Option<usize> {
        Some(self.memory_bytes() - std::mem::size_of_val(self.triangles.as_slice()))
    }

    fn counts_traversal(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_group_size_is_bounded_below_and_grows() {
        assert_eq!(default_group_size(0), MIN_GROUP_SIZE);
        assert_eq!(default_group_size(10_000), MIN_GROUP_SIZE);
        // Above the minimum, groups of ⌈n / TARGET_GROUPS⌉ triangles.
        assert_eq!(
            default_group_size(2_000_000),
            2_000_000usize.div_ceil(TARGET_GROUPS)
        );
        assert!(2_000_000usize.div_ceil(TARGET_GROUPS) > MIN_GROUP_SIZE);
    }
}
