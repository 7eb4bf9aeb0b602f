//! Per-pixel accumulators.

use rt_core::glam::Vec3;
use rt_core::Rgb;

/// Running statistics of one pixel's samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    mean: Rgb,
    m2: Rgb,
    n: u32,
    half_sum: [Rgb; 2],
    half_n: [u32; 2],
}

impl PixelStats {
    /// Adds sample number `index` (its parity picks the half-buffer). The caller guarantees the
    /// value is finite; [`crate::FilmStripe::add_sample`] checks.
    #[inline]
    pub fn add(&mut self, x: Rgb, index: u32) {
        // Welford's update: numerically stable where sum and sum of squares would cancel.
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f32;
        self.m2 += delta * (x - self.mean);
        let h = (index & 1) as usize;
        self.half_sum[h] += x;
        self.half_n[h] += 1;
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

    /// Unbiased sample variance of one sample.
    #[inline]
    pub fn sample_variance(&self) -> Rgb {
        if self.n < 2 {
            return Rgb::ZERO;
        }
        self.m2 / (self.n - 1) as f32
    }

    /// Estimated variance of the mean (sample variance / n).
    #[inline]
    pub fn variance_of_mean(&self) -> Rgb {
        if self.n < 2 {
            return Rgb::ZERO;
        }
        self.sample_variance() / self.n as f32
    }

    /// Mean of the even-numbered (`half = 0`) or odd-numbered (`half = 1`) samples.
    #[inline]
    pub fn half_mean(&self, half: usize) -> Rgb {
        if self.half_n[half] == 0 {
            return Rgb::ZERO;
        }
        self.half_sum[half] / self.half_n[half] as f32
    }
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

/// Sums of first-hit AOVs over the samples of a pixel that hit something.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AovPixel {
    /// Sum of albedos.
    pub albedo: Rgb,
    /// Sum of normals.
    pub normal: Vec3,
    /// Sum of depths.
    pub depth: f32,
    /// Sum of positions.
    pub position: Vec3,
    /// Samples that hit a surface.
    pub hits: u32,
}

impl AovPixel {
    /// Accumulates one first hit.
    #[inline]
    pub fn add(&mut self, h: &FirstHit) {
        self.albedo += h.albedo;
        self.normal += h.normal;
        self.depth += h.depth;
        self.position += h.position;
        self.hits += 1;
    }

    /// Averages over hits (all zero for a pixel that saw only the background).
    pub fn average(&self) -> FirstHit {
        if self.hits == 0 {
            return FirstHit::default();
        }
        let k = 1.0 / self.hits as f32;
        FirstHit {
            albedo: self.albedo * k,
            normal: self.normal * k,
            depth: self.depth * k,
            position: self.position * k,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_two_pass_statistics() {
        let xs = [0.5f32, 2.0, 7.25, 1.0, 1e-3, 4.0, 3.5];
        let mut p = PixelStats::default();
        for (i, &x) in xs.iter().enumerate() {
            p.add(Rgb::splat(x), i as u32);
        }
        let n = xs.len() as f32;
        let mean = xs.iter().sum::<f32>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (n - 1.0);
        assert!((p.mean().x - mean).abs() < 1e-5);
        assert!((p.sample_variance().x - var).abs() < 1e-4);
        assert!((p.variance_of_mean().x - var / n).abs() < 1e-5);
        let even: Vec<f32> = xs.iter().step_by(2).copied().collect();
        assert!((p.half_mean(0).x - even.iter().sum::<f32>() / even.len() as f32).abs() < 1e-5);
        assert_eq!(p.count(), 7);
    }
}
