//! The hierarchical stopping criterion of Dammertz, Hanika, Keller and Lensch, "A Hierarchical
//! Automatic Stopping Condition for Monte Carlo Global Illumination" (WSCG 2009; thesis §6.2.2).
//!
//! It reads the film only, so it serves every technique. The film keeps the mean `I` of all
//! samples and the mean `A` of the even-numbered ones; `I − A = (B − A) / 2` compares two
//! independent half estimates at the cost of one extra buffer. Per pixel
//! `e_p = Σ_c |I_c − A_c| / sqrt(Σ_c I_c)` (the square root mimics the eye's response), per block
//! `e_b = r / N · Σ_{p ∈ b} e_p` with `r = sqrt(area_b / area_image)`. A block whose error is
//! below `ε_t = v` is done; one below `ε_s = 256 v` is split in two along its longer axis where
//! the error on both sides is as equal as it can be; others keep sampling. Only leaf blocks are
//! kept (a flat list), and the first decision is taken on the whole image, so no block stops
//! before the image as a whole has seen many samples.
//!
//! Deviations: a denominator `Σ I` below 10⁻⁸ counts as 10⁻⁸ (black pixels whose halves differ
//! still count; the thesis leaves the zero case open); blocks are never split below
//! [`MIN_BLOCK`] pixels a side (the thesis gives no minimum); decisions are taken after passes
//! that leave every active pixel with an even number of samples, so `A` holds exactly half of
//! them.

use crate::Film;

/// The thesis' threshold for every test scene (radiance in display units, about [0, 1]).
pub const DEFAULT_ERROR: f32 = 2e-4;

/// `ε_s / ε_t`, empirical in the thesis.
pub const SPLIT_FACTOR: f32 = 256.0;

/// Smallest side of a block, in pixels, that may still be split.
pub const MIN_BLOCK: u32 = 8;

/// A rectangle of pixels, `x0..x1 × y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Block {
    fn area(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }
}

/// Why a threshold was rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("error threshold must be a positive finite number, got {0}")]
pub struct BadThreshold(pub f32);

/// What one decision did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Decision {
    /// Blocks that met the threshold and stopped.
    pub finished: usize,
    /// Blocks split in two.
    pub split: usize,
    /// Blocks still sampling afterwards.
    pub active: usize,
}

/// The list of blocks still sampling, and the per-pixel state of the whole image.
#[derive(Clone, Debug)]
pub struct StoppingCriterion {
    threshold: f32,
    width: u32,
    height: u32,
    active: Vec<Block>,
    /// Blocks that met the threshold, in the order they did.
    finished: Vec<Block>,
    /// Per pixel: still sampling.
    mask: Vec<bool>,
    /// Reused per decision: per-pixel errors.
    errors: Vec<f32>,
}

impl StoppingCriterion {
    /// One block over a `width × height` image with threshold `v` (`ε_t`).
    pub fn new(width: u32, height: u32, v: f32) -> Result<Self, BadThreshold> {
        if v.is_nan() || v <= 0.0 || !v.is_finite() {
            return Err(BadThreshold(v));
        }
        let n = width as usize * height as usize;
        let all = Block {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        };
        Ok(Self {
            threshold: v,
            width,
            height,
            active: if n > 0 { vec![all] } else { Vec::new() },
            finished: Vec::new(),
            mask: vec![true; n],
            errors: Vec::new(),
        })
    }

    /// The blocks still sampling.
    pub fn active(&self) -> &[Block] {
        &self.active
    }

    /// The blocks that met the threshold, in the order they did.
    pub fn finished(&self) -> &[Block] {
        &self.finished
    }

    /// True once every block has met the threshold.
    pub fn converged(&self) -> bool {
        self.active.is_empty()
    }

    /// Per pixel, row-major: true while its block samples.
    pub fn mask(&self) -> &[bool] {
        &self.mask
    }

    /// The error of block `b` ([`StoppingCriterion::decide`] computes the pixel errors first).
    fn block_error(&self, b: &Block) -> f32 {
        let image = f64::from(self.width) * f64::from(self.height);
        let r = (b.area() as f64 / image).sqrt();
        let mut sum = 0.0f64;
        for y in b.y0..b.y1 {
            let row = (y * self.width) as usize;
            sum += self.errors[row + b.x0 as usize..row + b.x1 as usize]
                .iter()
                .map(|&e| f64::from(e))
                .sum::<f64>();
        }
        (r * sum / b.area().max(1) as f64) as f32
    }

