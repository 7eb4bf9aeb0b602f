//! Boykov–Kolmogorov max-flow (Boykov and Kolmogorov 2004, "An experimental comparison of
//! min-cut/max-flow algorithms for energy minimization in vision"), specialised to a
//! 4-connected pixel grid: every node has arcs to its right, left, lower and upper neighbour,
//! addressed by direction, so the graph needs no adjacency lists and no allocation per build.
//! Search trees grow from the source and the sink; an augmenting path is found where they
//! meet; saturated tree arcs make orphans that are re-adopted or freed. The
//! timestamp/distance heuristic of Kolmogorov's `maxflow` v3 keeps the trees shallow.
//!
//! Layout (for speed, not in the paper): the grid is padded by one node on every side, so a
//! neighbour index never leaves the array; padding nodes have no capacity and stay free, so
//! they are never entered and need no "does this arc exist" test. Each node's capacities,
//! terminal residual and tree state sit together in one `Node` (one or two cache lines
//! instead of one per array).
//!
//! Buffers are kept across calls to [`GridMaxflow::reset`], so the α-expansions of one graph
//! cut reuse them. Capacities are `f64`.

use rayon::prelude::*;
use std::collections::VecDeque;

/// Arc directions: right (+1), left (−1), down (+stride), up (−stride). `d ^ 1` is the reverse.
const RIGHT: u8 = 0;
const DOWN: u8 = 2;
/// `parent` markers besides a direction.
const TERMINAL: u8 = 4;
const ORPHAN: u8 = 5;
const FREE: u8 = 6;

/// One node of the padded grid.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// Residual capacity of the arc to the neighbour in each direction.
    cap: [f64; 4],
    /// Residual terminal capacity: > 0 from the source, < 0 to the sink.
    tr: f64,
    /// Timestamp and distance to the terminal (Kolmogorov's heuristic).
    ts: u32,
    dist: u32,
    /// Direction to the parent, or `TERMINAL`, `ORPHAN`, `FREE`.
    parent: u8,
    /// In the sink tree (meaningful unless free).
    sink: bool,
    /// In the active queue.
    active: bool,
}

impl Default for Node {
    fn default() -> Self {
        Self {
            cap: [0.0; 4],
            tr: 0.0,
            ts: 0,
            dist: 0,
            parent: FREE,
            sink: false,
            active: false,
        }
    }
}

/// A max-flow problem on a `width × height` grid, and its solver.
#[derive(Clone, Debug, Default)]
pub struct GridMaxflow {
    width: usize,
    height: usize,
    /// `width + 2`: the padded row length.
    stride: usize,
    nodes: Vec<Node>,
    queue: VecDeque<u32>,
    orphans: VecDeque<u32>,
    time: u32,
    flow: f64,
}

impl GridMaxflow {
    /// An empty solver; [`GridMaxflow::reset`] sizes it.
    pub fn new() -> Self {
        Self::default()
    }

    /// Clears the graph to `width × height` nodes with no capacities, keeping the buffers.
    pub fn reset(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.stride = width + 2;
        self.nodes.clear();
        self.nodes
            .resize(self.stride * (height + 2), Node::default());
        self.queue.clear();
        self.orphans.clear();
        self.time = 0;
        self.flow = 0.0;
    }

    /// The padded index of pixel `p` (row-major in the unpadded grid).
    #[inline]
    fn index(&self, p: usize) -> usize {
        let (x, y) = (p % self.width, p / self.width);
        (y + 1) * self.stride + x + 1
    }

    /// Adds terminal capacities to node `p`: `source` is paid when `p` ends on the sink side,
    /// `sink` when it ends on the source side. Either may be negative (only the difference
    /// matters to the cut).
    pub fn add_tweights(&mut self, p: usize, source: f64, sink: f64) {
        let i = self.index(p);
        self.nodes[i].tr += source - sink;
        self.flow += source.min(sink);
    }

    /// Adds capacity `forward` on the arc from `p` to its right neighbour (`down = false`) or
    /// lower neighbour (`down = true`), and `backward` on the reverse arc. Both non-negative;
    /// the neighbour must be inside the grid.
    pub fn add_edge(&mut self, p: usize, down: bool, forward: f64, backward: f64) {
        let (x, y) = (p % self.width, p / self.width);
        assert!(
            if down {
                y + 1 < self.height
            } else {
                x + 1 < self.width
            },
            "edge leaves the grid"
        );
        let i = self.index(p);
        let (d, j) = if down {
            (DOWN, i + self.stride)
        } else {
            (RIGHT, i + 1)
        };
        self.nodes[i].cap[d as usize] += forward;
        self.nodes[j].cap[(d ^ 1) as usize] += backward;
    }

