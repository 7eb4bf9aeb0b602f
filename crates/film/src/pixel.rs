//! Per-pixel statistics. The film keeps each kind of exact sum ([`crate::fixed`]) in its own
//! buffer so that a render pays only for the statistics some consumer reads: the sum and count
//! always, the sums of squares and the even samples' sums only when asked for (see
//! [`crate::FilmBuffers`]). This module holds what is read back from those sums.

use rt_core::glam::Vec3;
use rt_core::Rgb;

use crate::fixed::{Squares3, Sum1, Sum3};

/// The means and counts of the even- and odd-numbered samples of one pixel: two independent
/// half-estimates whose difference the stopping criterion (Dammertz §6.2) and the GREE error
/// estimates read. Counts are kept rather than derived from the sample index because dropped
/// (non-finite) samples leave gaps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HalfSums {
    mean: [Rgb; 2],
    n: [u32; 2],
}

impl HalfSums {
    /// From the even and odd samples' exact sums and counts.
    pub(crate) fn from_sums(even: &Sum3, odd: &Sum3, n: [u32; 2]) -> Self {
        Self {
            mean: [even.mean(n[0].into()), odd.mean(n[1].into())],
            n,
        }
    }

    /// From the two halves' estimates and sample counts.
    pub(crate) fn from_means(mean: [Rgb; 2], n: [u32; 2]) -> Self {
        Self { mean, n }
    }

    /// Mean of the even-numbered (`half = 0`) or odd-numbered (`half = 1`) samples; zero
    /// without samples.
    #[inline]
    pub fn mean(&self, half: usize) -> Rgb {
        self.mean[half]
    }

    /// Number of samples in half `half`.
    #[inline]
    pub fn count(&self, half: usize) -> u32 {
        self.n[half]
    }
}

/// The statistics of one pixel, assembled from the film's buffers. Quantities whose buffer the
/// film does not keep are `None`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    mean: Rgb,
    n: u32,
    sample_variance: Option<Rgb>,
    halves: Option<HalfSums>,
}

impl PixelStats {
    pub(crate) fn new(
        sum: &Sum3,
        n: u32,
        squares: Option<&Squares3>,
        halves: Option<HalfSums>,
    ) -> Self {
        Self {
            mean: sum.mean(n.into()),
            n,
            sample_variance: squares.map(|q| q.variance(n.into(), sum)),
            halves,
        }
    }

    /// A pixel of filtered sums: its estimate, the samples taken in it, no variance.
    pub(crate) fn filtered(mean: Rgb, n: u32, halves: Option<HalfSums>) -> Self {
        Self {
            mean,
            n,
            sample_variance: None,
            halves,
        }
    }

    /// Number of samples.
    #[inline]
    pub fn count(&self) -> u32 {
        self.n
    }

    /// Sample mean (the pixel estimate).
    #[inline]
    pub fn mean(&self) -> Rgb {
        self.mean
    }

    /// Unbiased sample variance of one sample (zero below two samples); `None` if the film
    /// keeps no variance buffer.
    #[inline]
    pub fn sample_variance(&self) -> Option<Rgb> {
        self.sample_variance
    }

    /// Estimated variance of the mean (sample variance / n); `None` if the film keeps no
    /// variance buffer.
    #[inline]
    pub fn variance_of_mean(&self) -> Option<Rgb> {
        let v = self.sample_variance?;
        if self.n < 2 {
            return Some(Rgb::ZERO);
        }
        Some(v / self.n as f32)
    }

    /// The even/odd half means; `None` if the film keeps no half-buffers.
    #[inline]
    pub fn halves(&self) -> Option<&HalfSums> {
        self.halves.as_ref()
    }
}

/// True if the film keeps radiance sample `l`: finite and non-negative in every channel.
/// The one rule for every buffer (means, splats, per-sample records, sparse re-renders):
/// anything else is dropped and counted.
#[inline]
pub fn accepts_sample(l: Rgb) -> bool {
    l.is_finite() && l.min_element() >= 0.0
}

/// What the first visible surface of one camera sample looked like.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstHit {
    /// Reflectance at normal incidence (texture included).
    pub albedo: Rgb,
    /// Unit shading normal, facing the camera.
    pub normal: Vec3,
    /// Distance from the camera along the ray.
    pub depth: f32,
    /// World-space position.
    pub position: Vec3,
}

impl FirstHit {
    /// True if every field is finite (a non-finite first hit is dropped whole).
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.albedo.is_finite()
            && self.normal.is_finite()
            && self.depth.is_finite()
            && self.position.is_finite()
    }
}

