//! The filter labelling (thesis §5.1.4, Eq. 5.2–5.4): minimise
//! `E(L) = Σ_p D_L(p)(p) + λ Σ_{p~q} V(p, q, L(p), L(q))` over a 4-neighbourhood by α-expansion
//! (Boykov, Veksler and Zabih 2001), each expansion a binary cut solved by our own
//! Boykov–Kolmogorov max-flow ([`maxflow`]).
//!
//! V is the photomontage seam cost (Agarwala et al. 2004): `V = X + Y` with
//! `X = ‖F_a(p) − F_b(p)‖ + ‖F_a(q) − F_b(q)‖` and `Y` the same on image gradients (forward
//! differences to the right and down, both stacked in one 6-vector; 0 past the last column or
//! row), unsquared, 0 when `a = b`. V is a sum of norms of label differences, so it is a metric
//! in the labels and every expansion move is submodular (not in the thesis); a term that
//! rounding makes non-submodular is clamped, which only affects the proposal, not the energy.
//!
//! Deviations and choices:
//! - Normalisation ([`LabelProblem::new`]): the data term is divided by μ² for
//!   [`ErrorMetric::Squared`] (it is a squared radiance) and left as is for
//!   [`ErrorMetric::Relative`] (already relative); V is divided by μ; μ is the mean bank
//!   radiance ([`crate::scale`]). So λ is dimensionless and scaling every radiance by the
//!   same factor leaves the labelling unchanged (for the squared metric).
//! - The start is the per-pixel argmin. An expansion is accepted only if it strictly lowers
//!   the energy (its change, in `f64`, see below), so the energy never rises. Sweeps over all
//!   labels stop after a sweep that lowered the energy by at most [`CutOptions::tolerance`] of it
//!   (none accepted included) or after [`CutOptions::max_sweeps`]. A label whose expansion
//!   failed is not retried until another expansion has been accepted (its proposal would be
//!   the same).
//! - Thesis: GPU, on NPP's binary cut. Here: CPU, serial max-flow; the per-pixel parts
//!   (graph weights, energies) are row-parallel and bit-identical for any thread count.
//! - Each expansion graph starts from the flow of α's previous expansion (Kohli and Torr
//!   2007, dynamic graph cuts; see `expand`): the same cut with fewer augmentations.
//! - An expansion's energy change is summed from its own graph terms over the switched pixels
//!   and their edges (no seam is evaluated again); it is accepted if it is negative beyond
//!   1e-12 of the energy (below that it is rounding). The reported energy is recomputed in
//!   full at the end.
//! - Optional restriction ([`CutOptions::band`]): after the first sweep, only pixels within a
//!   band around the label boundaries may switch; the others keep their label and drop out
//!   of the graph. A restricted move is still a move whose energy change is exact, so the
//!   energy still never rises; a restricted sweep that accepts nothing is followed by an
//!   unrestricted one, so convergence still means an α-expansion local minimum. Off by
//!   default: the seam term dominates, boundaries are dense, and the band saved little.

pub mod maxflow;

use crate::params::ErrorMetric;
use crate::scale::mean_radiance;
use maxflow::GridMaxflow;
use rayon::prelude::*;
use rt_core::{Rgb, RgbImage};

/// A labelling problem: per-label data costs and the bank that defines the seam cost.
#[derive(Clone, Debug)]
pub struct LabelProblem<'a> {
    width: usize,
    height: usize,
    bank: &'a [RgbImage],
    data: &'a [Vec<f32>],
    data_scale: f64,
    pair_weight: f64,
}

/// Settings of [`alpha_expansion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutOptions {
    /// Most sweeps over all labels (default 4).
    pub max_sweeps: u32,
    /// Stop after a sweep that lowered the energy by at most this fraction of it (default
    /// 1e-4; 0 runs to convergence or `max_sweeps`).
    pub tolerance: f64,
    /// After the first sweep, expansions only switch pixels within this many 4-neighbour
    /// steps of a label boundary (`None`, the default: everywhere). See the module doc.
    pub band: Option<u32>,
}

