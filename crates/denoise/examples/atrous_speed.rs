//! Filter-only timing of the À-Trous filter, the CPU counterpart of thesis Table 6.2: median
//! milliseconds over several runs at 512², 1024² and 1920×1080 for 0–3 edge-stopping weights
//! (none; colour; colour and normal; all three, as the thesis' Fig. 6.35) and 1, 5 and 10
//! iterations, on a synthetic noisy frame (the cost does not depend on the content). Each cell
//! is the median wall-clock time and, in brackets, the mean CPU time summed over all threads.
//!
//! `cargo run --release -p rt-denoise --example atrous_speed [-- RUNS [simd=off] [512] [one]]`; the
//! thread count is rayon's (set `RAYON_NUM_THREADS`).

use rt_core::glam::Vec3;
use rt_core::sampler::hash_u32;
use rt_core::{Image, Rgb};
use rt_denoise::{Denoiser, DenoiserSpec, NoisyFrame};
use std::time::Instant;

fn frame(w: usize, h: usize) -> NoisyFrame {
    let u = |x: usize, y: usize, k: u32| {
        hash_u32((y * w + x) as u32 ^ k.wrapping_mul(0x9e37_79b9)) as f32 / u32::MAX as f32
    };
    let mut f = NoisyFrame::new(Image::from_fn(w, h, |x, y| {
        Rgb::new(u(x, y, 1), u(x, y, 2), u(x, y, 3)) * 4.0
    }));
    f.normal = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(u(x, y, 4) - 0.5, u(x, y, 5) - 0.5, 1.0).normalize()
    }));
    f.position = Some(Image::from_fn(w, h, |x, y| {
        Vec3::new(x as f32, y as f32, u(x, y, 6) * 10.0) / w as f32
    }));
    f
}

/// CPU time of all this process's threads so far, in nanoseconds (Linux: the sum of
/// `/proc/self/task/*/schedstat`; 0 elsewhere). On a loaded machine it estimates the time the
/// filter would take alone better than the wall clock does.
fn cpu_ns() -> u64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

/// Median wall-clock milliseconds and mean CPU milliseconds (all threads) per run.
fn median_ms(d: &dyn Denoiser, f: &NoisyFrame, runs: usize) -> (f64, f64) {
    let cpu0 = cpu_ns();
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            let out = d.denoise(f).expect("frame has every channel");
            std::hint::black_box(out);
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let cpu = (cpu_ns() - cpu0) as f64 / 1e6 / runs as f64;
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], cpu)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let runs = args.first().and_then(|a| a.parse().ok()).unwrap_or(5);
    let simd = if args.iter().any(|a| a == "simd=off") {
        ":simd=off"
    } else {
        ""
    };
    if args.iter().any(|a| a == "one") {
        // The headline case only: 512², 5 iterations, 3 weights.
        let d = format!("atrous:demodulate=off{simd}").parse::<DenoiserSpec>();
        let d = d.and_then(|s| s.build()).expect("valid spec");
        let (wall, cpu) = median_ms(d.as_ref(), &frame(512, 512), runs);
        println!(
            "512x512, 5 iterations, 3 weights: {wall:.1} ms wall (median), {cpu:.1} ms CPU (mean, all threads)"
        );
        return;
    }
    let sizes: &[(usize, usize)] = if args.iter().any(|a| a == "512") {
        &[(512, 512)]
    } else {
        &[(512, 512), (1024, 1024), (1920, 1080)]
    };
    let weights = [
        "colour=off:normal=off:position=off",
        "colour=on:normal=off:position=off",
        "colour=on:normal=on:position=off",
        "colour=on:normal=on:position=on",
    ];
    println!(
        "threads {}, runs {runs}, median wall ms (mean CPU ms over all threads){}",
        rayon::current_num_threads(),
        if simd.is_empty() {
            ""
        } else {
            ", portable code"
        }
    );
    print!("| W |");
    for (w, h) in sizes {
        print!(" {w}x{h}: 1 / 5 / 10 |");
    }
    println!();
    println!("|---|{}", "---|".repeat(sizes.len()));
    let frames: Vec<NoisyFrame> = sizes.iter().map(|&(w, h)| frame(w, h)).collect();
    for (nw, wts) in weights.iter().enumerate() {
        print!("| {nw} |");
        for f in &frames {
            let ms: Vec<String> = [1, 5, 10]
                .iter()
                .map(|it| {
                    let spec = format!("atrous:iterations={it}:{wts}:demodulate=off{simd}");
                    let d = spec.parse::<DenoiserSpec>().and_then(|s| s.build());
                    let d = d.expect("valid spec");
                    let (wall, cpu) = median_ms(d.as_ref(), f, runs);
                    format!("{wall:.1} ({cpu:.1})")
                })
                .collect();
            print!(" {} |", ms.join(" / "));
        }
        println!();
    }
}