    /// Builds the whole graph at once, row-parallel: `node(x, y)` gives pixel (x, y)'s net
    /// terminal capacity (> 0: paid when it ends on the sink side; < 0: on the source side)
    /// and the capacities of its arcs to the right, left, lower and upper neighbour (those
    /// leaving the grid are ignored). Replaces the graph, and sizes the solver like
    /// [`GridMaxflow::reset`]. The two capacities of an edge come from different calls, so
    /// the caller must make them agree (each node reads both of its edge's costs).
    pub fn build<F>(&mut self, width: usize, height: usize, node: F)
    where
        F: Fn(usize, usize) -> (f64, [f64; 4]) + Sync,
    {
        if (width, height) != (self.width, self.height) || self.nodes.is_empty() {
            self.reset(width, height);
        }
        self.queue.clear();
        self.orphans.clear();
        self.time = 0;
        self.flow = 0.0;
        let s = self.stride;
        // Every pixel node is overwritten in full; the padding nodes are never written by
        // the solver (zero capacity keeps them out of both trees), so they stay as reset.
        self.nodes
            .par_chunks_mut(s)
            .skip(1)
            .take(height)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, n) in row[1..=width].iter_mut().enumerate() {
                    let (tr, mut cap) = node(x, y);
                    if x + 1 == width {
                        cap[RIGHT as usize] = 0.0;
                    }
                    if x == 0 {
                        cap[(RIGHT ^ 1) as usize] = 0.0;
                    }
                    if y + 1 == height {
                        cap[DOWN as usize] = 0.0;
                    }
                    if y == 0 {
                        cap[(DOWN ^ 1) as usize] = 0.0;
                    }
                    *n = Node {
                        cap,
                        tr,
                        ..Node::default()
                    };
                }
            });
    }

    #[inline]
    fn head(&self, i: usize, d: u8) -> usize {
        match d {
            0 => i + 1,
            1 => i - 1,
            2 => i + self.stride,
            _ => i - self.stride,
        }
    }

    #[inline]
    fn set_active(&mut self, i: usize) {
        if !self.nodes[i].active {
            self.nodes[i].active = true;
            self.queue.push_back(i as u32);
        }
    }

    fn next_active(&mut self) -> Option<usize> {
        while let Some(i) = self.queue.pop_front() {
            let i = i as usize;
            self.nodes[i].active = false;
            if self.nodes[i].parent != FREE {
                return Some(i);
            }
        }
        None
    }

    /// Whether `p` is on the sink side of the minimum cut found by [`GridMaxflow::maxflow`]
    /// (free nodes count as source side).
    pub fn in_sink(&self, p: usize) -> bool {
        self.in_sink_at(p % self.width, p / self.width)
    }

    /// [`GridMaxflow::in_sink`] of pixel (x, y).
    pub fn in_sink_at(&self, x: usize, y: usize) -> bool {
        let n = &self.nodes[(y + 1) * self.stride + x + 1];
        n.parent != FREE && n.sink
    }

    /// The residual capacities of pixel (x, y)'s arcs to the right, left, lower and upper
    /// neighbour (after [`GridMaxflow::maxflow`]: what the flow left of each).
    pub fn residual_at(&self, x: usize, y: usize) -> [f64; 4] {
        self.nodes[(y + 1) * self.stride + x + 1].cap
    }

    /// Computes the maximum flow (the minimum cut's cost plus the constant of
    /// [`GridMaxflow::add_tweights`]).
    pub fn maxflow(&mut self) -> f64 {
        for i in 0..self.nodes.len() {
            let n = &mut self.nodes[i];
            if n.tr != 0.0 {
                n.sink = n.tr < 0.0;
                n.parent = TERMINAL;
                n.ts = 0;
                n.dist = 1;
                self.set_active(i);
            }
        }
        let mut current: Option<usize> = None;
        loop {
            let mut i = current.take().filter(|&i| {
                self.nodes[i].active = false;
                self.nodes[i].parent != FREE
            });
            if i.is_none() {
                i = self.next_active();
            }
            let Some(i) = i else { break };
            let meet = self.grow(i);
            self.time += 1;
            if let Some((tail, d)) = meet {
                self.nodes[i].active = true;
                current = Some(i);
                self.augment(tail, d);
                while let Some(o) = self.orphans.pop_front() {
                    self.adopt(o as usize);
                }
            }
        }
        self.flow
    }

    /// Growth from `i`: claims free neighbours it has residual capacity to, and returns an
    /// arc (tail, dir) from the source tree into the sink tree if it touches the other tree.
    #[inline]
    fn grow(&mut self, i: usize) -> Option<(usize, u8)> {
        let ni = self.nodes[i];
        for d in 0..4u8 {
            let j = self.head(i, d);
            let nj = self.nodes[j];
            // Padding nodes have zero capacity both ways, so they fail this test.
            let c = if ni.sink {
                nj.cap[(d ^ 1) as usize]
            } else {
                ni.cap[d as usize]
            };
            if c <= 0.0 {
                continue;
            }
            if nj.parent == FREE {
                let n = &mut self.nodes[j];
                n.sink = ni.sink;
                n.parent = d ^ 1;
                n.ts = ni.ts;
                n.dist = ni.dist + 1;
                self.set_active(j);
            } else if nj.sink != ni.sink {
                return Some(if ni.sink { (j, d ^ 1) } else { (i, d) });
            } else if nj.ts <= ni.ts && nj.dist > ni.dist {
                let n = &mut self.nodes[j];
                n.parent = d ^ 1;
                n.ts = ni.ts;
                n.dist = ni.dist + 1;
            }
        }
        None
    }

    fn orphan_front(&mut self, i: usize) {
        self.nodes[i].parent = ORPHAN;
        self.orphans.push_front(i as u32);
    }

    fn orphan_back(&mut self, i: usize) {
        self.nodes[i].parent = ORPHAN;
        self.orphans.push_back(i as u32);
    }

    /// Pushes the bottleneck along source → `tail` → (arc `d`) → head → sink.
    fn augment(&mut self, tail: usize, d: u8) {
        let head = self.head(tail, d);
        // Bottleneck.
        let mut b = self.nodes[tail].cap[d as usize];
        let mut i = tail;
        loop {
            let pd = self.nodes[i].parent;
            if pd == TERMINAL {
                break;
            }
            let j = self.head(i, pd);
            b = b.min(self.nodes[j].cap[(pd ^ 1) as usize]);
            i = j;
        }
        b = b.min(self.nodes[i].tr);
        let mut i = head;
        loop {
            let pd = self.nodes[i].parent;
            if pd == TERMINAL {
                break;
            }
            b = b.min(self.nodes[i].cap[pd as usize]);
            i = self.head(i, pd);
        }
        b = b.min(-self.nodes[i].tr);
        // Augment.
        self.nodes[tail].cap[d as usize] -= b;
        self.nodes[head].cap[(d ^ 1) as usize] += b;
        let mut i = tail;
        loop {
            let pd = self.nodes[i].parent;
            if pd == TERMINAL {
                break;
            }
            let j = self.head(i, pd);
            self.nodes[i].cap[pd as usize] += b;
            let c = &mut self.nodes[j].cap[(pd ^ 1) as usize];
            *c -= b;
            if *c <= 0.0 {
                self.orphan_front(i);
            }
            i = j;
        }
        self.nodes[i].tr -= b;
        if self.nodes[i].tr <= 0.0 {
            self.orphan_front(i);
        }
        let mut i = head;
        loop {
            let pd = self.nodes[i].parent;
            if pd == TERMINAL {
                break;
            }
            let j = self.head(i, pd);
            self.nodes[j].cap[(pd ^ 1) as usize] += b;
            let c = &mut self.nodes[i].cap[pd as usize];
            *c -= b;
            if *c <= 0.0 {
                self.orphan_front(i);
            }
            i = j;
        }
        self.nodes[i].tr += b;
        if self.nodes[i].tr >= 0.0 {
            self.orphan_front(i);
        }
        self.flow += b;
    }

    /// Residual capacity from `j` to `i` in the flow direction of `i`'s tree: parent → child
    /// in the source tree, child → parent in the sink tree. `d` is the arc from `i` to `j`.
    #[inline]
    fn tree_cap(&self, i: usize, d: u8, j: usize) -> f64 {
        if self.nodes[i].sink {
            self.nodes[i].cap[d as usize]
        } else {
            self.nodes[j].cap[(d ^ 1) as usize]
        }
    }

    /// Finds `i` a new parent in its tree, or frees it.
    fn adopt(&mut self, i: usize) {
        let sink = self.nodes[i].sink;
        let mut best: Option<(u8, u32)> = None;
        for d in 0..4u8 {
            let j = self.head(i, d);
            // Padding nodes are free, so they fail this test.
            if self.tree_cap(i, d, j) <= 0.0
                || self.nodes[j].sink != sink
                || self.nodes[j].parent == FREE
            {
                continue;
            }
            // Is j rooted at a terminal? Walk up, counting the distance.
            let mut k = j;
            let mut dist = 0u32;
            let rooted = loop {
                let nk = &self.nodes[k];
                if nk.ts == self.time {
                    dist += nk.dist;
                    break true;
                }
                let pk = nk.parent;
                dist += 1;
                if pk == TERMINAL {
                    let nk = &mut self.nodes[k];
                    nk.ts = self.time;
                    nk.dist = 1;
                    break true;
                }
                if pk == ORPHAN || pk == FREE {
                    break false;
                }
                k = self.head(k, pk);
            };
            if rooted {
                if best.is_none_or(|(_, bd)| dist < bd) {
                    best = Some((d, dist));
                }
                // Mark the path with the distances just found.
                let mut k = j;
                let mut dk = dist;
                while self.nodes[k].ts != self.time {
                    let nk = &mut self.nodes[k];
                    nk.ts = self.time;
                    nk.dist = dk;
                    dk -= 1;
                    let pk = nk.parent;
                    k = self.head(k, pk);
                }
            }
        }
        if let Some((d, dist)) = best {
            let n = &mut self.nodes[i];
            n.parent = d;
            n.ts = self.time;
            n.dist = dist + 1;
            return;
        }
        // No parent: i becomes free; its children become orphans, neighbours that could
        // reach it become active.
        self.nodes[i].parent = FREE;
        for d in 0..4u8 {
            let j = self.head(i, d);
            let pj = self.nodes[j].parent;
            if self.nodes[j].sink != sink || pj == FREE {
                continue;
            }
            if self.tree_cap(i, d, j) > 0.0 {
                self.set_active(j);
            }
            if pj < TERMINAL && self.head(j, pj) == i {
                self.orphan_back(j);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::rng::SplitMix64;

    /// Minimum cut by enumerating every labelling of a tiny grid.
    fn brute_force(
        w: usize,
        h: usize,
        tw: &[(f64, f64)],
        edges: &[(usize, bool, f64, f64)],
    ) -> f64 {
        let n = w * h;
        let mut best = f64::INFINITY;
        for mask in 0u32..(1 << n) {
            let t = |p: usize| mask >> p & 1 == 1; // sink side
            let mut cost = 0.0;
            for (p, &(s, k)) in tw.iter().enumerate() {
                cost += if t(p) { s } else { k };
            }
            for &(p, down, f, b) in edges {
                let q = if down { p + w } else { p + 1 };
                if !t(p) && t(q) {
                    cost += f;
                }
                if t(p) && !t(q) {
                    cost += b;
                }
            }
            best = best.min(cost);
        }
        best
    }

    #[test]
    fn matches_brute_force_on_random_grids() {
        let mut rng = SplitMix64::new(11);
        let mut g = GridMaxflow::new();
        for case in 0..300 {
            let (w, h) = (1 + rng.below(4), 1 + rng.below(4));
            let tw: Vec<(f64, f64)> = (0..w * h)
                .map(|_| (rng.f32() as f64 * 4.0 - 1.0, rng.f32() as f64 * 4.0 - 1.0))
                .collect();
            let mut edges = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    let p = y * w + x;
                    if x + 1 < w {
                        edges.push((p, false, rng.f32() as f64 * 3.0, rng.f32() as f64 * 3.0));
                    }
                    if y + 1 < h {
                        edges.push((p, true, rng.f32() as f64 * 3.0, rng.f32() as f64 * 3.0));
                    }
                }
            }
            // Every other case goes through `build`, with the same graph node by node.
            let built = case % 2 == 1;
            if built {
                let mut caps = vec![[0.0; 4]; w * h];
                for &(p, down, f, b) in &edges {
                    let (d, q) = if down { (2, p + w) } else { (0, p + 1) };
                    caps[p][d] = f;
                    caps[q][d ^ 1] = b;
                }
                g.build(w, h, |x, y| {
                    let p = y * w + x;
                    (tw[p].0 - tw[p].1, caps[p])
                });
            } else {
                g.reset(w, h);
                for (p, &(s, k)) in tw.iter().enumerate() {
                    g.add_tweights(p, s, k);
                }
                for &(p, down, f, b) in &edges {
                    g.add_edge(p, down, f, b);
                }
            }
            let flow = g.maxflow();
            let want = brute_force(w, h, &tw, &edges);
            // `build` takes net terminal capacities, so its flow lacks the constant.
            if !built {
                assert!((flow - want).abs() < 1e-9, "case {case}: {flow} vs {want}");
            }
            // The cut it reports costs the flow.
            let mut cost = 0.0;
            for (p, &(s, k)) in tw.iter().enumerate() {
                cost += if g.in_sink(p) { s } else { k };
            }
            for &(p, down, f, b) in &edges {
                let q = if down { p + w } else { p + 1 };
                if !g.in_sink(p) && g.in_sink(q) {
                    cost += f;
                }
                if g.in_sink(p) && !g.in_sink(q) {
                    cost += b;
                }
            }
            assert!(
                (cost - want).abs() < 1e-9,
                "case {case}: cut {cost} vs {want}"
            );
        }
    }
}
