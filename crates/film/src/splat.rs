//! Contributions of light paths, which land on any pixel: summed per pixel and normalised by
//! the number of light paths taken, not by a pixel's camera samples (Dammertz 2011, §6.1.2;
//! Veach 1997, §10.3.3).
//!
//! Sums are `f64`: a light tracer adds many small splats to the same pixels over thousands of
//! passes, and an `f32` sum would stop growing long before (the accumulation problem of
//! instant radiosity, thesis §6.1.4). The sums of the even-numbered sample indices are kept
//! apart when the film keeps half-buffers, so the two half-images of a splatting technique are
//! as independent as a camera technique's.

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
    all: Vec<[f64; 3]>,
    /// Sums of the even sample indices (only with half-buffers).
    even: Vec<[f64; 3]>,
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
            self.all = vec![[0.0; 3]; pixels];
            if halves {
                self.even = vec![[0.0; 3]; pixels];
            }
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
            add3(&mut self.all[i], v);
            if even {
                add3(&mut self.even[i], v);
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
            Some(s) if self.paths > 0 => scaled(*s, self.paths),
            _ => Rgb::ZERO,
        }
    }

    /// The estimate of pixel `i` from the even (`0`) or odd (`1`) sample indices only.
    pub(crate) fn half_mean(&self, i: usize, half: usize) -> Rgb {
        let (Some(all), Some(even)) = (self.all.get(i), self.even.get(i)) else {
            return Rgb::ZERO;
        };
        if half == 0 {
            scaled(*even, self.even_paths)
        } else {
            let odd = [all[0] - even[0], all[1] - even[1], all[2] - even[2]];
            scaled(odd, self.paths - self.even_paths)
        }
    }

    /// Bytes held, `None` before the first splat.
    pub(crate) fn bytes(&self) -> Option<usize> {
        (!self.all.is_empty()).then(|| {
            std::mem::size_of_val(self.all.as_slice()) + std::mem::size_of_val(self.even.as_slice())
        })
    }
}

#[inline]
fn add3(s: &mut [f64; 3], v: Rgb) {
    s[0] += f64::from(v.x);
    s[1] += f64::from(v.y);
    s[2] += f64::from(v.z);
}

#[inline]
fn scaled(s: [f64; 3], n: u64) -> Rgb {
    if n == 0 {
        return Rgb::ZERO;
    }
    let k = 1.0 / n as f64;
    Rgb::new((s[0] * k) as f32, (s[1] * k) as f32, (s[2] * k) as f32)
}
