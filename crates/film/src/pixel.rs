//! Per-pixel accumulators. The film keeps each kind in its own buffer so that a render pays
//! only for the statistics some consumer reads: the mean and count always, the Welford `M2`
//! and the even/odd half sums only when asked for (see [`crate::FilmBuffers`]).

use rt_core::glam::Vec3;
use rt_core::Rgb;

/// Running mean and sample count of one pixel: the only per-pixel state every film keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct MeanCount {
    pub mean: Rgb,
    pub n: u32,
}

impl MeanCount {
    /// Welford's mean update (numerically stable where a running sum would lose the small
    /// samples of a bright pixel). Returns `delta = x - old mean`, which the optional `M2`
    /// update needs: computing it once here keeps the mean's bits the same whether or not the
    /// variance is kept.
    #[inline]
    pub fn add(&mut self, x: Rgb) -> Rgb {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f32;
        delta
    }
}

/// Welford's `M2` update, after [`MeanCount::add`] returned `delta` and moved the mean to
/// `mean`.
#[inline]
pub(crate) fn add_m2(m2: &mut Rgb, x: Rgb, delta: Rgb, mean: Rgb) {
    *m2 += delta * (x - mean);
}

/// Sums and counts of the even- and odd-numbered samples of one pixel: two independent
/// half-estimates whose difference the stopping criterion (Dammertz §6.2) and the GREE error
/// estimates read. Counts are kept rather than derived from the sample index because dropped
/// (non-finite) samples leave gaps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HalfSums {
    sum: [Rgb; 2],
    n: [u32; 2],
}

impl HalfSums {
    /// Adds sample number `index`; its parity picks the half.
    #[inline]
    pub fn add(&mut self, x: Rgb, index: u32) {
        let h = (index & 1) as usize;
        self.sum[h] += x;
        self.n[h] += 1;
    }

    /// Mean of the even-numbered (`half = 0`) or odd-numbered (`half = 1`) samples; zero
    /// without samples.
    #[inline]
    pub fn mean(&self, half: usize) -> Rgb {
        if self.n[half] == 0 {
            return Rgb::ZERO;
        }
        self.sum[half] / self.n[half] as f32
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
    m2: Option<Rgb>,
    halves: Option<HalfSums>,
}

impl PixelStats {
    pub(crate) fn new(mc: MeanCount, m2: Option<Rgb>, halves: Option<HalfSums>) -> Self {
        Self {
            mean: mc.mean,
            n: mc.n,
            m2,
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
        let m2 = self.m2?;
        if self.n < 2 {
            return Some(Rgb::ZERO);
        }
        Some(m2 / (self.n - 1) as f32)
    }

    /// Estimated variance of the mean (sample variance / n); `None` if the film keeps no
    /// variance buffer.
    #[inline]
    pub fn variance_of_mean(&self) -> Option<Rgb> {
        let v = self.sample_variance()?;
        if self.n < 2 {
            return Some(Rgb::ZERO);
        }
        Some(v / self.n as f32)
    }

    /// The even/odd half sums; `None` if the film keeps no half-buffers.
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

    #[inline]
    pub(crate) fn add(&mut self, o: &LightSplit) {
        self.emission += o.emission;
        self.direct += o.direct;
        self.indirect += o.indirect;
        self.diffuse += o.diffuse;
        self.glossy += o.glossy;
        self.irradiance += o.irradiance;
    }

    #[inline]
    pub(crate) fn scaled(&self, k: f32) -> LightSplit {
        LightSplit {
            emission: self.emission * k,
            direct: self.direct * k,
            indirect: self.indirect * k,
            diffuse: self.diffuse * k,
            glossy: self.glossy * k,
            irradiance: self.irradiance * k,
        }
    }
}

/// Welford `M2` of every first-hit feature of one pixel, for the variance of the features'
/// means (the NFOR/Tungsten buffer convention: each feature with its variance).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FeatureM2 {
    pub albedo: Rgb,
    pub normal: Vec3,
    pub depth: f32,
    pub position: Vec3,
}

/// Welford's update of `m2` for a feature kept as a running sum: `sum` and `n` are the sum and
/// count before `x` is added.
#[inline]
pub(crate) fn welford_on_sums<T>(m2: &mut T, sum: T, n: u32, x: T)
where
    T: Copy
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<Output = T>
        + std::ops::Mul<f32, Output = T>
        + std::ops::AddAssign,
{
    if n == 0 {
        return;
    }
    let old_mean = sum * (1.0 / n as f32);
    let new_mean = (sum + x) * (1.0 / (n + 1) as f32);
    *m2 += (x - old_mean) * (x - new_mean);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(xs: &[f32]) -> PixelStats {
        let (mut mc, mut m2, mut h) = (MeanCount::default(), Rgb::ZERO, HalfSums::default());
        for (i, &x) in xs.iter().enumerate() {
            let x = Rgb::splat(x);
            let delta = mc.add(x);
            add_m2(&mut m2, x, delta, mc.mean);
            h.add(x, i as u32);
        }
        PixelStats::new(mc, Some(m2), Some(h))
    }

    #[test]
    fn welford_matches_two_pass_statistics() {
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
        let mut mc = MeanCount::default();
        mc.add(Rgb::splat(2.0));
        let p = PixelStats::new(mc, None, None);
        assert_eq!(p.mean(), Rgb::splat(2.0));
        assert!(p.sample_variance().is_none() && p.variance_of_mean().is_none());
        assert!(p.halves().is_none());
        assert_eq!(stats(&[3.0]).variance_of_mean(), Some(Rgb::ZERO));
        assert_eq!(HalfSums::default().mean(1), Rgb::ZERO);
    }
}
