//! Times each filter-bank denoiser on a 512×512 synthetic noisy frame (every channel present)
//! and prints milliseconds and the MSE against the noise-free image.
//!
//! `cargo run --release -p rt-denoise --example bank [-- SIZE [SPEC...]]`

use rt_core::glam::Vec3;
use rt_core::sampler::hash_u32;
use rt_core::{Image, Rgb};
use rt_denoise::{DenoiserSpec, NoisyFrame};
use std::time::Instant;

fn uniform(i: u32) -> f32 {
    (hash_u32(i) >> 8) as f32 / (1u32 << 24) as f32
}

/// A standard normal variate from two hashed uniforms.
fn gauss(i: u32) -> f32 {
    let (u1, u2) = (uniform(2 * i).max(1e-7), uniform(2 * i + 1));
    (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(512);
    let mut specs: Vec<String> = args.collect();
    if specs.is_empty() {
        specs = [
            "gaussian",
            "gaussian:sigma=16",
            "bilateral",
            "bilateral:sigma=8",
            "nlm",
            "guided",
            "guided:guide=colour",
        ]
        .map(String::from)
        .to_vec();
    }
    // Discs of different albedo on a floor, lit by a gradient; noise σ = 0.1 per channel.
    let disc = |x: usize, y: usize| {
        let (cx, cy) = ((x % 128) as f32 - 64.0, (y % 128) as f32 - 64.0);
        cx * cx + cy * cy < 40.0 * 40.0
    };
    let albedo = Image::from_fn(n, n, |x, y| {
        if disc(x, y) {
            Vec3::new(0.8, 0.3, 0.2)
        } else {
            Vec3::splat(0.5)
        }
    });
    let truth = Image::from_fn(n, n, |x, y| {
        albedo.pixel(x, y) * (0.5 + x as f32 / n as f32)
    });
    let sigma = 0.1;
    let mut frame = NoisyFrame::new(Image::from_fn(n, n, |x, y| {
        let i = 3 * (y * n + x) as u32;
        truth.pixel(x, y) + Rgb::new(gauss(i), gauss(i + 1), gauss(i + 2)) * sigma
    }));
    frame.variance = Some(Image::filled(n, n, Rgb::splat(sigma * sigma)));
    frame.albedo = Some(albedo);
    frame.normal = Some(Image::from_fn(n, n, |x, y| {
        if disc(x, y) {
            Vec3::new(0.0, 0.6, 0.8)
        } else {
            Vec3::Z
        }
    }));
    frame.position = Some(Image::from_fn(n, n, |x, y| {
        Vec3::new(x as f32, y as f32, if disc(x, y) { 5.0 } else { 0.0 }) * 0.01
    }));
    let mse = |img: &Image<Rgb>| {
        let s: f64 = img
            .pixels()
            .iter()
            .zip(truth.pixels())
            .map(|(a, b)| f64::from((*a - *b).length_squared()) / 3.0)
            .sum();
        s / img.len() as f64
    };
    println!("{n}x{n}, {} rayon threads", rayon::current_num_threads());
    println!("{:<70} {:>10} {:>12}", "denoiser", "ms", "mse");
    println!(
        "{:<70} {:>10} {:>12.3e}",
        "(noisy input)",
        "",
        mse(&frame.colour)
    );
    for spec in &specs {
        let d = match spec.parse::<DenoiserSpec>().and_then(|s| s.build()) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        };
        let t = Instant::now();
        let out = d.denoise(&frame).expect("the frame has every channel");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        println!("{:<70} {ms:>10.1} {:>12.3e}", d.name(), mse(&out));
    }
}
