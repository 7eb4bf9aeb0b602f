//! Times `rt_denoise::Oidn` (our FFI to Open Image Denoise) on one frame, for comparison with
//! `tools/oidn/pyoidn_denoise.py` on the same EXR; prints one JSON line like that script's.
//!
//! ```text
//! cargo run --release -p rt-denoise --features oidn --example oidn_time -- \
//!     IN.exr|synthetic:WxH [--out OUT.exr] [--save-input IN.exr] [--spec oidn:...] [--repeat N]
//! ```
//! `synthetic:WxH` is a noisy checkerboard with albedo and normals (content does not change
//! OIDN's time); `--save-input` writes it so the Python script can read the same frame.
//! Times: `load_s` loading the library and creating the device, `first_s` the first frame
//! (builds the network), `runs_s` further frames with the cached filter.

use rt_core::glam::Vec3;
use rt_core::{Image, Rgb};
use rt_denoise::{DenoiserSpec, NoisyFrame};
use std::path::PathBuf;
use std::time::Instant;

fn synthetic(w: usize, h: usize) -> NoisyFrame {
    let mut state = 0x853c_49e6_748f_ea9bu64;
    let mut rnd = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let albedo = Image::from_fn(w, h, |x, y| {
        if (x / 16 + y / 16) % 2 == 0 {
            Rgb::new(0.8, 0.7, 0.6)
        } else {
            Rgb::new(0.1, 0.15, 0.2)
        }
    });
    let colour = Image::from_fn(w, h, |x, y| {
        let light = 0.5 + 1.5 * (x + y) as f32 / (w + h) as f32;
        albedo.pixel(x, y) * light * (2.0 * rnd())
    });
    let mut f = NoisyFrame::new(colour);
    f.albedo = Some(albedo);
    f.normal = Some(Image::filled(w, h, Vec3::Z));
    f
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let input = args
        .next()
        .ok_or("usage: oidn_time IN.exr|synthetic:WxH [options]")?;
    let (mut out, mut save, mut spec, mut repeat) = (None, None, "oidn".to_string(), 3usize);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--out" => out = Some(PathBuf::from(value()?)),
            "--save-input" => save = Some(PathBuf::from(value()?)),
            "--spec" => spec = value()?,
            "--repeat" => repeat = value()?.parse()?,
            _ => return Err(format!("unknown argument {a}").into()),
        }
    }
    let frame = match input.strip_prefix("synthetic:") {
        Some(size) => {
            let (w, h) = size.split_once('x').ok_or("synthetic:WxH")?;
            synthetic(w.parse()?, h.parse()?)
        }
        None => NoisyFrame::from_exr(input.as_ref())?,
    };
    if let Some(p) = &save {
        frame.write_exr(p, &[])?;
    }
    let t = Instant::now();
    let denoiser = spec.parse::<DenoiserSpec>()?.build()?;
    let load_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut img = denoiser.denoise(&frame)?;
    let first_s = t.elapsed().as_secs_f64();
    let mut runs = Vec::new();
    for _ in 0..repeat {
        let t = Instant::now();
        img = denoiser.denoise(&frame)?;
        runs.push(t.elapsed().as_secs_f64());
    }
    if let Some(p) = &out {
        NoisyFrame::new(img).write_exr(p, &[])?;
    }
    let mut sorted = runs.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(first_s);
    println!(
        "{{\"denoiser\": \"{}\", \"input\": \"{input}\", \"width\": {}, \"height\": {}, \
         \"load_s\": {load_s}, \"first_s\": {first_s}, \"runs_s\": {runs:?}, \"median_s\": {median}}}",
        denoiser.name(),
        frame.width(),
        frame.height()
    );
    Ok(())
}