impl Default for CutOptions {
    fn default() -> Self {
        Self {
            max_sweeps: 4,
            tolerance: 1e-4,
            band: BAND,
        }
    }
}

/// The default [`CutOptions::band`]: none, since on the synthetic example a band of 8 saved
/// about 3 % of the instructions for 0.02 % more energy.
const BAND: Option<u32> = None;

/// The result of [`alpha_expansion`].
#[derive(Clone, Debug, PartialEq)]
pub struct Labelling {
    /// One label per pixel, row-major.
    pub labels: Vec<u16>,
    /// Its energy.
    pub energy: f64,
    /// The energy of the starting labelling.
    pub initial_energy: f64,
    /// Sweeps run.
    pub sweeps: u32,
    /// Expansions accepted.
    pub accepted: u32,
}

impl<'a> LabelProblem<'a> {
    /// The problem with the normalisation of the module doc: data costs `data[l][p]` (raw
    /// errors of `metric`), seam costs from `bank`, dimensionless `lambda`.
    ///
    /// # Panics
    /// If `data` and `bank` differ in length, are empty, or a map is not the bank's size.
    pub fn new(
        bank: &'a [RgbImage],
        data: &'a [Vec<f32>],
        lambda: f32,
        metric: ErrorMetric,
    ) -> Self {
        Self::with_mean(bank, data, lambda, metric, mean_radiance(bank))
    }

    /// [`LabelProblem::new`] for a caller that already has the bank's mean radiance `mu`
    /// ([`crate::scale::mean_radiance`]), which is a pass over every bank image.
    ///
    /// # Panics
    /// As [`LabelProblem::new`].
    pub fn with_mean(
        bank: &'a [RgbImage],
        data: &'a [Vec<f32>],
        lambda: f32,
        metric: ErrorMetric,
        mu: f64,
    ) -> Self {
        let data_scale = match metric {
            ErrorMetric::Squared => 1.0 / (mu * mu),
            ErrorMetric::Relative => 1.0,
        };
        Self::with_scales(bank, data, data_scale, lambda as f64 / mu)
    }

    /// The problem `E = data_scale · Σ D + pair_weight · Σ V` with explicit weights.
    ///
    /// # Panics
    /// As [`LabelProblem::new`].
    pub fn with_scales(
        bank: &'a [RgbImage],
        data: &'a [Vec<f32>],
        data_scale: f64,
        pair_weight: f64,
    ) -> Self {
        assert!(
            !bank.is_empty() && bank.len() == data.len(),
            "one data map per filter"
        );
        let (width, height) = (bank[0].width(), bank[0].height());
        for (f, d) in bank.iter().zip(data) {
            assert!(f.width() == width && f.height() == height && d.len() == width * height);
        }
        Self {
            width,
            height,
            bank,
            data,
            data_scale,
            pair_weight,
        }
    }

    /// Number of labels.
    pub fn labels(&self) -> usize {
        self.bank.len()
    }

    /// Scaled data cost of label `l` at pixel `p`.
    #[inline]
    pub fn data_cost(&self, p: usize, l: u16) -> f64 {
        self.data[l as usize][p] as f64 * self.data_scale
    }

    /// `‖F_a(p) − F_b(p)‖ + ‖∇F_a(p) − ∇F_b(p)‖`, one pixel's half of V.
    #[inline]
    fn half_seam(&self, p: usize, a: u16, b: u16) -> f64 {
        let (fa, fb) = (
            self.bank[a as usize].pixels(),
            self.bank[b as usize].pixels(),
        );
        let d = fa[p] - fb[p];
        let x = p % self.width;
        let gx = if x + 1 < self.width {
            (fa[p + 1] - fa[p]) - (fb[p + 1] - fb[p])
        } else {
            Rgb::ZERO
        };
        let q = p + self.width;
        let gy = if q < fa.len() {
            (fa[q] - fa[p]) - (fb[q] - fb[p])
        } else {
            Rgb::ZERO
        };
        d.length() as f64 + ((gx.length_squared() + gy.length_squared()) as f64).sqrt()
    }

