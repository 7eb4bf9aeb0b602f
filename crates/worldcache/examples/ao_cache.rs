//! Ambient occlusion cached over frames, as the thesis does: each frame traces one AO ray per
//! pixel at the primary hit, records it into the cache, merges, and reconstructs every pixel
//! from the cache. Prints relMSE against a 256-ray reference per frame, for the implicit
//! points, the fixed grid at matched density, and plain per-pixel accumulation.
//!
//! `cargo run --release -p rt-worldcache --example ao_cache [SCENE] [LOD] [FRAMES]`
//! (defaults: the procedural `rotated` city, implicit LOD 6 / grid LOD 7, 32 frames).

use rayon::prelude::*;
use rt_core::{frame::Frame, sampling::cosine_hemisphere, scene::SurfaceHit, Accel};
use rt_worldcache::glam::{Vec2, Vec3};
use rt_worldcache::hash::{pcg3_to_1, unit};
use rt_worldcache::CacheSpec;

/// The primary hit of a pixel, normals turned towards the camera.
struct Pixel {
    si: SurfaceHit,
    p: Vec3,
    n: Vec3,
    ng: Vec3,
}

fn ao_ray(accel: &dyn Accel, px: &Pixel, u: Vec2, dist: f32) -> f32 {
    let d = Frame::from_normal(px.n).to_world(cosine_hemisphere(u));
    if d.dot(px.ng) <= 0.0 {
        return 0.0;
    }
    if accel.occluded(&px.si.spawn_ray(d), dist) {
        0.0
    } else {
        1.0
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("rotated", String::as_str);
    let lod: u32 = args.get(2).map_or(Ok(6), |s| s.parse())?;
    let frames: u32 = args.get(3).map_or(Ok(32), |s| s.parse())?;
    let scene = rt_scene::procedural::generate(name)?;
    let accel = rt_accel::AccelSpec::default().build(&scene.triangles)?;
    let mut camera = scene.cameras[0].clone();
    (camera.width, camera.height) = (160, 120);
    let (w, h) = (camera.width, camera.height);
    let mut bounds = rt_core::Aabb::EMPTY;
    for t in &scene.triangles {
        for v in t {
            bounds = bounds.grown(*v);
        }
    }
    let extent = (bounds.max - bounds.min).max_element();
    let dist = 0.05 * extent;

    // Primary hits at pixel centres (fixed camera, as in the thesis' protocol).
    let pixels: Vec<Option<Pixel>> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let film = Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let ray = camera.generate_ray(film, Vec2::ZERO);
            let hit = accel.intersect(&ray, f32::INFINITY)?;
            let si = scene.surface(&hit, 0.0);
            let flip = if si.ng.dot(ray.dir) > 0.0 { -1.0 } else { 1.0 };
            Some(Pixel {
                si,
                p: si.p,
                n: si.ns * flip,
                ng: si.ng * flip,
            })
        })
        .collect();
    let reference: Vec<f32> = pixels
        .par_iter()
        .enumerate()
        .map(|(i, px)| {
            px.as_ref().map_or(1.0, |px| {
                let n = 256;
                (0..n)
                    .map(|k| {
                        let hsh = pcg3_to_1(i as u32, k, 0xabc);
                        let u = Vec2::new(unit(hsh), unit(rt_worldcache::hash::pcg(hsh)));
                        ao_ray(accel.as_ref(), px, u, dist)
                    })
                    .sum::<f32>()
                    / n as f32
            })
        })
        .collect();
    let rel_mse = |img: &[f32]| {
        img.iter()
            .zip(&reference)
            .map(|(a, r)| (a - r).powi(2) / (r * r + 1e-2))
            .sum::<f32>()
            / img.len() as f32
    };

    let mut caches = [
        (
            "implicit+bary",
            format!("worldspace:lod={lod}")
                .parse::<CacheSpec>()?
                .build(extent)?,
        ),
        (
            "grid+bary",
            format!("grid:lod={}", lod + 1)
                .parse::<CacheSpec>()?
                .build(extent)?,
        ),
        (
            "grid+jitter1",
            format!("grid:lod={},jitter=1", lod + 1)
                .parse::<CacheSpec>()?
                .build(extent)?,
        ),
    ];
    let mut accumulated = vec![0.0f32; (w * h) as usize];
    println!("scene {name}, {w}x{h}, AO distance {dist:.3}, s0 {extent:.3}, implicit LOD {lod}");
    println!(
        "frame  per-pixel  {}",
        caches.iter().map(|c| c.0).collect::<Vec<_>>().join("  ")
    );
    for f in 0..frames {
        let ao: Vec<Option<f32>> = pixels
            .par_iter()
            .enumerate()
            .map(|(i, px)| {
                px.as_ref().map(|px| {
                    let hsh = pcg3_to_1(i as u32, f, 0x51);
                    let u = Vec2::new(unit(hsh), unit(rt_worldcache::hash::pcg(hsh)));
                    ao_ray(accel.as_ref(), px, u, dist)
                })
            })
            .collect();
        for (a, v) in accumulated.iter_mut().zip(&ao) {
            *a += v.unwrap_or(1.0);
        }
        let mut line = format!("{:5}  {:9.4}", f + 1, {
            let mean: Vec<f32> = accumulated.iter().map(|a| a / (f + 1) as f32).collect();
            rel_mse(&mean)
        });
        for (_, cache) in caches.iter_mut() {
            pixels
                .par_iter()
                .zip(&ao)
                .enumerate()
                .for_each(|(i, (px, v))| {
                    if let (Some(px), Some(v)) = (px, v) {
                        let xi = pcg3_to_1(i as u32 % w, i as u32 / w, f);
                        cache.record(px.p, px.n, Vec3::splat(*v), xi);
                    }
                });
            cache.end_pass();
            let img: Vec<f32> = pixels
                .par_iter()
                .map(|px| {
                    px.as_ref().map_or(1.0, |px| {
                        cache.lookup(px.p, px.n).map_or(0.0, |l| l.value.x)
                    })
                })
                .collect();
            line += &format!("  {:13.4}", rel_mse(&img));
        }
        println!("{line}");
    }
    for (name, c) in &caches {
        println!(
            "{name}: {} entries of {} B ({} KiB used of {} KiB)",
            c.table().len(),
            rt_worldcache::ENTRY_BYTES,
            c.table().len() * rt_worldcache::ENTRY_BYTES / 1024,
            c.table().bytes() / 1024
        );
    }
    Ok(())
}
