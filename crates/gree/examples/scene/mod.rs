//! The synthetic scene shared by the examples: a truth with flat regions, sharp edges and fine
//! stripes; N is the truth plus noise whose level grows to the right, so different filters win
//! in different places; the bank is 8 box filters; the cache "renderer" returns the truth plus
//! independent noise of the same per-sample level.

// Each example uses a part of the scene.
#![allow(dead_code)]

use rt_core::rng::SplitMix64;
use rt_gree::{CacheRenderer, Rgb, RgbImage};

pub fn normal(rng: &mut SplitMix64) -> f32 {
    let u1 = (rng.f32() as f64).max(1e-12);
    let u2 = rng.f32() as f64;
    ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
}

pub fn truth(size: usize) -> RgbImage {
    let s = size as f32;
    RgbImage::from_fn(size, size, |x, y| {
        let (u, v) = (x as f32 / s, y as f32 / s);
        let disc = (u - 0.35).powi(2) + (v - 0.4).powi(2) < 0.04;
        let stripes = v > 0.7 && ((x / 3) % 2 == 0);
        let base = 0.2 + 0.3 * u;
        let c = if disc {
            Rgb::new(0.9, 0.5, 0.2)
        } else if stripes {
            Rgb::new(0.1, 0.6, 0.8)
        } else {
            Rgb::splat(base)
        };
        c * (0.8 + 0.2 * (v * 6.0).sin())
    })
}

/// Per-sample noise level at column x.
pub fn sigma(x: usize, size: usize) -> f32 {
    0.3 + 1.2 * x as f32 / size as f32
}

/// A separable box filter of radius r (clamped borders).
pub fn box_blur(img: &RgbImage, r: usize) -> RgbImage {
    if r == 0 {
        return img.clone();
    }
    let (w, h) = (img.width(), img.height());
    let pass = |src: &RgbImage, horizontal: bool| {
        RgbImage::from_fn(w, h, |x, y| {
            let mut sum = Rgb::ZERO;
            let mut n = 0.0;
            for d in -(r as isize)..=r as isize {
                let (xx, yy) = if horizontal {
                    (x as isize + d, y as isize)
                } else {
                    (x as isize, y as isize + d)
                };
                if xx >= 0 && yy >= 0 && (xx as usize) < w && (yy as usize) < h {
                    sum += src.pixel(xx as usize, yy as usize);
                    n += 1.0;
                }
            }
            sum / n
        })
    };
    pass(&pass(img, true), false)
}

pub struct Renderer<'a> {
    pub truth: &'a RgbImage,
    pub rng: SplitMix64,
}

impl CacheRenderer for Renderer<'_> {
    type Error = std::convert::Infallible;
    fn render_caches(&mut self, pixels: &[(u32, u32)], spp: u32) -> Result<Vec<Rgb>, Self::Error> {
        let size = self.truth.width();
        Ok(pixels
            .iter()
            .map(|&(x, y)| {
                let s = sigma(x as usize, size) / (spp as f32).sqrt();
                let n = Rgb::new(
                    normal(&mut self.rng),
                    normal(&mut self.rng),
                    normal(&mut self.rng),
                );
                self.truth.pixel(x as usize, y as usize) + n * s
            })
            .collect())
    }
}

pub fn mse(a: &RgbImage, b: &RgbImage) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| (*p - *q).length_squared() as f64)
        .sum();
    sum / (3 * a.pixels().len()) as f64
}

/// The box radii of the bank.
pub const RADII: [usize; 8] = [0, 1, 2, 3, 5, 8, 12, 16];

/// The scene at `size × size` with `n_spp` samples in N.
pub struct Scene {
    /// The noise-free image.
    pub truth: RgbImage,
    /// N.
    pub noisy: RgbImage,
    /// N's variance of the mean.
    pub variance: RgbImage,
    /// Box filters of N with radii [`RADII`].
    pub bank: Vec<RgbImage>,
}

impl Scene {
    pub fn new(size: usize, n_spp: u32) -> Self {
        let truth = truth(size);
        let mut rng = SplitMix64::new(1);
        let n_spp = n_spp as f32;
        let noisy = RgbImage::from_fn(size, size, |x, y| {
            let s = sigma(x, size) / n_spp.sqrt();
            truth.pixel(x, y) + Rgb::new(normal(&mut rng), normal(&mut rng), normal(&mut rng)) * s
        });
        let variance = RgbImage::from_fn(size, size, |x, _| {
            Rgb::splat(sigma(x, size).powi(2) / n_spp)
        });
        let bank = RADII.iter().map(|&r| box_blur(&noisy, r)).collect();
        Self {
            truth,
            noisy,
            variance,
            bank,
        }
    }
}