    /// The photomontage seam cost V(p, q, a, b), unscaled (0 for `a == b`).
    #[inline]
    pub fn seam_cost(&self, p: usize, q: usize, a: u16, b: u16) -> f64 {
        if a == b {
            0.0
        } else {
            self.half_seam(p, a, b) + self.half_seam(q, a, b)
        }
    }

    /// Scaled pairwise term of the edge (p, q).
    #[inline]
    fn pair(&self, p: usize, q: usize, a: u16, b: u16) -> f64 {
        if a == b || self.pair_weight == 0.0 {
            0.0
        } else {
            self.pair_weight * self.seam_cost(p, q, a, b)
        }
    }

    /// `E(labels)`, summed in `f64` per row, then over rows in order.
    ///
    /// # Panics
    /// If `labels` has not one label per pixel.
    pub fn energy(&self, labels: &[u16]) -> f64 {
        assert_eq!(labels.len(), self.width * self.height);
        let w = self.width;
        let rows: Vec<f64> = (0..self.height)
            .into_par_iter()
            .map(|y| {
                let mut e = 0.0;
                for x in 0..w {
                    let p = y * w + x;
                    e += self.data_cost(p, labels[p]);
                    if x + 1 < w {
                        e += self.pair(p, p + 1, labels[p], labels[p + 1]);
                    }
                    if y + 1 < self.height {
                        e += self.pair(p, p + w, labels[p], labels[p + w]);
                    }
                }
                e
            })
            .collect();
        rows.iter().sum()
    }

    /// The per-pixel argmin of the data cost (ties to the lower label).
    pub fn argmin(&self) -> Vec<u16> {
        (0..self.width * self.height)
            .into_par_iter()
            .map(|p| {
                let mut best = 0u16;
                for l in 1..self.labels() as u16 {
                    if self.data[l as usize][p] < self.data[best as usize][p] {
                        best = l;
                    }
                }
                best
            })
            .collect()
    }
}

/// Per-edge costs of an expansion: A = V(l_p, l_q), B = V(l_p, α), C = V(α, l_q).
type EdgeCosts = [f64; 3];

/// Reused buffers of [`alpha_expansion`].
#[derive(Default)]
struct Buffers {
    flow: GridMaxflow,
    right: Vec<EdgeCosts>,
    down: Vec<EdgeCosts>,
    own: Vec<f64>,
    proposal: Vec<u16>,
    /// Pixels a restricted expansion may switch.
    free: Vec<bool>,
    /// Distance to the nearest label boundary, for `free`.
    dist: Vec<u32>,
    /// Per label, the flow on each pixel's right and down edge after its last expansion
    /// (empty before the first): 16 bytes per pixel and label.
    warm: Vec<Vec<[f64; 2]>>,
}

