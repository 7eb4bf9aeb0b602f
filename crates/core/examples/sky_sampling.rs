//! Measurements behind the sky's sampling design (`rt_core::environment::sky`): how much of a
//! texel the sun covers at the default table size, and the per-sample noise of next-event
//! estimation of the irradiance of a horizontal surface under the sky for several ways of
//! splitting samples between the sun disc and the texels, and with the sun rasterised into
//! its texel instead.
//!
//! `cargo run --release -p rt-core --example sky_sampling`

use rt_core::color::luminance;
use rt_core::environment::sky::{Sky, DEFAULT_RESOLUTION};
use rt_core::environment::sun::SUN_ANGULAR_RADIUS_DEG;
use rt_core::environment::{dir_to_uv, uv_to_dir, EnvMap, Environment};
use rt_core::frame::Frame;
use rt_core::glam::{Vec2, Vec3};
use rt_core::rng::SplitMix64;
use rt_core::Rgb;
use std::f64::consts::PI;

const SAMPLES: usize = 1_000_000;

fn sun_at(elevation_deg: f64) -> Vec3 {
    let e = elevation_deg.to_radians();
    Vec3::new(0.6 * e.cos() as f32, e.sin() as f32, -0.8 * e.cos() as f32)
}

/// Texels of the sky alone, as `Sky::to_env_map` tabulates them.
fn sky_texels(sky: &Sky, w: u32, h: u32) -> Vec<Rgb> {
    (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                sky.radiance(uv_to_dir(Vec2::new(
                    (x as f32 + 0.5) / w as f32,
                    (y as f32 + 0.5) / h as f32,
                )))
            })
        })
        .collect()
}

/// Mean and relative standard deviation of `estimate` over `SAMPLES` draws.
fn stats(mut estimate: impl FnMut(&mut SplitMix64) -> f64) -> (f64, f64) {
    let mut rng = SplitMix64::new(7);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..SAMPLES {
        let v = estimate(&mut rng);
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / SAMPLES as f64;
    let var = sum2 / SAMPLES as f64 - mean * mean;
    (mean, var.max(0.0).sqrt() / mean)
}

fn main() {
    let (w, h) = DEFAULT_RESOLUTION;
    let r = SUN_ANGULAR_RADIUS_DEG.to_radians();
    let sun_omega = 2.0 * PI * (1.0 - r.cos());
    println!("sun disc: radius {SUN_ANGULAR_RADIUS_DEG} deg, solid angle {sun_omega:.3e} sr");
    println!("\ntexels covered by the sun at {w}x{h} (texel solid angle at the sun's row):");
    for el in [5.0, 30.0, 45.0, 60.0, 85.0] {
        let theta = (90.0f64 - el).to_radians();
        let texel = (2.0 * PI / w as f64) * (PI / h as f64) * theta.sin();
        // Square texels of side a with ~50 of them on the disc: a² = Ω / 50 at the sun's row.
        let side = (sun_omega / 50.0 / theta.sin()).sqrt();
        let (need_w, need_h) = ((2.0 * PI / side).ceil(), (PI / side).ceil());
        println!(
            "  elevation {el:>4} deg: texel {texel:.3e} sr, sun covers {:.2} texel; 50 texels on the disc need {need_w}x{need_h} ({:.0} MB of RGB f32)",
            sun_omega / texel,
            need_w * need_h * 12.0 / 1e6,
        );
    }

    println!(
        "\nirradiance of a horizontal surface, one-sample NEE, {SAMPLES} samples, turbidity 3:"
    );
    println!("  relative standard deviation per sample (lower is better)");
    for el in [10.0, 45.0, 75.0] {
        let sky = Sky::new(sun_at(el), 3.0).unwrap();
        let full = Environment::Map(sky.to_env_map(1.0, w, h).unwrap());
        let disc = *full.map().unwrap().sun().unwrap();
        let p_power = full.map().unwrap().importance().sun_probability() as f64;
        let texels = sky_texels(&sky, w, h);
        let map_only = Environment::Map(EnvMap::new(w, h, texels.clone()));
        let f =
            |env: &Environment, d: Vec3| luminance(env.radiance(d)) as f64 * d.y.max(0.0) as f64;
        let frame = Frame::from_normal(disc.dir());
        // Mixture with share p of the samples in the disc.
        let mixture = |p: f64| {
            stats(|rng| {
                let u = rng.vec2();
                let d = if (u.x as f64) < p {
                    let one_minus_cos = (rng.f32() as f64 * (1.0 - r.cos())) as f32;
                    let s = (one_minus_cos * (2.0 - one_minus_cos)).sqrt();
                    let phi = 2.0 * std::f32::consts::PI * u.y;
                    frame.to_world(Vec3::new(s * phi.cos(), s * phi.sin(), 1.0 - one_minus_cos))
                } else {
                    match map_only.sample(rng.vec2()) {
                        Some(s) => s.dir,
                        None => return 0.0,
                    }
                };
                let in_disc = if disc.contains(d) {
                    1.0 / disc.solid_angle() as f64
                } else {
                    0.0
                };
                let pdf = p * in_disc + (1.0 - p) * map_only.pdf(d) as f64;
                if pdf > 0.0 {
                    f(&full, d) / pdf
                } else {
                    0.0
                }
            })
        };
        let (e_power, sd_power) = stats(|rng| match full.sample(rng.vec2()) {
            Some(s) => luminance(s.radiance) as f64 * s.dir.y.max(0.0) as f64 / s.pdf as f64,
            None => 0.0,
        });
        println!("  sun elevation {el} deg (E = {e_power:.2} klx, p_sun by power {p_power:.3}):");
        println!("    by power (the design)    {sd_power:.3}");
        for p in [0.1, 0.5, 0.9] {
            let (e, sd) = mixture(p);
            println!("    p_sun = {p:<4}              {sd:.3}   (E = {e:.2})");
        }
        // The sun's power spread over the texel that holds its centre, map sampling only.
        let mut raster = texels;
        let uv = dir_to_uv(disc.dir());
        let (x, y) = ((uv.x * w as f32) as u32, (uv.y * h as f32) as u32);
        let t0 = PI * y as f64 / h as f64;
        let t1 = PI * (y + 1) as f64 / h as f64;
        let texel_omega = 2.0 * PI / w as f64 * (t0.cos() - t1.cos());
        raster[(y * w + x) as usize] +=
            disc.radiance() * (disc.solid_angle() as f64 / texel_omega) as f32;
        let raster = Environment::Map(EnvMap::new(w, h, raster));
        let (e, sd) = stats(|rng| match raster.sample(rng.vec2()) {
            Some(s) => luminance(s.radiance) as f64 * s.dir.y.max(0.0) as f64 / s.pdf as f64,
            None => 0.0,
        });
        println!(
            "    sun rasterised           {sd:.3}   (E = {e:.2}; the sun becomes a texel, {:.2}x the disc's solid angle)",
            texel_omega / sun_omega
        );
    }
}
