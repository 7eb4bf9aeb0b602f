//! Contributions of light paths, which land on any pixel: summed per pixel and normalised by
//! the number of light paths taken, not by a pixel's camera samples (Dammertz 2011, §6.1.2;
//! Veach 1997, §10.3.3).
//!
//! Sums are exact ([`crate::fixed`]): a light tracer adds many small splats to the same pixels
//! over thousands of passes, where an `f32` sum would stop growing long before (the
//! accumulation problem of instant radiosity, thesis §6.1.4), and splats from many threads or
//! machines land in no fixed order. The sums of the even-numbered sample indices are kept
//! apart when the film keeps half-buffers, so the two half-images of a splatting technique are
//! as independent as a camera technique's.

use crate::fixed::Sum3;
use rt_core::Rgb;

/// One light path's contribution to one pixel (row-major index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    /// Pixel index, `y · width + x`.
    pub pixel: u32,
    /// Contribution, before division by the number of light paths.
    pub value: Rgb,
}

/// Splat sums of a film; nothing is allocated until the first splat arrives.
#[derive(Clone, Debug, Default)]
pub(crate) struct SplatSums {
    all: Vec<Sum3>,
    /// Sums of the even sample indices (only with half-buffers).
    even: Vec<Sum3>,
    paths: u64,
    even_paths: u64,
}

impl SplatSums {
    /// Adds `paths` light paths of sample index `index` and their splats, in order; returns how
    /// many splats were dropped as non-finite, negative or outside the image.
    pub(crate) fn add(
        &mut self,
        pixels: usize,
        halves: bool,
        index: u32,
        paths: u64,
        splats: &[Splat],
    ) -> u64 {
        if self.all.is_empty() {
            self.allocate(pixels, halves);
        }
        let even = index.is_multiple_of(2) && !self.even.is_empty();
        self.paths += paths;
        if even {
            self.even_paths += paths;
        }
        let mut dropped = 0;
        for s in splats {
            let v = s.value;
            let i = s.pixel as usize;
            if !crate::accepts_sample(v) || i >= self.all.len() {
                dropped += 1;
                continue;
            }
            self.all[i].add(v);
            if even {
                self.even[i].add(v);
            }
        }
        dropped
    }

    /// Light paths taken.
    pub(crate) fn paths(&self) -> u64 {
        self.paths
    }

    /// The splat estimate of pixel `i` (zero before any light path).
    #[inline]
    pub(crate) fn mean(&self, i: usize) -> Rgb {
        match self.all.get(i) {
            Some(s) => s.mean(self.paths),
            None => Rgb::ZERO,
        }
    }

    /// The estimate of pixel `i` from the even (`0`) or odd (`1`) sample indices only.
    pub(crate) fn half_mean(&self, i: usize, half: usize) -> Rgb {
        let (Some(all), Some(even)) = (self.all.get(i), self.even.get(i)) else {
            return Rgb::ZERO;
        };
        if half == 0 {
            even.mean(self.even_paths)
        } else {
            all.minus(even).mean(self.paths - self.even_paths)
        }
    }

    /// Bytes held, `None` before the first splat.
    pub(crate) fn bytes(&self) -> Option<usize> {
        (!self.all.is_empty()).then(|| {
            std::mem::size_of_val(self.all.as_slice()) + std::mem::size_of_val(self.even.as_slice())
        })
    }
}

impl SplatSums {
    fn allocate(&mut self, pixels: usize, halves: bool) {
        self.all = vec![Sum3::default(); pixels];
        if halves {
            self.even = vec![Sum3::default(); pixels];
        }
    }

    /// The sums of all and of the even sample indices, the light paths and the even ones;
    /// `None` before the first light path.
    pub(crate) fn parts(&self) -> Option<(&[Sum3], &[Sum3], u64, u64)> {
        (!self.all.is_empty()).then_some((&self.all, &self.even, self.paths, self.even_paths))
    }

    /// The sums to add into, allocated if there were none.
    pub(crate) fn parts_mut(&mut self, pixels: usize, halves: bool) -> (&mut [Sum3], &mut [Sum3]) {
        if self.all.is_empty() {
            self.allocate(pixels, halves);
        }
        (&mut self.all, &mut self.even)
    }

    /// Counts light paths whose splats were added with [`SplatSums::parts_mut`].
    pub(crate) fn add_paths(&mut self, paths: u64, even_paths: u64) {
        self.paths += paths;
        self.even_paths += even_paths;
    }
}
