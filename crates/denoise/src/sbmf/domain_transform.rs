//! The domain transform's recursive filter (Gastal & Oliveira, "Domain Transform for
//! Edge-Aware Image and Video Processing", SIGGRAPH 2011, §5.2 "RF"), on images of `C`-channel
//! pixels: SBMF's blur on each manifold and, with uniform distances, the low-pass that makes
//! the manifolds smooth.
//!
//! One iteration is a horizontal pass (left to right, then right to left) followed by a
//! vertical one; iteration `i` of `N` uses `σ_i = σ_s·√3·2^(N−i−1)/√(4^N − 1)` so that the
//! iterations together have standard deviation `σ_s`, and the feedback weight between
//! neighbours `d` apart in the transformed domain is `a^d` with `a = exp(−√2/σ_i)`. The edge-
//! aware distance between neighbouring pixels is `1 + (σ_s/σ_r)·Σ_c |g_c(p) − g_c(q)|` (the
//! paper's Eq. 11, L1 over the guide's channels); the low-pass uses `d = 1`.
//!
//! Deterministic: rows of the horizontal pass run in parallel (each row is independent), the
//! vertical pass walks rows in order with the columns as the inner loop.

use rayon::prelude::*;

/// Iterations of horizontal + vertical passes (the paper's recommendation).
pub(crate) const ITERATIONS: usize = 3;

/// Transformed-domain distances between each pixel and its left (`dx`) and upper (`dy`)
/// neighbour (the entries of the first column / row are unused).
pub(crate) struct Distances {
    pub dx: Vec<f32>,
    pub dy: Vec<f32>,
}

/// Edge-aware distances of the guide image `g` (`w × h`, row-major): `1 + ratio·L1(Δg)`.
pub(crate) fn distances<const D: usize>(g: &[[f32; D]], w: usize, ratio: f32) -> Distances {
    let l1 = |a: &[f32; D], b: &[f32; D]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>();
    let mut dx = vec![1.0; g.len()];
    let mut dy = vec![1.0; g.len()];
    for i in 0..g.len() {
        if i % w != 0 {
            dx[i] = 1.0 + ratio * l1(&g[i], &g[i - 1]);
        }
        if i >= w {
            dy[i] = 1.0 + ratio * l1(&g[i], &g[i - w]);
        }
    }
    Distances { dx, dy }
}

/// Filters `data` (`w` wide, row-major) in place with spatial standard deviation `sigma_s`
/// pixels; `dist` makes it edge-aware (`None`: every neighbour is 1 apart, a plain low-pass).
pub(crate) fn recursive_filter<const C: usize>(
    data: &mut [[f32; C]],
    w: usize,
    sigma_s: f32,
    dist: Option<&Distances>,
) {
    if data.is_empty() || w == 0 || sigma_s <= 0.0 {
        return;
    }
    let n = ITERATIONS as i32;
    for it in 0..ITERATIONS {
        let sigma_i =
            sigma_s * 3f32.sqrt() * 2f32.powi(n - it as i32 - 1) / (4f32.powi(n) - 1.0).sqrt();
        let ln_a = -std::f32::consts::SQRT_2 / sigma_i;
        let weight = |d: Option<f32>| match d {
            Some(d) => (d * ln_a).exp(),
            None => ln_a.exp(),
        };
        // Horizontal: rows are independent.
        data.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let d = |x: usize| dist.map(|t| t.dx[y * w + x]);
            for x in 1..row.len() {
                let a = weight(d(x));
                let prev = row[x - 1];
                blend(&mut row[x], &prev, a);
            }
            for x in (0..row.len().saturating_sub(1)).rev() {
                let a = weight(d(x + 1));
                let next = row[x + 1];
                blend(&mut row[x], &next, a);
            }
        });
        // Vertical: down, then up, whole rows at a time.
        let h = data.len() / w;
        for y in 1..h {
            let (above, rest) = data.split_at_mut(y * w);
            let above = &above[(y - 1) * w..];
            for (x, (p, q)) in rest[..w].iter_mut().zip(above).enumerate() {
                blend(p, q, weight(dist.map(|t| t.dy[y * w + x])));
            }
        }
        for y in (0..h.saturating_sub(1)).rev() {
            let (upto, below) = data.split_at_mut((y + 1) * w);
            let row = &mut upto[y * w..];
            for (x, (p, q)) in row.iter_mut().zip(&below[..w]).enumerate() {
                blend(p, q, weight(dist.map(|t| t.dy[(y + 1) * w + x])));
            }
        }
    }
}

/// `p ← p + a·(q − p)`: the recursion's feedback from the neighbour already filtered.
#[inline]
fn blend<const C: usize>(p: &mut [f32; C], q: &[f32; C], a: f32) {
    for c in 0..C {
        p[c] += a * (q[c] - p[c]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn low_pass_keeps_constants_and_spreads_an_impulse_but_not_across_an_edge() {
        let (w, h) = (21, 9);
        let mut flat = vec![[2.0f32]; w * h];
        recursive_filter(&mut flat, w, 4.0, None);
        assert!(flat.iter().all(|p| (p[0] - 2.0).abs() < 1e-5));
        let mut imp = vec![[0.0f32]; w * h];
        imp[4 * w + 10] = [1.0];
        recursive_filter(&mut imp, w, 3.0, None);
        assert!(imp[4 * w + 13][0] > 0.01 && imp[4 * w + 10][0] < 0.5);
        // A guide step between columns 10 and 11 stops the spread.
        let guide: Vec<[f32; 1]> = (0..w * h)
            .map(|i| [(i % w > 10) as u8 as f32 * 10.0])
            .collect();
        let d = distances(&guide, w, 3.0);
        let mut imp2 = vec![[0.0f32]; w * h];
        imp2[4 * w + 10] = [1.0];
        recursive_filter(&mut imp2, w, 3.0, Some(&d));
        assert!(imp2[4 * w + 11][0] < 1e-3 * imp[4 * w + 11][0].max(1e-9) + 1e-6);
        assert!(imp2[4 * w + 9][0] > imp[4 * w + 9][0]);
    }
}