    /// Takes one decision from `film`'s means and even-sample half means: finishes, splits or
    /// keeps every active block. The film must keep half-buffers.
    ///
    /// # Panics
    /// If the film keeps no half-buffers or differs in size.
    pub fn decide(&mut self, film: &Film) -> Decision {
        assert_eq!((film.width(), film.height()), (self.width, self.height));
        let all = film.mean_image();
        let even = film
            .half_image(0)
            .expect("the stopping criterion needs the film's half-buffers");
        self.errors.clear();
        self.errors.extend(all.iter().zip(&even).map(|(i, a)| {
            let num = (*i - *a).abs().element_sum();
            let den = i.element_sum().max(1e-8).sqrt();
            let e = num / den;
            if e.is_finite() {
                e
            } else {
                f32::INFINITY
            }
        }));
        let (t, s) = (self.threshold, self.threshold * SPLIT_FACTOR);
        let mut next = Vec::with_capacity(self.active.len() + 8);
        let mut d = Decision::default();
        for b in std::mem::take(&mut self.active) {
            let e = self.block_error(&b);
            if e < t {
                d.finished += 1;
                self.finished.push(b);
                for y in b.y0..b.y1 {
                    let row = (y * self.width) as usize;
                    self.mask[row + b.x0 as usize..row + b.x1 as usize].fill(false);
                }
            } else if e < s {
                match self.split(&b) {
                    Some((l, r)) => {
                        d.split += 1;
                        next.push(l);
                        next.push(r);
                    }
                    None => next.push(b),
                }
            } else {
                next.push(b);
            }
        }
        d.active = next.len();
        self.active = next;
        d
    }

    /// Splits `b` along its longer axis where the summed pixel error is as equal as it can be
    /// on both sides; `None` when the axis is shorter than twice [`MIN_BLOCK`].
    fn split(&self, b: &Block) -> Option<(Block, Block)> {
        let (w, h) = (b.x1 - b.x0, b.y1 - b.y0);
        let along_x = w >= h;
        let len = if along_x { w } else { h };
        if len < 2 * MIN_BLOCK {
            return None;
        }
        // Error per column (or row) of the block, then the cut that best balances the halves.
        let line = |k: u32| -> f64 {
            if along_x {
                (b.y0..b.y1)
                    .map(|y| f64::from(self.errors[(y * self.width + b.x0 + k) as usize]))
                    .sum()
            } else {
                let row = ((b.y0 + k) * self.width) as usize;
                self.errors[row + b.x0 as usize..row + b.x1 as usize]
                    .iter()
                    .map(|&e| f64::from(e))
                    .sum()
            }
        };
        let sums: Vec<f64> = (0..len).map(line).collect();
        let total: f64 = sums.iter().sum();
        let mut left = 0.0;
        let mut best = (f64::INFINITY, len / 2);
        for (k, s) in sums.iter().enumerate() {
            left += s;
            let cut = k as u32 + 1;
            if cut < MIN_BLOCK || len - cut < MIN_BLOCK {
                continue;
            }
            let imbalance = (2.0 * left - total).abs();
            if imbalance < best.0 {
                best = (imbalance, cut);
            }
        }
        let cut = best.1;
        Some(if along_x {
            (
                Block {
                    x1: b.x0 + cut,
                    ..*b
                },
                Block {
                    x0: b.x0 + cut,
                    ..*b
                },
            )
        } else {
            (
                Block {
                    y1: b.y0 + cut,
                    ..*b
                },
                Block {
                    y0: b.y0 + cut,
                    ..*b
                },
            )
        })
    }
}

/// The leaf blocks of a stopping decision as per-pixel maps (`render --aov blocks`): each
/// pixel's block index (finished blocks first, in the order they finished, then the active
/// ones) and whether its block met the threshold.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockMap {
    /// Block index per pixel, row-major.
    pub index: Vec<u32>,
    /// Per pixel: its block met the threshold.
    pub converged: Vec<bool>,
}

