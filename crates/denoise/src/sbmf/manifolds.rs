//! Building the sample-based adaptive manifolds (Bauszat thesis §4.2.2, after Gastal &
//! Oliveira, "Adaptive Manifolds for Real-Time High-Dimensional Filtering", SIGGRAPH 2012,
//! §4.2): a full binary tree of `2^h − 1` manifolds, each one guide-space point per pixel.
//!
//! - The root is the per-pixel mean of the samples' guides, low-pass filtered.
//! - Each node's samples are split by the sign of the projection of their distance to the node
//!   (`g_m − η(i)`) on the dominant eigenvector of those distances' covariance over the whole
//!   node (AMF's clustering; found by power iteration from a fixed start, so deterministic).
//! - A child is the per-pixel mean of only its own samples' guides, low-pass filtered by
//!   normalised convolution (the filtered sums over the filtered counts), so pixels without a
//!   sample of the cluster take their neighbours' values; where no sample of the cluster is
//!   near at all (filtered count below 10⁻⁶) the child keeps its parent's value.
//!
//! Deviations: AMF clusters pixels softly and builds the manifolds at a lower resolution;
//! here samples belong to one cluster (the thesis' wording) and everything is at full
//! resolution. The low-pass is the recursive filter with `σ_s` (AMF's `h_σs`).

use super::domain_transform::recursive_filter;
use super::guides::{Guide, DIMS};
use rayon::prelude::*;
use rt_film::SampleRecords;

/// Power-iteration steps for the dominant eigenvector (9×9 covariance: converges quickly).
const POWER_STEPS: usize = 24;

/// The manifolds, in breadth-first order (node `k`'s children are `2k+1` and `2k+2`), each a
/// `width × height` image of guide-space points.
pub(crate) fn build(
    records: &SampleRecords,
    guides: &[Guide],
    width: usize,
    count: usize,
    sigma_s: f32,
) -> Vec<Vec<Guide>> {
    let pixels = records.offsets().len() - 1;
    // Node of every sample at the current level.
    let mut node = vec![0u32; guides.len()];
    let mut manifolds: Vec<Vec<Guide>> = Vec::with_capacity(count);
    manifolds.push(cluster_mean(
        records, guides, &node, 0, width, sigma_s, None,
    ));
    let mut level_start = 0;
    while manifolds.len() < count {
        let level_end = manifolds.len();
        // Split directions of this level's nodes.
        let dirs: Vec<Guide> = (level_start..level_end)
            .into_par_iter()
            .map(|k| dominant_direction(records, guides, &node, k as u32, &manifolds[k]))
            .collect();
        // Move each sample into its child.
        node.par_chunks_mut(4096)
            .enumerate()
            .for_each(|(c, chunk)| {
                for (o, nd) in chunk.iter_mut().enumerate() {
                    let j = c * 4096 + o;
                    let k = *nd as usize;
                    let eta = &manifolds[k][records.pixel()[j] as usize];
                    let dir = &dirs[k - level_start];
                    let proj: f32 = (0..DIMS).map(|d| (guides[j][d] - eta[d]) * dir[d]).sum();
                    *nd = 2 * k as u32 + if proj >= 0.0 { 2 } else { 1 };
                }
            });
        let children: Vec<Vec<Guide>> = (level_end..(2 * level_end + 1).min(count))
            .into_par_iter()
            .map(|c| {
                let parent = &manifolds[(c - 1) / 2];
                cluster_mean(
                    records,
                    guides,
                    &node,
                    c as u32,
                    width,
                    sigma_s,
                    Some(parent),
                )
            })
            .collect();
        manifolds.extend(children);
        level_start = level_end;
        debug_assert!(manifolds.iter().all(|m| m.len() == pixels));
    }
    manifolds
}

/// Low-passed per-pixel mean of the guides of the samples in node `k` (normalised
/// convolution); `parent` fills pixels no sample of the node reaches.
fn cluster_mean(
    records: &SampleRecords,
    guides: &[Guide],
    node: &[u32],
    k: u32,
    width: usize,
    sigma_s: f32,
    parent: Option<&[Guide]>,
) -> Vec<Guide> {
    let pixels = records.offsets().len() - 1;
    let mut sums = vec![[0.0f32; DIMS + 1]; pixels];
    for (i, s) in sums.iter_mut().enumerate() {
        for j in records.pixel_range(i) {
            if node[j] == k {
                for d in 0..DIMS {
                    s[d] += guides[j][d];
                }
                s[DIMS] += 1.0;
            }
        }
    }
    recursive_filter(&mut sums, width, sigma_s, None);
    sums.iter()
        .enumerate()
        .map(|(i, s)| {
            if s[DIMS] > 1e-6 {
                std::array::from_fn(|d| s[d] / s[DIMS])
            } else {
                parent.map_or([0.0; DIMS], |p| p[i])
            }
        })
        .collect()
}

/// Unit dominant eigenvector of the covariance of `g_m − η(pixel)` over node `k`'s samples.
fn dominant_direction(
    records: &SampleRecords,
    guides: &[Guide],
    node: &[u32],
    k: u32,
    eta: &[Guide],
) -> Guide {
    let mut cov = [[0.0f64; DIMS]; DIMS];
    for (j, g) in guides.iter().enumerate() {
        if node[j] != k {
            continue;
        }
        let e = &eta[records.pixel()[j] as usize];
        let r: [f64; DIMS] = std::array::from_fn(|d| (g[d] - e[d]) as f64);
        for (row, ra) in cov.iter_mut().zip(&r) {
            for (c, rb) in row.iter_mut().zip(&r) {
                *c += ra * rb;
            }
        }
    }
    // Start from the axis of largest variance, tilted towards all axes so that it is not
    // orthogonal to the dominant eigenvector by accident.
    let axis = (0..DIMS)
        .max_by(|&a, &b| cov[a][a].total_cmp(&cov[b][b]))
        .unwrap_or(0);
    let mut v = [0.1f64; DIMS];
    v[axis] = 1.0;
    for _ in 0..POWER_STEPS {
        let mut next = [0.0f64; DIMS];
        for a in 0..DIMS {
            next[a] = (0..DIMS).map(|b| cov[a][b] * v[b]).sum();
        }
        let len = next.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !len.is_finite() || len <= 1e-300 {
            break;
        }
        v = next.map(|x| x / len);
    }
    let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    std::array::from_fn(|d| (v[d] / len) as f32)
}
