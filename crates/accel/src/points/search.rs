//! The searches: one depth-first traversal, three visitors (k nearest, within a radius,
//! nearest covering item).

use super::build::PointKdTree;
use super::{distance_squared, radius_bound, Neighbour, MAX_DEPTH};
use glam::Vec3;

/// Work done by the queries run with one [`PointQuery`], summed until
/// [`PointQuery::reset_stats`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryStats {
    /// Queries answered.
    pub queries: u64,
    /// Items whose distance to the query was computed.
    pub nodes_visited: u64,
    /// Bounded-first k-NN queries that found fewer than `k` items within the initial radius
    /// and searched again.
    pub restarts: u64,
}

/// Reusable per-thread state of the queries: the k-NN max-heap and the work counters.
///
/// Queries never allocate once the heap has room for their `k` (or for every item, when the
/// tree holds fewer than `k`): create it with [`PointQuery::new`] for the largest `k` you ask.
#[derive(Clone, Debug, Default)]
pub struct PointQuery {
    /// A max-heap on [`Neighbour`]'s order while a k-NN search runs, sorted ascending after.
    heap: Vec<Neighbour>,
    stats: QueryStats,
}

impl PointQuery {
    /// State for k-NN queries of up to `k` neighbours.
    pub fn new(k: usize) -> Self {
        Self {
            heap: Vec::with_capacity(k),
            stats: QueryStats::default(),
        }
    }

    /// The work done since creation or the last reset.
    pub fn stats(&self) -> QueryStats {
        self.stats
    }

    /// Zeroes the work counters.
    pub fn reset_stats(&mut self) {
        self.stats = QueryStats::default();
    }
}

/// How [`PointKdTree::nearest_covering_with`] bounds its search.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CoverBound {
    /// Skip a subtree when the query is farther from its cell than the largest radius in it.
    #[default]
    Subtree,
    /// Search up to the largest radius of all items (the thesis' "search bound = maximum bin
    /// radius"); for comparison.
    Global,
}

/// What a search does at each item and how far it still needs to look.
trait Visitor {
    /// Squared distance beyond which no item can change the result.
    fn bound(&self) -> f32;
    /// [`Visitor::bound`] for the subtree rooted at heap number `h`.
    fn subtree_bound(&self, _tree: &PointKdTree, _h: usize) -> f32 {
        self.bound()
    }
    /// Considers heap item `h` at squared distance `dist2`.
    fn visit(&mut self, tree: &PointKdTree, h: usize, dist2: f32);
}

impl PointKdTree {
    /// Runs `v` over every item not pruned by its bounds; returns the number visited.
    #[inline(always)]
    fn search<V: Visitor>(&self, q: Vec3, v: &mut V) -> u64 {
        let n = self.nodes.len();
        let qa = q.to_array();
        // (far child's heap number, lower bound of the squared distance to its parent's cell,
        // squared distance to its parent's split plane)
        let mut stack = [(0usize, 0f32, 0f32); MAX_DEPTH];
        let mut top = 0;
        let mut visited = 0;
        let (mut h, mut lb) = (1, 0.0);
        loop {
            // Down the near side, leaving each node's own item and far child for the way back.
            while h <= n && lb <= v.subtree_bound(self, h) {
                let axis = self.axes[h - 1] as usize;
                let diff = qa[axis] - self.nodes[h - 1].point[axis];
                let near = 2 * h + usize::from(diff >= 0.0);
                stack[top] = (near ^ 1, lb, diff * diff);
                top += 1;
                h = near;
            }
            loop {
                if top == 0 {
                    return visited;
                }
                top -= 1;
                let (far, parent_lb, plane2) = stack[top];
                if parent_lb > v.bound() {
                    continue;
                }
                let parent = far / 2;
                visited += 1;
                let p = Vec3::from(self.nodes[parent - 1].point);
                v.visit(self, parent, distance_squared(p, q));
                // The far cell lies inside the parent's and beyond its plane.
                let far_lb = parent_lb.max(plane2);
                if far <= n && far_lb <= v.subtree_bound(self, far) {
                    (h, lb) = (far, far_lb);
                    break;
                }
            }
        }
    }