/// How one camera sample's radiance divides, for denoisers that filter the parts apart
/// (seed 002's direct/indirect and diffuse/glossy splits, Dammertz's demodulation). The parts
/// are partitions: `emission + direct + indirect` and `emission + diffuse + glossy` are both
/// the sample's radiance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSplit {
    /// Light seen directly: an emitter or the environment at the first hit.
    pub emission: Rgb,
    /// Light reflected once at the first hit.
    pub direct: Rgb,
    /// Light reflected at the first hit after further bounces.
    pub indirect: Rgb,
    /// Light reflected by the first hit's diffuse layers.
    pub diffuse: Rgb,
    /// Light reflected by the first hit's specular layers.
    pub glossy: Rgb,
    /// Reflected light (`direct + indirect`) over the first hit's albedo, per channel (zero
    /// where the albedo is).
    pub irradiance: Rgb,
}

impl LightSplit {
    /// True if every part is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.emission.is_finite()
            && self.direct.is_finite()
            && self.indirect.is_finite()
            && self.diffuse.is_finite()
            && self.glossy.is_finite()
            && self.irradiance.is_finite()
    }
}

/// Exact sums of the lighting split of one pixel's samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct SplitSums([Sum3; 6]);

impl SplitSums {
    #[inline]
    pub fn add(&mut self, o: &LightSplit) {
        let parts = [
            o.emission,
            o.direct,
            o.indirect,
            o.diffuse,
            o.glossy,
            o.irradiance,
        ];
        for (s, v) in self.0.iter_mut().zip(parts) {
            s.add(v);
        }
    }

    pub fn parts(&self) -> &[Sum3; 6] {
        &self.0
    }

    pub fn from_parts(parts: [Sum3; 6]) -> Self {
        Self(parts)
    }

    pub fn merge(&mut self, o: &SplitSums) {
        for (s, v) in self.0.iter_mut().zip(&o.0) {
            s.merge(v);
        }
    }

    /// The parts' means over `n` samples.
    pub fn mean(&self, n: u32) -> LightSplit {
        let m = self.0.map(|s| s.mean(n.into()));
        LightSplit {
            emission: m[0],
            direct: m[1],
            indirect: m[2],
            diffuse: m[3],
            glossy: m[4],
            irradiance: m[5],
        }
    }
}

/// Exact sums of squares of every first-hit feature of one pixel, for the variance of the
/// features' means (the NFOR/Tungsten buffer convention: each feature with its variance).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct FeatureSquares {
    pub albedo: Sum3,
    pub normal: Sum3,
    pub depth: Sum1,
    pub position: Sum3,
}

impl FeatureSquares {
    pub fn merge(&mut self, o: &FeatureSquares) {
        self.albedo.merge(&o.albedo);
        self.normal.merge(&o.normal);
        self.depth.merge(&o.depth);
        self.position.merge(&o.position);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(xs: &[f32]) -> PixelStats {
        let (mut sum, mut sq, mut even) = (Sum3::default(), Squares3::default(), Sum3::default());
        let mut n = [0u32; 2];
        for (i, &x) in xs.iter().enumerate() {
            let x = Rgb::splat(x);
            sum.add(x);
            sq.add(x);
            if i % 2 == 0 {
                even.add(x);
            }
            n[i % 2] += 1;
        }
        let halves = HalfSums::from_sums(&even, &sum.minus(&even), n);
        PixelStats::new(&sum, xs.len() as u32, Some(&sq), Some(halves))
    }

    #[test]
    fn exact_sums_match_two_pass_statistics() {
        let xs = [0.5f32, 2.0, 7.25, 1.0, 1e-3, 4.0, 3.5];
        let p = stats(&xs);
        let n = xs.len() as f32;
        let mean = xs.iter().sum::<f32>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (n - 1.0);
        assert!((p.mean().x - mean).abs() < 1e-5);
        assert!((p.sample_variance().unwrap().x - var).abs() < 1e-4);
        assert!((p.variance_of_mean().unwrap().x - var / n).abs() < 1e-5);
        let even: Vec<f32> = xs.iter().step_by(2).copied().collect();
        let h = p.halves().unwrap();
        assert!((h.mean(0).x - even.iter().sum::<f32>() / even.len() as f32).abs() < 1e-5);
        assert_eq!((h.count(0), h.count(1)), (4, 3));
        assert_eq!(p.count(), 7);
    }

    #[test]
    fn missing_buffers_read_as_none_and_one_sample_has_zero_variance() {
        let mut sum = Sum3::default();
        sum.add(Rgb::splat(2.0));
        let p = PixelStats::new(&sum, 1, None, None);
        assert_eq!(p.mean(), Rgb::splat(2.0));
        assert!(p.sample_variance().is_none() && p.variance_of_mean().is_none());
        assert!(p.halves().is_none());
        assert_eq!(stats(&[3.0]).variance_of_mean(), Some(Rgb::ZERO));
        assert_eq!(HalfSums::default().mean(1), Rgb::ZERO);
    }
}