impl BlockMap {
    /// The map of `finished` and `active` blocks over a `width × height` image. Pixels in no
    /// block (never, for a criterion's blocks, which tile the image) get index `u32::MAX`.
    pub fn new(width: u32, height: u32, finished: &[Block], active: &[Block]) -> Self {
        let n = width as usize * height as usize;
        let mut map = Self {
            index: vec![u32::MAX; n],
            converged: vec![false; n],
        };
        let leaves = finished.iter().map(|b| (b, true));
        let leaves = leaves.chain(active.iter().map(|b| (b, false)));
        for (i, (b, done)) in leaves.enumerate() {
            for y in b.y0..b.y1.min(height) {
                let row = (y * width) as usize;
                let span = row + b.x0 as usize..row + b.x1.min(width) as usize;
                map.index[span.clone()].fill(i as u32);
                map.converged[span].fill(done);
            }
        }
        map
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilmBuffers;
    use rt_core::Rgb;

    /// A film whose left half has identical halves (no error) and whose right half has halves
    /// that differ by `d`.
    fn film(w: u32, h: u32, d: f32) -> Film {
        let mut f = Film::new(w, h, FilmBuffers::default().with_halves());
        for y in 0..h {
            for x in 0..w {
                let noisy = x >= w / 2;
                for i in 0..2 {
                    let v = if noisy && i == 1 { 0.5 + d } else { 0.5 };
                    f.add_sample(x, y, i, Rgb::splat(v), None);
                }
            }
        }
        f
    }

    #[test]
    fn converged_images_stop_at_once_and_noisy_halves_keep_sampling() {
        let mut c = StoppingCriterion::new(64, 32, DEFAULT_ERROR).unwrap();
        let d = c.decide(&film(64, 32, 0.0));
        assert_eq!((d.finished, c.converged()), (1, true));
        assert!(c.mask().iter().all(|&m| !m));

        // Right half: |I − A| = d/2 per channel, so e_p = 1.5 d / sqrt(1.5 + 1.5 d) = 0.236 for
        // d = 0.2; the image's error is half that, above ε_s = 0.0512: keep sampling.
        let mut c = StoppingCriterion::new(64, 32, DEFAULT_ERROR).unwrap();
        let d = c.decide(&film(64, 32, 0.2));
        assert_eq!((d.finished, d.split, d.active), (0, 0, 1));
    }

    #[test]
    fn a_block_between_the_thresholds_splits_where_the_error_balances() {
        // Choose d so the whole image's error lies between ε_t and ε_s.
        let (w, h) = (64, 32);
        let f = film(w, h, 4e-3);
        let mut c = StoppingCriterion::new(w, h, 2e-5).unwrap();
        let d = c.decide(&f);
        assert_eq!(d.split, 1, "{d:?}");
        // All the error is in the right half: the balancing cut lies inside it, not at the
        // middle, and never closer than MIN_BLOCK to an edge.
        let cut = c.active()[0].x1;
        assert!(cut > w / 2 && cut <= w - MIN_BLOCK, "cut at {cut}");
        // Further splits isolate the error-free left part, which stops while the noisy right
        // edge still samples.
        for _ in 0..10 {
            if !c.mask()[0] {
                break;
            }
            c.decide(&f);
        }
        assert!(
            !c.mask()[0] && c.mask()[(w - 1) as usize],
            "{:?}",
            c.active()
        );
    }

    #[test]
    fn blocks_never_stop_above_the_threshold() {
        // Random half differences: after every decision, each finished pixel's block had an
        // error below the threshold; checked by recomputing from the decided blocks.
        let (w, h) = (48, 40);
        let mut rng = rt_core::rng::SplitMix64::new(3);
        let mut f = Film::new(w, h, FilmBuffers::default().with_halves());
        for y in 0..h {
            for x in 0..w {
                let scale = if x < 16 { 1e-6 } else { 3e-3 };
                for i in 0..2 {
                    f.add_sample(x, y, i, Rgb::splat(0.3 + scale * rng.f32()), None);
                }
            }
        }
        let v = 1e-4;
        let mut c = StoppingCriterion::new(w, h, v).unwrap();
        for _ in 0..20 {
            let before: Vec<Block> = c.active().to_vec();
            c.decide(&f);
            for b in before {
                let stopped = !c.mask()[(b.y0 * w + b.x0) as usize];
                if stopped && c.active().iter().all(|a| a.x0 != b.x0 || a.y0 != b.y0) {
                    assert!(
                        c.block_error(&b) < v,
                        "{b:?} stopped at {}",
                        c.block_error(&b)
                    );
                }
            }
        }
    }

    #[test]
    fn bad_thresholds_are_rejected() {
        for v in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(StoppingCriterion::new(4, 4, v).is_err(), "{v}");
        }
    }
}