/// Builds the binary problem "keep (source side) or switch to α (sink side)" and cuts it.
/// Returns the energy change of the proposal (left in `buf.proposal`), or `None` if no pixel
/// switches.
/// With `restricted`, only pixels with `buf.free` set may switch; the others are left out of
/// the graph (their edges to free pixels become terminal capacities), so the cut is the best
/// move among those that keep them, and the max-flow never visits them.
fn expand(
    problem: &LabelProblem,
    labels: &[u16],
    alpha: u16,
    restricted: bool,
    buf: &mut Buffers,
) -> Option<f64> {
    let (w, h) = (problem.width, problem.height);
    let n = w * h;
    let free = restricted.then_some(&buf.free[..]);
    let is_free = |p: usize| free.is_none_or(|f| f[p]);
    buf.right.resize(n, [0.0; 3]);
    buf.down.resize(n, [0.0; 3]);
    buf.own.resize(n, 0.0);
    // Each pixel's half of V(l_p, α), reused by its four edges: inside a label region
    // B = C = V(l, α) needs nothing else.
    buf.own.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, s) in row.iter_mut().enumerate() {
            let p = y * w + x;
            let l = labels[p];
            *s = if l == alpha || problem.pair_weight == 0.0 {
                0.0
            } else {
                problem.half_seam(p, l, alpha)
            };
        }
    });
    let own = &buf.own;
    let pw = problem.pair_weight;
    let costs = |p: usize, q: usize| -> EdgeCosts {
        let (lp, lq) = (labels[p], labels[q]);
        if lp == lq {
            let b = if lp == alpha {
                0.0
            } else {
                pw * (own[p] + own[q])
            };
            return [0.0, b, b];
        }
        let b = if lp == alpha {
            0.0
        } else {
            pw * (own[p] + problem.half_seam(q, lp, alpha))
        };
        let c = if lq == alpha {
            0.0
        } else {
            pw * (problem.half_seam(p, alpha, lq) + own[q])
        };
        [problem.pair(p, q, lp, lq), b, c]
    };
    buf.right
        .par_chunks_mut(w)
        .zip(buf.down.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (right, down))| {
            for x in 0..w {
                let p = y * w + x;
                right[x] = if x + 1 < w { costs(p, p + 1) } else { [0.0; 3] };
                down[x] = if y + 1 < h { costs(p, p + w) } else { [0.0; 3] };
            }
        });
    // Each node's terminal capacity and arcs come from its data term and its four edges,
    // so the graph is built row-parallel with each node written once.
    //
    // Warm start (Kohli and Torr 2007, "Dynamic graph cuts for efficient inference in Markov
    // random fields", §4; the "recycle" of Alahari, Kohli and Torr 2008): α's graph differs
    // from the one of its previous expansion only where labels changed since, so the flow
    // found then is pushed again from the start. Any edge flow is admissible after clamping
    // it to the new capacities: the terminals are stored as one net residual per node, so
    // the imbalance it leaves at a node is just a terminal capacity (Kohli and Torr's
    // reparametrisation). The min cut is the same as from zero flow, only found with far
    // fewer augmentations when little changed.
    let (right, down) = (&buf.right, &buf.down);
    let warm = &buf.warm[alpha as usize];
    let f = |p: usize, k: usize| warm.get(p).map_or(0.0, |f: &[f64; 2]| f[k]);
    buf.flow.build(w, h, |x, y| {
        let p = y * w + x;
        if !is_free(p) {
            return (0.0, [0.0; 4]);
        }
        let mut tr = if labels[p] == alpha {
            0.0
        } else {
            problem.data_cost(p, alpha) - problem.data_cost(p, labels[p])
        };
        let mut cap = [0.0; 4];
        // Flow f on an edge leaves its first node (−f at its terminal, capacity − f ahead)
        // and enters its second (+f at its terminal, reverse capacity + f). An edge to a
        // kept pixel (x = 0 there) is a terminal term: C − A if p is its first node, B − A
        // if p is its second.
        let mut mag = tr.abs();
        let first = |[a, b, c]: EdgeCosts, q: usize, k: usize, tr: &mut f64, mag: &mut f64| {
            if !is_free(q) {
                *tr += c - a;
                return 0.0;
            }
            let e = split_edge([a, b, c]);
            let f = f(p, k).clamp(-e.backward, e.forward);
            *tr += e.first - f;
            *mag += e.first.abs() + f.abs();
            e.forward - f
        };
        let second = |[a, b, c]: EdgeCosts, q: usize, k: usize, tr: &mut f64, mag: &mut f64| {
            if !is_free(q) {
                *tr += b - a;
                return 0.0;
            }
            let e = split_edge([a, b, c]);
            let f = f(q, k).clamp(-e.backward, e.forward);
            *tr += e.second + f;
            *mag += e.second.abs() + f.abs();
            e.backward + f
        };
        if x + 1 < w {
            cap[0] = first(right[p], p + 1, 0, &mut tr, &mut mag);
        }
        if x > 0 {
            cap[1] = second(right[p - 1], p - 1, 0, &mut tr, &mut mag);
        }
        if y + 1 < h {
            cap[2] = first(down[p], p + w, 1, &mut tr, &mut mag);
        }
        if y > 0 {
            cap[3] = second(down[p - w], p - w, 1, &mut tr, &mut mag);
        }
        // A warm start leaves a terminal that the old flow saturated as rounding dust;
        // BK would root a tree at it and push 1e-17 units through, many thousands of times.
        if tr.abs() <= 1e-12 * mag {
            tr = 0.0;
        }
        (tr, cap)
    });
    buf.flow.maxflow();
    let g = &buf.flow;
    // Keep this flow for α's next expansion. In f64: an f32 flow would still be admissible
    // after the clamp, but its rounding leaves dust on almost every terminal, and BK then
    // spends its time on augmentations of 1e-8.
    let warm = &mut buf.warm[alpha as usize];
    warm.resize(n, [0.0; 2]);
    warm.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, f) in row.iter_mut().enumerate() {
            let p = y * w + x;
            let r = g.residual_at(x, y);
            // Edges to kept pixels carried no flow.
            let flow = |e: EdgeCosts, q: usize, r: f64| {
                if is_free(p) && is_free(q) {
                    split_edge(e).forward - r
                } else {
                    0.0
                }
            };
            *f = [
                if x + 1 < w {
                    flow(right[p], p + 1, r[0])
                } else {
                    0.0
                },
                if y + 1 < h {
                    flow(down[p], p + w, r[2])
                } else {
                    0.0
                },
            ];
        }
    });
    buf.proposal.resize(n, 0);
    let changed = buf
        .proposal
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let mut changed = false;
            for (x, l) in row.iter_mut().enumerate() {
                let p = y * w + x;
                let switch = labels[p] != alpha && g.in_sink_at(x, y);
                changed |= switch;
                *l = if switch { alpha } else { labels[p] };
            }
            changed
        })
        .reduce(|| false, |a, b| a || b);
    if !changed {
        return None;
    }
    // The energy change, from the terms already computed: only switched pixels and their
    // edges change, so this costs no seam evaluation. The edge terms are the very values
    // `LabelProblem::energy` adds (V is evaluated by the same expressions), each edge is
    // counted once from its first node, and rows are summed in order.
    let proposal = &buf.proposal;
    let rows: Vec<f64> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut e = 0.0;
            for x in 0..w {
                let p = y * w + x;
                let sp = proposal[p] != labels[p];
                if sp {
                    e += problem.data_cost(p, alpha) - problem.data_cost(p, labels[p]);
                }
                let edge = |[a, b, c]: EdgeCosts, sq: bool| match (sp, sq) {
                    (true, true) => -a,
                    (true, false) => c - a,
                    (false, true) => b - a,
                    (false, false) => 0.0,
                };
                if x + 1 < w {
                    e += edge(right[p], proposal[p + 1] != labels[p + 1]);
                }
                if y + 1 < h {
                    e += edge(down[p], proposal[p + w] != labels[p + w]);
                }
            }
            e
        })
        .collect();
    Some(rows.iter().sum())
}

