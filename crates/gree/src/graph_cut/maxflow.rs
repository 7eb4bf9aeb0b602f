//! Boykov–Kolmogorov max-flow (Boykov and Kolmogorov 2004, "An experimental comparison of
//! min-cut/max-flow algorithms for energy minimization in vision"), specialised to a
//! 4-connected pixel grid: every node has arcs to its right, left, lower and upper neighbour,
//! addressed by direction, so the graph needs no adjacency lists and no allocation per build.
//! Search trees grow from the source and the sink; an augmenting path is found where they
//! meet; saturated tree arcs make orphans that are re-adopted or freed. The
//! timestamp/distance heuristic of Kolmogorov's `maxflow` v3 keeps the trees shallow.
//!
//! Buffers are kept across calls to [`GridMaxflow::reset`], so the α-expansions of one graph
//! cut reuse them. Capacities are `f64`.

use std::collections::VecDeque;

/// Arc directions: right (+1), left (−1), down (+width), up (−width). `d ^ 1` is the reverse.
const RIGHT: u8 = 0;
const DOWN: u8 = 2;
/// `parent` markers besides a direction.
const TERMINAL: u8 = 4;
const ORPHAN: u8 = 5;
const FREE: u8 = 6;

/// A max-flow problem on a `width × height` grid, and its solver.
#[derive(Clone, Debug, Default)]
pub struct GridMaxflow {
    width: usize,
    height: usize,
    /// Residual capacity of arc (node, direction), 4 per node.
    cap: Vec<f64>,
    /// Residual terminal capacity: > 0 from the source, < 0 to the sink.
    tr: Vec<f64>,
    /// Bit d set when arc (node, d) exists (the neighbour is inside the grid).
    arcs: Vec<u8>,
    parent: Vec<u8>,
    sink: Vec<bool>,
    ts: Vec<u32>,
    dist: Vec<u32>,
    active: Vec<bool>,
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
        let n = width * height;
        if (width, height) != (self.width, self.height) || self.arcs.len() != n {
            self.arcs = (0..n)
                .map(|p| {
                    let (x, y) = (p % width, p / width);
                    u8::from(x + 1 < width)
                        | u8::from(x > 0) << 1
                        | u8::from(y + 1 < height) << 2
                        | u8::from(y > 0) << 3
                })
                .collect();
        }
        self.width = width;
        self.height = height;
        self.cap.clear();
        self.cap.resize(4 * n, 0.0);
        self.tr.clear();
        self.tr.resize(n, 0.0);
        self.parent.clear();
        self.parent.resize(n, FREE);
        self.sink.clear();
        self.sink.resize(n, false);
        self.ts.clear();
        self.ts.resize(n, 0);
        self.dist.clear();
        self.dist.resize(n, 0);
        self.active.clear();
        self.active.resize(n, false);
        self.queue.clear();
        self.orphans.clear();
        self.time = 0;
        self.flow = 0.0;
    }

    /// Adds terminal capacities to node `p`: `source` is paid when `p` ends on the sink side,
    /// `sink` when it ends on the source side. Either may be negative (only the difference
    /// matters to the cut).
    pub fn add_tweights(&mut self, p: usize, source: f64, sink: f64) {
        self.tr[p] += source - sink;
        self.flow += source.min(sink);
    }

    /// Adds capacity `forward` on the arc from `p` to its right neighbour (`down = false`) or
    /// lower neighbour (`down = true`), and `backward` on the reverse arc. Both non-negative.
    pub fn add_edge(&mut self, p: usize, down: bool, forward: f64, backward: f64) {
        let (d, q) = if down {
            (DOWN, p + self.width)
        } else {
            (RIGHT, p + 1)
        };
        self.cap[4 * p + d as usize] += forward;
        self.cap[4 * q + (d ^ 1) as usize] += backward;
    }

    #[inline]
    fn head(&self, p: usize, d: u8) -> usize {
        match d {
            0 => p + 1,
            1 => p - 1,
            2 => p + self.width,
            _ => p - self.width,
        }
    }

    #[inline]
    fn exists(&self, p: usize, d: u8) -> bool {
        self.arcs[p] >> d & 1 == 1
    }

    fn set_active(&mut self, p: usize) {
        if !self.active[p] {
            self.active[p] = true;
            self.queue.push_back(p as u32);
        }
    }

    fn next_active(&mut self) -> Option<usize> {
        while let Some(p) = self.queue.pop_front() {
            let p = p as usize;
            self.active[p] = false;
            if self.parent[p] != FREE {
                return Some(p);
            }
        }
        None
    }

    /// Whether `p` is on the sink side of the minimum cut found by [`GridMaxflow::maxflow`]
    /// (free nodes count as source side).
    pub fn in_sink(&self, p: usize) -> bool {
        self.parent[p] != FREE && self.sink[p]
    }

    /// Computes the maximum flow (the minimum cut's cost plus the constant of
    /// [`GridMaxflow::add_tweights`]).
    pub fn maxflow(&mut self) -> f64 {
        let n = self.width * self.height;
        for p in 0..n {
            if self.tr[p] != 0.0 {
                self.sink[p] = self.tr[p] < 0.0;
                self.parent[p] = TERMINAL;
                self.ts[p] = 0;
                self.dist[p] = 1;
                self.set_active(p);
            }
        }
        let mut current: Option<usize> = None;
        loop {
            let mut i = current.take().filter(|&i| {
                self.active[i] = false;
                self.parent[i] != FREE
            });
            if i.is_none() {
                i = self.next_active();
            }
            let Some(i) = i else { break };
            // Growth: find an arc (tail, dir) from the source tree into the sink tree.
            let mut meet: Option<(usize, u8)> = None;
            for d in 0..4u8 {
                if !self.exists(i, d) {
                    continue;
                }
                let j = self.head(i, d);
                let c = if self.sink[i] {
                    self.cap[4 * j + (d ^ 1) as usize]
                } else {
                    self.cap[4 * i + d as usize]
                };
                if c <= 0.0 {
                    continue;
                }
                if self.parent[j] == FREE {
                    self.sink[j] = self.sink[i];
                    self.parent[j] = d ^ 1;
                    self.ts[j] = self.ts[i];
                    self.dist[j] = self.dist[i] + 1;
                    self.set_active(j);
                } else if self.sink[j] != self.sink[i] {
                    meet = Some(if self.sink[i] { (j, d ^ 1) } else { (i, d) });
                    break;
                } else if self.ts[j] <= self.ts[i] && self.dist[j] > self.dist[i] {
                    self.parent[j] = d ^ 1;
                    self.ts[j] = self.ts[i];
                    self.dist[j] = self.dist[i] + 1;
                }
            }
            self.time += 1;
            if let Some((tail, d)) = meet {
                self.active[i] = true;
                current = Some(i);
                self.augment(tail, d);
                while let Some(o) = self.orphans.pop_front() {
                    self.adopt(o as usize);
                }
            }
        }
        self.flow
    }

    fn orphan_front(&mut self, p: usize) {
        self.parent[p] = ORPHAN;
        self.orphans.push_front(p as u32);
    }

    fn orphan_back(&mut self, p: usize) {
        self.parent[p] = ORPHAN;
        self.orphans.push_back(p as u32);
    }

    /// Pushes the bottleneck along source → `tail` → (arc `d`) → head → sink.
    fn augment(&mut self, tail: usize, d: u8) {
        let head = self.head(tail, d);
        // Bottleneck.
        let mut b = self.cap[4 * tail + d as usize];
        let mut i = tail;
        while self.parent[i] != TERMINAL {
            let pd = self.parent[i];
            let j = self.head(i, pd);
            b = b.min(self.cap[4 * j + (pd ^ 1) as usize]);
            i = j;
        }
        b = b.min(self.tr[i]);
        let mut i = head;
        while self.parent[i] != TERMINAL {
            let pd = self.parent[i];
            b = b.min(self.cap[4 * i + pd as usize]);
            i = self.head(i, pd);
        }
        b = b.min(-self.tr[i]);
        // Augment.
        self.cap[4 * tail + d as usize] -= b;
        self.cap[4 * head + (d ^ 1) as usize] += b;
        let mut i = tail;
        while self.parent[i] != TERMINAL {
            let pd = self.parent[i];
            let j = self.head(i, pd);
            self.cap[4 * i + pd as usize] += b;
            let c = &mut self.cap[4 * j + (pd ^ 1) as usize];
            *c -= b;
            let saturated = *c <= 0.0;
            if saturated {
                self.orphan_front(i);
            }
            i = j;
        }
        self.tr[i] -= b;
        if self.tr[i] <= 0.0 {
            self.orphan_front(i);
        }
        let mut i = head;
        while self.parent[i] != TERMINAL {
            let pd = self.parent[i];
            let j = self.head(i, pd);
            self.cap[4 * j + (pd ^ 1) as usize] += b;
            let c = &mut self.cap[4 * i + pd as usize];
            *c -= b;
            let saturated = *c <= 0.0;
            if saturated {
                self.orphan_front(i);
            }
            i = j;
        }
        self.tr[i] += b;
        if self.tr[i] >= 0.0 {
            self.orphan_front(i);
        }
        self.flow += b;
    }

    /// Residual capacity from `j` to `i` in the flow direction of `i`'s tree: parent → child
    /// in the source tree, child → parent in the sink tree. `d` is the arc from `i` to `j`.
    #[inline]
    fn tree_cap(&self, i: usize, d: u8, j: usize) -> f64 {
        if self.sink[i] {
            self.cap[4 * i + d as usize]
        } else {
            self.cap[4 * j + (d ^ 1) as usize]
        }
    }

    /// Finds `i` a new parent in its tree, or frees it.
    fn adopt(&mut self, i: usize) {
        let sink = self.sink[i];
        let mut best: Option<(u8, u32)> = None;
        for d in 0..4u8 {
            if !self.exists(i, d) {
                continue;
            }
            let j = self.head(i, d);
            if self.tree_cap(i, d, j) <= 0.0 || self.sink[j] != sink || self.parent[j] == FREE {
                continue;
            }
            // Is j rooted at a terminal? Walk up, counting the distance.
            let mut k = j;
            let mut dist = 0u32;
            let rooted = loop {
                if self.ts[k] == self.time {
                    dist += self.dist[k];
                    break true;
                }
                let pk = self.parent[k];
                dist += 1;
                if pk == TERMINAL {
                    self.ts[k] = self.time;
                    self.dist[k] = 1;
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
                while self.ts[k] != self.time {
                    self.ts[k] = self.time;
                    self.dist[k] = dk;
                    dk -= 1;
                    k = self.head(k, self.parent[k]);
                }
            }
        }
        if let Some((d, dist)) = best {
            self.parent[i] = d;
            self.ts[i] = self.time;
            self.dist[i] = dist + 1;
            return;
        }
        // No parent: i becomes free; its children become orphans, neighbours that could
        // reach it become active.
        self.parent[i] = FREE;
        for d in 0..4u8 {
            if !self.exists(i, d) {
                continue;
            }
            let j = self.head(i, d);
            let pj = self.parent[j];
            if self.sink[j] != sink || pj == FREE {
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
            g.reset(w, h);
            for (p, &(s, k)) in tw.iter().enumerate() {
                g.add_tweights(p, s, k);
            }
            for &(p, down, f, b) in &edges {
                g.add_edge(p, down, f, b);
            }
            let flow = g.maxflow();
            let want = brute_force(w, h, &tw, &edges);
            assert!((flow - want).abs() < 1e-9, "case {case}: {flow} vs {want}");
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
