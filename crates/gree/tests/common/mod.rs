//! Synthetic scenes and fake cache renderers shared by the integration tests.
#![allow(dead_code)]

use rt_core::rng::SplitMix64;
use rt_gree::{CacheRenderer, Rgb, RgbImage};

/// Gaussian noise from a seeded stream (Box–Muller).
pub struct Gauss(SplitMix64);

impl Gauss {
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::new(seed))
    }

    pub fn normal(&mut self) -> f32 {
        let u1 = (self.0.f32() as f64).max(1e-12);
        let u2 = self.0.f32() as f64;
        ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    }

    pub fn rgb(&mut self, sigma: f32) -> Rgb {
        Rgb::new(self.normal(), self.normal(), self.normal()) * sigma
    }
}

/// A smooth ground truth with some structure, in [0.1, 0.9].
pub fn truth(w: usize, h: usize) -> RgbImage {
    RgbImage::from_fn(w, h, |x, y| {
        let (fx, fy) = (x as f32, y as f32);
        let v = 0.45 + 0.2 * (fx / 9.0).sin() + 0.15 * (fy / 7.0).cos();
        Rgb::new(v, 0.8 * v + 0.05, 0.5 * v + 0.2)
    })
}

/// `base + sigma·noise` where `noisy(x, y)`, `base` elsewhere.
pub fn with_noise(
    base: &RgbImage,
    sigma: f32,
    seed: u64,
    noisy: impl Fn(usize, usize) -> bool,
) -> RgbImage {
    let mut g = Gauss::new(seed);
    RgbImage::from_fn(base.width(), base.height(), |x, y| {
        let n = g.rgb(sigma);
        base.pixel(x, y) + if noisy(x, y) { n } else { Rgb::ZERO }
    })
}

pub fn mse(a: &RgbImage, b: &RgbImage) -> f64 {
    a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| (*p - *q).length_squared() as f64)
        .sum::<f64>()
        / (3 * a.pixels().len()) as f64
}

/// Truth plus independent noise of `sigma / sqrt(spp)` per channel: an honest cache renderer
/// whose samples have standard deviation `sigma`. Counts what it traces.
pub struct Independent<'a> {
    pub truth: &'a RgbImage,
    pub sigma: f32,
    pub gauss: Gauss,
    pub traced: u64,
}

impl<'a> Independent<'a> {
    pub fn new(truth: &'a RgbImage, sigma: f32, seed: u64) -> Self {
        Self {
            truth,
            sigma,
            gauss: Gauss::new(seed),
            traced: 0,
        }
    }
}

impl CacheRenderer for Independent<'_> {
    type Error = std::convert::Infallible;
    fn render_caches(&mut self, pixels: &[(u32, u32)], spp: u32) -> Result<Vec<Rgb>, Self::Error> {
        self.traced += pixels.len() as u64 * spp as u64;
        let s = self.sigma / (spp as f32).sqrt();
        Ok(pixels
            .iter()
            .map(|&(x, y)| self.truth.pixel(x as usize, y as usize) + self.gauss.rgb(s))
            .collect())
    }
}

/// A broken cache renderer that returns N's own values (reuses N's samples).
pub struct ReusesN<'a>(pub &'a RgbImage);

impl CacheRenderer for ReusesN<'_> {
    type Error = std::convert::Infallible;
    fn render_caches(&mut self, pixels: &[(u32, u32)], _spp: u32) -> Result<Vec<Rgb>, Self::Error> {
        Ok(pixels
            .iter()
            .map(|&(x, y)| self.0.pixel(x as usize, y as usize))
            .collect())
    }
}