/// An edge's share of the expansion graph: terminal capacities for its first and second
/// node and its two arc capacities.
struct EdgeSplit {
    first: f64,
    second: f64,
    forward: f64,
    backward: f64,
}

/// The pairwise term with E(0,0) = A, E(0,1) = B, E(1,0) = C, E(1,1) = D = V(α, α) = 0
/// (x = 1: switch to α), written `A + (C − A)·x_p + (D − C)·x_q + (B + C − A − D)·(1 − x_p)·x_q`
/// (Kolmogorov and Zabih 2004): C − A and −C go to the terminals, B + C − A to the forward
/// arc. Kolmogorov and Zabih's other split (A to the first terminal, arcs B − A and C, so
/// that label interiors add nothing to the terminals) made BK's paths longer here: 7 % more
/// instructions in the first sweep of the synthetic example. A term that rounding makes
/// non-submodular (B + C < A) is clamped, which only affects the proposal.
#[inline]
fn split_edge([a, b, c]: EdgeCosts) -> EdgeSplit {
    EdgeSplit {
        first: c - a,
        second: -c,
        forward: (b + c - a).max(0.0),
        backward: 0.0,
    }
}

/// Sets `buf.free` to the pixels within `band` 4-neighbour steps of a label boundary (a
/// pixel with a neighbour of another label), by a two-pass city-block distance transform
/// (sequential, so the same for any thread count).
fn near_boundary(labels: &[u16], w: usize, band: u32, buf: &mut Buffers) {
    let n = labels.len();
    let dist = &mut buf.dist;
    dist.clear();
    dist.resize(n, u32::MAX);
    for p in 0..n {
        let (x, l) = (p % w, labels[p]);
        let edge = (x + 1 < w && labels[p + 1] != l)
            || (x > 0 && labels[p - 1] != l)
            || (p + w < n && labels[p + w] != l)
            || (p >= w && labels[p - w] != l);
        if edge {
            dist[p] = 0;
        }
    }
    for p in 0..n {
        let x = p % w;
        let mut d = dist[p];
        if x > 0 {
            d = d.min(dist[p - 1].saturating_add(1));
        }
        if p >= w {
            d = d.min(dist[p - w].saturating_add(1));
        }
        dist[p] = d;
    }
    for p in (0..n).rev() {
        let x = p % w;
        let mut d = dist[p];
        if x + 1 < w {
            d = d.min(dist[p + 1].saturating_add(1));
        }
        if p + w < n {
            d = d.min(dist[p + w].saturating_add(1));
        }
        dist[p] = d;
    }
    buf.free.clear();
    buf.free.extend(dist.iter().map(|&d| d <= band));
}

