//! GREE on a synthetic 512x512 image with a bank of 8 box filters, timing each stage.
//!
//! The truth has flat regions, sharp edges and fine stripes; N is the truth plus noise whose
//! level grows to the right, so different filters win in different places. The cache
//! "renderer" returns the truth plus independent noise of the same per-sample level.
//!
//! Run with `cargo run --release -p rt-gree --example synthetic [-- size [lambda [kappa]]]`
//! (defaults: 512 and [`GreeParams::default`]'s λ and κ).

use rt_core::rng::SplitMix64;
use rt_gree::{composite, CacheRenderer, GreeParams, Rgb, RgbImage};
use std::time::Instant;

fn normal(rng: &mut SplitMix64) -> f32 {
    let u1 = (rng.f32() as f64).max(1e-12);
    let u2 = rng.f32() as f64;
    ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
}

fn truth(size: usize) -> RgbImage {
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
fn sigma(x: usize, size: usize) -> f32 {
    0.3 + 1.2 * x as f32 / size as f32
}

/// A separable box filter of radius r (clamped borders).
fn box_blur(img: &RgbImage, r: usize) -> RgbImage {
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

struct Renderer<'a> {
    truth: &'a RgbImage,
    rng: SplitMix64,
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

fn mse(a: &RgbImage, b: &RgbImage) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| (*p - *q).length_squared() as f64)
        .sum();
    sum / (3 * a.pixels().len()) as f64
}

fn main() {
    let size: usize = std::env::args()
        .nth(1)
        .map_or(512, |s| s.parse().expect("size"));
    let arg = |i: usize, default: f32| {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("number"))
    };
    let defaults = GreeParams::default();
    let params = GreeParams {
        lambda: arg(2, defaults.lambda),
        kappa: arg(3, defaults.kappa),
        ..defaults
    };
    let budget = params.budget_split();
    let truth = truth(size);
    let mut rng = SplitMix64::new(1);
    let n_spp = budget.n as f32;
    let noisy = RgbImage::from_fn(size, size, |x, y| {
        let s = sigma(x, size) / n_spp.sqrt();
        truth.pixel(x, y) + Rgb::new(normal(&mut rng), normal(&mut rng), normal(&mut rng)) * s
    });
    let variance = RgbImage::from_fn(size, size, |x, _| {
        Rgb::splat(sigma(x, size).powi(2) / n_spp)
    });
    let radii = [0, 1, 2, 3, 5, 8, 12, 16];
    let bank: Vec<RgbImage> = radii.iter().map(|&r| box_blur(&noisy, r)).collect();

    let mut renderer = Renderer {
        truth: &truth,
        rng: SplitMix64::new(2),
    };
    let t = Instant::now();
    let out = composite(&noisy, &variance, &bank, &mut renderer, &params).expect("GREE");
    let wall = t.elapsed();

    println!(
        "{size}x{size}, {} filters, n = {} spp, c = {} spp, {} caches ({} cache samples)",
        bank.len(),
        budget.n,
        budget.c,
        out.caches.len(),
        out.samples_traced
    );
    for (r, f) in radii.iter().zip(&bank) {
        println!("  box r = {r:>2}: MSE {:.3e}", mse(f, &truth));
    }
    println!("  argmin      : MSE {:.3e}", mse(&out.argmin_image, &truth));
    println!("  GREE        : MSE {:.3e}", mse(&out.image, &truth));
    println!(
        "  energy {:.4e} -> {:.4e} ({} sweeps, {} expansions accepted)",
        out.energy.0, out.energy.1, out.cut_moves.0, out.cut_moves.1
    );
    let t = out.timings;
    for (name, d) in [
        ("placement", t.placement),
        ("cache render", t.cache_render),
        ("errors", t.errors),
        ("interpolation", t.interpolation),
        ("graph cut", t.graph_cut),
        ("fusion", t.fusion),
    ] {
        println!("  {name:<14} {:>8.2} ms", d.as_secs_f64() * 1e3);
    }
    println!(
        "  {:<14} {:>8.2} ms (wall {:.2} ms)",
        "total",
        t.total().as_secs_f64() * 1e3,
        wall.as_secs_f64() * 1e3
    );
}
