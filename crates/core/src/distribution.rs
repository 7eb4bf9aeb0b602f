//! Piecewise-constant 1D and 2D distributions, for sampling emitters by power and environment
//! maps by luminance.

use glam::Vec2;

/// A piecewise-constant distribution over `[0, 1)` with `n` equal bins (or a discrete
/// distribution over `n` items).
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    /// Builds from non-negative weights. Non-finite or negative weights count as zero. If all
    /// weights are zero the distribution is uniform, so sampling never fails; check
    /// [`Distribution1D::integral`] to tell the cases apart.
    pub fn new(weights: &[f32]) -> Self {
        let n = weights.len().max(1);
        let func: Vec<f32> = (0..n)
            .map(|i| {
                let w = weights.get(i).copied().unwrap_or(0.0);
                if w.is_finite() && w > 0.0 {
                    w
                } else {
                    0.0
                }
            })
            .collect();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f32);
        // Accumulate in f64: scenes have millions of emitters.
        let mut acc = 0.0f64;
        for &f in &func {
            acc += f as f64 / n as f64;
            cdf.push(acc as f32);
        }
        let integral = acc as f32;
        if integral > 0.0 {
            for c in cdf.iter_mut() {
                *c /= integral;
            }
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f32 / n as f32;
            }
        }
        *cdf.last_mut().unwrap() = 1.0;
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True if there are no bins (never: an empty input gives one zero bin).
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// Mean of the weights (the integral of the step function over [0,1)).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Bytes of the tables held on the heap (length × element size).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.func.as_slice()) + std::mem::size_of_val(self.cdf.as_slice())
    }

    /// Picks a bin: returns `(index, probability of that bin, u remapped to [0,1) within the bin)`.
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find(u);
        let lo = self.cdf[i];
        let w = self.cdf[i + 1] - lo;
        let remapped = if w > 0.0 {
            ((u - lo) / w).clamp(0.0, ONE_MINUS_EPS)
        } else {
            0.0
        };
        (i, w, remapped)
    }

    /// Probability of bin `i` under [`Distribution1D::sample_discrete`].
    #[inline]
    pub fn discrete_pmf(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Samples a continuous value in [0,1): returns `(x, pdf(x), bin)`.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, p, rem) = self.sample_discrete(u);
        let n = self.func.len() as f32;
        // Keep x inside bin i despite rounding, so that pdf(x) agrees with the returned pdf.
        let hi = f32::from_bits(((i + 1) as f32 / n).to_bits() - 1);
        (((i as f32 + rem) / n).min(hi), p * n, i)
    }

    /// Density of the continuous distribution at bin `i`.
    #[inline]
    pub fn pdf_bin(&self, i: usize) -> f32 {
        self.discrete_pmf(i) * self.func.len() as f32
    }

    fn find(&self, u: f32) -> usize {
        // Largest i with cdf[i] <= u, restricted to bins of non-zero width where possible.
        let n = self.func.len();
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1);
        if self.cdf[i + 1] > self.cdf[i] {
            return i;
        }
        // u landed on a zero-width bin (rounding at the ends): step to a neighbour with mass.
        (i..n)
            .chain((0..i).rev())
            .find(|&j| self.cdf[j + 1] > self.cdf[j])
            .unwrap_or(i)
    }
}

/// Largest f32 below one.
pub const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant distribution over `[0,1)²`, sampled as a marginal over rows (v) and a
/// conditional within the row (u).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// Builds from a `width × height` row-major array of non-negative weights.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Self {
        let rows: Vec<Distribution1D> = (0..height)
            .map(|y| Distribution1D::new(&weights[y * width..(y + 1) * width]))
            .collect();
        let marginal = Distribution1D::new(&rows.iter().map(|r| r.integral()).collect::<Vec<_>>());
        Self { rows, marginal }
    }

    /// Total integral over the square.
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// Bytes held on the heap: the row distributions and their tables, and the marginal's.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.rows.as_slice())
            + self
                .rows
                .iter()
                .map(Distribution1D::memory_bytes)
                .sum::<usize>()
            + self.marginal.memory_bytes()
    }

    /// Samples a point; returns it and its density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, _) = self.rows[row].sample_continuous(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// Density at point `p`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let h = self.rows.len();
        let w = self.rows[0].len();
        let iy = ((p.y * h as f32) as usize).min(h - 1);
        let ix = ((p.x * w as f32) as usize).min(w - 1);
        self.marginal.pdf_bin(iy) * self.rows[iy].pdf_bin(ix)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_sampling_follows_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert!((d.discrete_pmf(0) - 0.25).abs() < 1e-6);
        assert_eq!(d.discrete_pmf(1), 0.0);
        assert_eq!(d.sample_discrete(0.1).0, 0);
        assert_eq!(d.sample_discrete(0.25).0, 2);
        assert_eq!(d.sample_discrete(0.9999).0, 2);
        // Rounding onto the zero bin never returns it.
        for i in 0..1000 {
            assert_ne!(d.sample_discrete(i as f32 / 1000.0).0, 1);
        }
    }

    #[test]
    fn all_zero_weights_give_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.integral(), 0.0);
        assert!((d.discrete_pmf(1) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn pdf_2d_matches_sample() {
        let w = [1.0, 2.0, 3.0, 4.0, 0.0, 6.0];
        let d = Distribution2D::new(&w, 3, 2);
        for i in 0..50 {
            let u = Vec2::new((i as f32 * 0.618) % 1.0, (i as f32 * 0.377) % 1.0);
            let (p, pdf) = d.sample(u);
            assert!((d.pdf(p) - pdf).abs() < 1e-4 * pdf.max(1.0));
        }
        // Two rows of 3 weights and 4 cdf entries; a marginal of 2 weights and 3 cdf entries.
        let row = std::mem::size_of::<Distribution1D>();
        assert_eq!(d.memory_bytes(), 2 * row + 2 * 7 * 4 + 5 * 4);
        // Density integrates to one: bins have area 1/6.
        let total: f32 = (0..6)
            .map(|i| {
                d.pdf(Vec2::new(
                    (i % 3) as f32 / 3.0 + 0.1,
                    (i / 3) as f32 / 2.0 + 0.1,
                )) / 6.0
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-5);
    }
}