    /// The `k` items nearest to `q`, within `max_radius` if given (`|p - q| <= max_radius`),
    /// sorted by distance and then payload; fewer if fewer qualify. Empty for a non-finite `q`
    /// or a NaN or negative radius.
    ///
    /// Searches unbounded from the start; [`PointKdTree::nearest_k_bounded_first`] returns the
    /// same items, usually sooner.
    pub fn nearest_k<'a>(
        &self,
        q: Vec3,
        k: usize,
        max_radius: Option<f32>,
        query: &'a mut PointQuery,
    ) -> &'a [Neighbour] {
        query.heap.clear();
        query.stats.queries += 1;
        let Ok(bound) = radius_bound(max_radius) else {
            return &[];
        };
        if !q.is_finite() || k == 0 {
            return &[];
        }
        self.knn_pass(q, k, bound, query);
        query.heap.sort_unstable_by_key(Neighbour::key);
        &query.heap
    }

    /// As [`PointKdTree::nearest_k`], searching first within `initial_radius` (capped at
    /// `max_radius`) and again within `max_radius` only if that found fewer than `k` items
    /// (Dammertz §6.1.3). The result is the same whatever `initial_radius` is; a good one holds
    /// a little more than `k` items around a typical query. With a NaN or negative
    /// `initial_radius` there is no first search.
    pub fn nearest_k_bounded_first<'a>(
        &self,
        q: Vec3,
        k: usize,
        initial_radius: f32,
        max_radius: Option<f32>,
        query: &'a mut PointQuery,
    ) -> &'a [Neighbour] {
        query.heap.clear();
        query.stats.queries += 1;
        let Ok(bound) = radius_bound(max_radius) else {
            return &[];
        };
        if !q.is_finite() || k == 0 {
            return &[];
        }
        let first = radius_bound(Some(initial_radius)).unwrap_or(f32::INFINITY);
        if first < bound {
            self.knn_pass(q, k, first, query);
            // Every item outside the first radius is farther than the k found inside it.
            if query.heap.len() == k || query.heap.len() == self.len() {
                query.heap.sort_unstable_by_key(Neighbour::key);
                return &query.heap;
            }
            query.stats.restarts += 1;
            query.heap.clear();
        }
        self.knn_pass(q, k, bound, query);
        query.heap.sort_unstable_by_key(Neighbour::key);
        &query.heap
    }

    /// One k-NN search within squared radius `bound` into `query.heap` (left unsorted).
    fn knn_pass(&self, q: Vec3, k: usize, bound: f32, query: &mut PointQuery) {
        // Room for every item that can be found, so the search never grows the heap (k may be
        // absurdly large; the tree bounds it).
        let k = k.min(self.len());
        query.heap.reserve(k);
        let mut v = Knn {
            heap: &mut query.heap,
            k,
            radius2: bound,
        };
        query.stats.nodes_visited += self.search(q, &mut v);
    }

    /// Calls `f` with every item within `radius` of `q` (`|p - q| <= radius`), in the tree's
    /// order (deterministic for a given build; sort by [`Neighbour`]'s order if it matters).
    /// Nothing for a non-finite `q` or a NaN or negative radius.
    pub fn for_each_within(
        &self,
        q: Vec3,
        radius: f32,
        query: &mut PointQuery,
        f: impl FnMut(Neighbour),
    ) {
        query.stats.queries += 1;
        let Ok(radius2) = radius_bound(Some(radius)) else {
            return;
        };
        if !q.is_finite() {
            return;
        }
        let mut v = Within { radius2, f };
        query.stats.nodes_visited += self.search(q, &mut v);
    }

    /// Clears `out` and fills it with every item within `radius` of `q`, as
    /// [`PointKdTree::for_each_within`] finds them. Allocates only when `out` must grow.
    pub fn within(&self, q: Vec3, radius: f32, query: &mut PointQuery, out: &mut Vec<Neighbour>) {
        out.clear();
        self.for_each_within(q, radius, query, |n| out.push(n));
    }

    /// The nearest item whose own radius covers `q` (`|p - q| <= radius`), the lowest payload
    /// among equally near ones: the caustic histogram's bin for a photon at `q`. `None` if no
    /// item covers `q` or `q` is not finite.
    pub fn nearest_covering(&self, q: Vec3, query: &mut PointQuery) -> Option<Neighbour> {
        self.nearest_covering_with(q, CoverBound::Subtree, query)
    }

    /// [`PointKdTree::nearest_covering`] with a choice of search bound; both give the same
    /// answer.
    pub fn nearest_covering_with(
        &self,
        q: Vec3,
        bound: CoverBound,
        query: &mut PointQuery,
    ) -> Option<Neighbour> {
        query.stats.queries += 1;
        if !q.is_finite() {
            return None;
        }
        let global = self.max_radius();
        let global2 = global * global;
        let (best, visited) = match bound {
            CoverBound::Subtree => {
                let mut v = Covering::<true> {
                    best: None,
                    global2,
                };
                let visited = self.search(q, &mut v);
                (v.best, visited)
            }
            CoverBound::Global => {
                let mut v = Covering::<false> {
                    best: None,
                    global2,
                };
                let visited = self.search(q, &mut v);
                (v.best, visited)
            }
        };
        query.stats.nodes_visited += visited;
        best
    }
}

