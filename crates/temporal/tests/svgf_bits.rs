//! The AVX2 and the portable code of SVGF give the same bits, and so do any thread counts, on
//! frames that exercise every path: diffuse, glossy, sharp glossy (with Eq. 6's Gaussian) and
//! mirror pixels, sky, object edges, motion, short and long histories.

use rt_core::glam::{Vec2, Vec3};
use rt_core::{Image, Rgb, RgbImage};
use rt_film::{GuideBuffers, ReflectedGuides};
use rt_temporal::{Svgf, SvgfInput, SvgfParams};

/// Deterministic uniform numbers in [0, 1).
fn hash(x: usize, y: usize, k: usize) -> f32 {
    let mut v = ((x as u64) * 0x9E37_79B9) ^ ((y as u64) << 20) ^ ((k as u64) << 40);
    v ^= v >> 33;
    v = v.wrapping_mul(0xff51_afd7_ed55_8ccd);
    v ^= v >> 33;
    (v >> 40) as f32 / (1u64 << 24) as f32
}

/// Frame `k` of a scene of tiles: each 8×8 tile one object with its own depth, normal and
/// roughness (sky, mirror, sharp glossy, glossy or diffuse), moving half a pixel a frame.
fn guides(w: usize, h: usize, k: usize) -> GuideBuffers {
    let tile = |x: usize, y: usize| (x / 8 + 7 * (y / 8)) % 11;
    let roughness = |t: usize| match t % 5 {
        0 => 0.0,
        1 => 0.2,
        2 => 0.6,
        _ => 1.0,
    };
    let sky = |t: usize| t == 10;
    let depth = |x: usize, y: usize| {
        let t = tile(x, y);
        if sky(t) {
            0.0
        } else {
            2.0 + t as f32 * 0.3 + 0.01 * x as f32 + 0.2 * hash(x, y, 99)
        }
    };
    let normal = |x: usize, y: usize| {
        let t = tile(x, y) as f32;
        Vec3::new(0.3 * (t * 0.7).sin(), 0.2 * hash(x, y, 5), 1.0).normalize()
    };
    let position = |x: usize, y: usize| Vec3::new(x as f32 * 0.05, y as f32 * 0.05, depth(x, y));
    GuideBuffers {
        depth: Image::from_fn(w, h, depth),
        position: Image::from_fn(w, h, position),
        normal: Image::from_fn(w, h, normal),
        albedo: Image::from_fn(w, h, |x, y| {
            Rgb::new(0.2 + 0.6 * hash(x, y, 1), 0.5, 0.1 + 0.8 * hash(y, x, 2))
        }),
        emission: Image::filled(w, h, Rgb::ZERO),
        motion: Image::from_fn(w, h, |x, y| {
            Vec2::new(0.5 + 0.25 * (tile(x, y) % 3) as f32, -0.3 + 0.1 * k as f32)
        }),
        previous_depth: Image::from_fn(w, h, depth),
        object: Image::from_fn(w, h, |x, y| tile(x, y) as u32),
        instance: Image::from_fn(w, h, |x, y| tile(x, y) as u32),
        roughness: Image::from_fn(w, h, |x, y| roughness(tile(x, y))),
        reflected: Some(ReflectedGuides {
            position: Image::from_fn(w, h, |x, y| {
                position(x, y) + Vec3::new(0.1 * k as f32, 1.0 + hash(x, y, 3), 0.5)
            }),
            normal: Image::from_fn(w, h, |x, y| normal(y, x)),
            distance: Image::from_fn(w, h, |x, y| {
                if sky(tile(x, y)) || hash(x, y, 4) < 0.1 {
                    0.0
                } else {
                    1.0 + hash(x, y, 6)
                }
            }),
            albedo: Image::from_fn(w, h, |x, y| Rgb::splat(0.3 + 0.5 * hash(x, y, 7))),
            emission: Image::from_fn(w, h, |x, y| Rgb::splat((hash(x, y, 9) - 0.8).max(0.0))),
            direction: Image::from_fn(w, h, |x, y| {
                Vec3::new(hash(x, y, 8) - 0.5, 1.0, 0.2 * k as f32).normalize()
            }),
        }),
    }
}

fn noisy(w: usize, h: usize, k: usize, salt: usize) -> RgbImage {
    Image::from_fn(w, h, |x, y| {
        let n = hash(x, y, 10 * k + salt);
        Rgb::new(n, n * n, 0.5 * hash(y, x, k + salt)) * if n > 0.97 { 40.0 } else { 1.0 }
    })
}

/// The outputs of six frames.
fn run(params: &SvgfParams, simd: bool, threads: usize, w: usize, h: usize) -> Vec<Vec<u32>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut svgf = Svgf::new(params.clone()).with_simd(simd);
        (0..6)
            .map(|k| {
                let g = guides(w, h, k);
                let (direct, indirect) = (noisy(w, h, k, 1), noisy(w, h, k, 2));
                let emission = Image::from_fn(w, h, |x, y| Rgb::splat(0.1 * hash(x, y, 11)));
                let out = svgf.push(&SvgfInput {
                    guides: &g,
                    direct: &direct,
                    indirect: &indirect,
                    emission: &emission,
                });
                out.pixels()
                    .iter()
                    .flat_map(|p| p.to_array().map(f32::to_bits))
                    .collect()
            })
            .collect()
    })
}

#[test]
fn simd_and_portable_code_give_the_same_bits() {
    // Widths that are and are not whole vectors; both presets (σ_n = 64 and 128).
    for (w, h) in [(45, 37), (64, 24)] {
        for params in [SvgfParams::default(), SvgfParams::schied()] {
            let portable = run(&params, false, 2, w, h);
            let simd = run(&params, true, 2, w, h);
            for (k, (a, b)) in portable.iter().zip(&simd).enumerate() {
                let diff = a.iter().zip(b).filter(|(a, b)| a != b).count();
                assert_eq!(diff, 0, "{w}x{h}, frame {k}: {diff} values differ");
            }
        }
    }
    let uses = Svgf::new(SvgfParams::default()).uses_simd();
    println!("AVX2 code ran: {uses}");
}

#[test]
fn an_odd_normal_exponent_takes_the_same_path_in_both() {
    let params = SvgfParams {
        sigma_n: 3.0,
        ..SvgfParams::default()
    };
    assert_eq!(
        run(&params, false, 2, 40, 24),
        run(&params, true, 2, 40, 24)
    );
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let params = SvgfParams::default();
    let one = run(&params, true, 1, 45, 37);
    assert_eq!(one, run(&params, true, 3, 45, 37));
    assert_eq!(one, run(&params, false, 2, 45, 37));
}