/// α-expansion from `initial`: the energy never rises.
///
/// # Panics
/// If `initial` has not one label per pixel or names a label the problem lacks.
pub fn alpha_expansion(
    problem: &LabelProblem,
    initial: Vec<u16>,
    options: &CutOptions,
) -> Labelling {
    assert!(initial.iter().all(|&l| (l as usize) < problem.labels()));
    let mut labels = initial;
    let initial_energy = problem.energy(&labels);
    let mut energy = initial_energy;
    let mut buf = Buffers {
        warm: vec![Vec::new(); problem.labels()],
        ..Buffers::default()
    };
    let mut sweeps = 0;
    let mut accepted = 0;
    let single = problem.labels() < 2;
    // Label α's proposal depends only on the labelling, and an exact α-expansion of its own
    // result changes nothing, so α is not retried until another expansion is accepted.
    // Only unrestricted failures count: a restricted one says nothing about the full move.
    let mut failed_at = vec![u32::MAX; problem.labels()];
    // A restricted sweep that accepts nothing is followed by an unrestricted one before
    // stopping, so convergence still means no α-expansion lowers the energy.
    let mut full = true;
    while sweeps < options.max_sweeps && !single {
        sweeps += 1;
        let sweep_start = energy;
        let mut improved = false;
        let restricted = options.band.is_some() && sweeps > 1 && !full;
        for alpha in 0..problem.labels() as u16 {
            if !restricted && failed_at[alpha as usize] == accepted {
                continue;
            }
            if restricted {
                let band = options.band.unwrap_or(u32::MAX);
                near_boundary(&labels, problem.width, band, &mut buf);
            }
            // A gain below the rounding of the energy itself is no gain.
            if let Some(delta) = expand(problem, &labels, alpha, restricted, &mut buf) {
                if delta < -1e-12 * energy.abs() {
                    energy += delta;
                    std::mem::swap(&mut labels, &mut buf.proposal);
                    accepted += 1;
                    improved = true;
                }
            }
            if !restricted {
                failed_at[alpha as usize] = accepted;
            }
        }
        if !improved && restricted {
            full = true;
            continue;
        }
        full = false;
        if !improved || sweep_start - energy <= options.tolerance * sweep_start.abs() {
            break;
        }
    }
    // The running energy is a sum of changes; report the energy of the result in full.
    if accepted > 0 {
        energy = problem.energy(&labels);
    }
    Labelling {
        labels,
        energy,
        initial_energy,
        sweeps,
        accepted,
    }
}

#[cfg(test)]
mod tests;
