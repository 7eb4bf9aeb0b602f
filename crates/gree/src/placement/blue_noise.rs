//! A seeded blue-noise (Poisson-disk) set of exactly `count` distinct pixels (thesis §5.1.2's
//! "standard Poisson sampling").
//!
//! Deviation: the thesis precomputes one pattern; here it is generated per image by
//! *relaxation dart throwing* (McCool and Fiume 1992) on the pixel grid. The pixels are visited
//! in one seeded random order; a pass accepts every pixel at distance ≥ r from all accepted
//! ones. A pass that ends short of `count` shrinks r by [`SHRINK`] and runs again over the
//! same order, keeping the points it has; the run stops as soon as `count` points exist. The
//! first radius is a little above the saturation radius of random sequential adsorption for
//! `count` disks, `0.8345·sqrt(area / count)`, so the set is nearly a maximal Poisson-disk set
//! and the last, partial pass spreads its points uniformly.

use rt_core::rng::SplitMix64;

/// Factor by which the radius shrinks after a pass that did not reach the count.
pub const SHRINK: f64 = 0.95;

/// Saturation packing constant of random sequential adsorption: a saturated Poisson-disk set
/// with radius r has about `area / (π r²/4) · 0.547` points, so `r ≈ 0.8345·sqrt(area/N)`.
const SATURATION_RADIUS: f64 = 0.8345;

/// A seeded random permutation of `0..n` (Fisher–Yates).
pub(crate) fn permutation(n: usize, rng: &mut SplitMix64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        let j = rng.below(i + 1);
        order.swap(i, j);
    }
    order
}

/// Exactly `min(count, width·height)` distinct pixels of a `width × height` image with
/// blue-noise spacing, deterministic per `seed`, in the order they were accepted.
pub fn blue_noise(width: usize, height: usize, count: usize, seed: u32) -> Vec<(u32, u32)> {
    let pixels = width * height;
    let count = count.min(pixels);
    if count == 0 {
        return Vec::new();
    }
    let mut rng = SplitMix64::new(0xb1ee_0000_0000_0000 ^ seed as u64);
    let order = permutation(pixels, &mut rng);
    let mut r = SATURATION_RADIUS * ((pixels as f64) / count as f64).sqrt() * 1.05;
    // Buckets of side `cell` with linked lists of points, so a query scans a few cells.
    let cell = r.ceil().max(1.0) as usize;
    let (gw, gh) = (width.div_ceil(cell), height.div_ceil(cell));
    let mut head = vec![u32::MAX; gw * gh];
    let mut next = Vec::with_capacity(count);
    let mut points: Vec<(u32, u32)> = Vec::with_capacity(count);
    let mut taken = vec![false; pixels];
    loop {
        let r2 = r * r;
        let reach = (r / cell as f64).ceil() as isize;
        for &idx in &order {
            if taken[idx as usize] {
                continue;
            }
            let (x, y) = (idx as usize % width, idx as usize / width);
            let (cx, cy) = ((x / cell) as isize, (y / cell) as isize);
            let mut free = true;
            'scan: for gy in (cy - reach).max(0)..=(cy + reach).min(gh as isize - 1) {
                for gx in (cx - reach).max(0)..=(cx + reach).min(gw as isize - 1) {
                    let mut k = head[gy as usize * gw + gx as usize];
                    while k != u32::MAX {
                        let (px, py) = points[k as usize];
                        let dx = px as f64 - x as f64;
                        let dy = py as f64 - y as f64;
                        if dx * dx + dy * dy < r2 {
                            free = false;
                            break 'scan;
                        }
                        k = next[k as usize];
                    }
                }
            }
            if free {
                let c = cy as usize * gw + cx as usize;
                next.push(head[c]);
                head[c] = points.len() as u32;
                points.push((x as u32, y as u32));
                taken[idx as usize] = true;
                if points.len() == count {
                    return points;
                }
            }
        }
        // Below one pixel every free pixel is accepted, so the next pass finishes.
        r = if r < 1.0 { 0.0 } else { r * SHRINK };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_count_distinct_and_spread() {
        let (w, h) = (97, 61);
        for count in [1, 10, 300, 1000, w * h] {
            let pts = blue_noise(w, h, count, 7);
            assert_eq!(pts.len(), count);
            let mut seen = vec![false; w * h];
            for &(x, y) in &pts {
                assert!((x as usize) < w && (y as usize) < h);
                assert!(!seen[y as usize * w + x as usize], "duplicate");
                seen[y as usize * w + x as usize] = true;
            }
        }
        assert_eq!(blue_noise(w, h, 300, 7), blue_noise(w, h, 300, 7));
        assert_ne!(blue_noise(w, h, 300, 7), blue_noise(w, h, 300, 8));
    }

    /// Blue noise keeps a minimum distance that white noise does not: with N points in area A,
    /// the nearest pair of N uniform points is about `sqrt(A/(π N²))` apart (far below 1 pixel
    /// here), while the Poisson-disk set keeps the final radius, at least half of `sqrt(A/N)`.
    #[test]
    fn minimum_distance_is_blue_noise() {
        let (w, h, n) = (128usize, 128usize, 800usize);
        let pts = blue_noise(w, h, n, 3);
        let mut min_d2 = f64::INFINITY;
        for (i, a) in pts.iter().enumerate() {
            for b in &pts[i + 1..] {
                let dx = a.0 as f64 - b.0 as f64;
                let dy = a.1 as f64 - b.1 as f64;
                min_d2 = min_d2.min(dx * dx + dy * dy);
            }
        }
        let spacing = ((w * h) as f64 / n as f64).sqrt();
        assert!(
            min_d2.sqrt() >= 0.5 * spacing,
            "{} vs {}",
            min_d2.sqrt(),
            spacing
        );
    }
}