/// k nearest within a squared radius: a max-heap of at most `k` on [`Neighbour`]'s order.
struct Knn<'a> {
    heap: &'a mut Vec<Neighbour>,
    k: usize,
    radius2: f32,
}

impl Visitor for Knn<'_> {
    #[inline(always)]
    fn bound(&self) -> f32 {
        if self.heap.len() == self.k {
            // `k` is at least 1 here (a search with `k` = 0 never starts), so the heap has a top.
            self.heap.first().map_or(self.radius2, |n| n.dist2)
        } else {
            self.radius2
        }
    }

    #[inline(always)]
    fn visit(&mut self, tree: &PointKdTree, h: usize, dist2: f32) {
        let cand = Neighbour {
            dist2,
            payload: tree.nodes[h - 1].payload,
        };
        if self.heap.len() < self.k {
            if dist2 <= self.radius2 {
                push_heap(self.heap, cand);
            }
        } else if self.heap.first().is_some_and(|top| cand < *top) {
            replace_top(self.heap, cand);
        }
    }
}

/// Appends `n` and restores the max-heap order (the capacity was reserved by the caller).
fn push_heap(heap: &mut Vec<Neighbour>, n: Neighbour) {
    heap.push(n);
    let mut i = heap.len() - 1;
    while i > 0 {
        let parent = (i - 1) / 2;
        if heap[parent] >= heap[i] {
            break;
        }
        heap.swap(parent, i);
        i = parent;
    }
}

/// Replaces the largest entry by the smaller `n` and sifts it down.
fn replace_top(heap: &mut [Neighbour], n: Neighbour) {
    let len = heap.len();
    let mut i = 0;
    loop {
        let l = 2 * i + 1;
        if l >= len {
            break;
        }
        let r = l + 1;
        let c = if r < len && heap[r] > heap[l] { r } else { l };
        if heap[c] <= n {
            break;
        }
        heap[i] = heap[c];
        i = c;
    }
    heap[i] = n;
}

/// Every item within a squared radius, to a callback.
struct Within<F> {
    radius2: f32,
    f: F,
}

impl<F: FnMut(Neighbour)> Visitor for Within<F> {
    #[inline(always)]
    fn bound(&self) -> f32 {
        self.radius2
    }

    #[inline(always)]
    fn visit(&mut self, tree: &PointKdTree, h: usize, dist2: f32) {
        if dist2 <= self.radius2 {
            (self.f)(Neighbour {
                dist2,
                payload: tree.nodes[h - 1].payload,
            });
        }
    }
}

/// The nearest item that covers the query; `SUBTREE` chooses per-subtree or global radius
/// bounds.
struct Covering<const SUBTREE: bool> {
    best: Option<Neighbour>,
    global2: f32,
}

impl<const SUBTREE: bool> Visitor for Covering<SUBTREE> {
    #[inline(always)]
    fn bound(&self) -> f32 {
        self.best
            .map_or(self.global2, |b| b.dist2.min(self.global2))
    }

    #[inline(always)]
    fn subtree_bound(&self, tree: &PointKdTree, h: usize) -> f32 {
        if SUBTREE {
            let r = tree.radii[h - 1].subtree;
            self.bound().min(r * r)
        } else {
            self.bound()
        }
    }

    #[inline(always)]
    fn visit(&mut self, tree: &PointKdTree, h: usize, dist2: f32) {
        let r = tree.radii[h - 1].own;
        if dist2 > r * r {
            return;
        }
        let cand = Neighbour {
            dist2,
            payload: tree.nodes[h - 1].payload,
        };
        if self.best.is_none_or(|b| cand < b) {
            self.best = Some(cand);
        }
    }
}
