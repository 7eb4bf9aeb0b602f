//! SBMF benchmark on `scenes/dof.toml` (Bauszat thesis ch. 4, claims 13–14 of the seed-000
//! digest): renders 4 spp with per-sample records and a high-spp reference, runs SBMF, and
//! prints the MSE reduction and SSIM against the reference, then the depth-of-field step's
//! time (and summed-area-table lookups) for a maximum CoC of 4, 8 and 16 pixels.
//!
//! ```text
//! cargo run --release -p rt-denoise --example sbmf -- [--size 256x192] [--ref-spp 1024]
//!     [--spp 4] [--timing-size 512x384] [--repeats 5] [--out DIR] [--params k=v:k=v]
//!     [--ref-cache FILE.exr] [--no-timing | --timing-only]
//! ```
//!
//! The quality run and the timing run are separate renders: the reference costs
//! `ref-spp × pixels` samples, so it is taken at the smaller `--size`; the timing uses the
//! scene's full resolution. `--params` takes SBMF options in spec syntax
//! (`manifolds=7:sigma_spatial=12`). `--out` writes noisy, SBMF and reference PNGs.
//! `--ref-cache` reads the reference from an EXR of the right size if there is one, and
//! writes it there after rendering otherwise (the cache does not know the spp or the scene:
//! delete it when they change). `--no-timing` stops after the quality run, `--timing-only`
//! skips it (e.g. to count step B's instructions under callgrind).

use rt_denoise::{Options, Sbmf};
use rt_film::{AovSet, FilmBuffers, OutputOptions};
use rt_integrators::PathIntegrator;
use rt_testkit::{Renderer, SceneExt};
use std::time::Instant;

fn size(s: &str) -> (u32, u32) {
    let (w, h) = s.split_once('x').expect("size is WxH");
    (w.parse().expect("width"), h.parse().expect("height"))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |name: &str, default: &str| -> String {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
            .unwrap_or_else(|| default.to_string())
    };
    let (w, h) = size(&arg("--size", "256x192"));
    let (tw, th) = size(&arg("--timing-size", "512x384"));
    let ref_spp: u32 = arg("--ref-spp", "1024").parse().expect("--ref-spp");
    let spp: u32 = arg("--spp", "4").parse().expect("--spp");
    let repeats: usize = arg("--repeats", "5").parse().expect("--repeats");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1));
    let mut o = Options::of("sbmf", &arg("--params", "")).unwrap_or_else(|e| panic!("{e}"));
    let sbmf = Sbmf::from_options(&mut o).and_then(|s| o.finish().map(|_| s).map_err(Into::into));
    let sbmf = sbmf.unwrap_or_else(|e| panic!("{e}"));
    println!("{}", sbmf.name());
    let integrator = PathIntegrator::new(5);
    let base = rt_testkit::shipped_scene("dof.toml");

    if !args.iter().any(|a| a == "--timing-only") {
        quality(&args, &sbmf, &integrator, &base, (w, h), spp, ref_spp, out);
    }
    if args.iter().any(|a| a == "--no-timing") {
        return;
    }
    timing(&sbmf, &integrator, base, (tw, th), spp, repeats);
}

/// MSE and SSIM of the noisy image, SBMF and step A alone against the reference.
#[allow(clippy::too_many_arguments)]
fn quality(
    args: &[String],
    sbmf: &Sbmf,
    integrator: &PathIntegrator,
    base: &rt_core::Scene,
    (w, h): (u32, u32),
    spp: u32,
    ref_spp: u32,
    out: Option<&String>,
) {
    let scene = base.clone().with_resolution(w, h);
    let r = Renderer::new(&scene);
    let t = Instant::now();
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_samples();
    let (mut film, _) = r.render(integrator, buffers, spp, 1);
    let render_s = t.elapsed().as_secs_f64();
    let records = film.take_sample_records().expect("records kept");
    let noisy = rt_core::Image::new(w as usize, h as usize, film.mean_image()).expect("size");
    let t = Instant::now();
    let cache = args
        .iter()
        .position(|a| a == "--ref-cache")
        .and_then(|i| args.get(i + 1));
    let cached = cache
        .and_then(|c| rt_film::read_rgb(std::path::Path::new(c)).ok())
        .filter(|i| i.size() == (w as usize, h as usize));
    let reference = match cached {
        Some(img) => img,
        None => {
            let (film, _) = r.render(integrator, AovSet::default(), ref_spp, 2);
            let img = rt_core::Image::new(w as usize, h as usize, film.mean_image()).expect("size");
            if let Some(c) = cache {
                rt_film::write_rgb(std::path::Path::new(c), &img, &OutputOptions::default())
                    .expect("write the reference cache");
            }
            img
        }
    };
    let ref_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (colour, a_stats) = sbmf
        .step_a(&records, w as usize, h as usize)
        .expect("step A");
    let a_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (filtered, b_stats) = sbmf
        .step_b(&records, &colour, w as usize, h as usize)
        .expect("step B");
    let b_s = t.elapsed().as_secs_f64();
    let mse_in = rt_metrics::mse(&noisy, &reference).expect("mse");
    let mse_out = rt_metrics::mse(&filtered, &reference).expect("mse");
    let ssim_in = rt_metrics::ssim(&noisy, &reference).expect("ssim");
    let ssim_out = rt_metrics::ssim(&filtered, &reference).expect("ssim");
    println!(
        "quality at {w}x{h}: {spp} spp ({} samples, {:.1} MB of records) rendered in {render_s:.2} s, reference {ref_spp} spp in {ref_s:.1} s",
        records.len(),
        records.memory_bytes() as f64 / 1e6
    );
    println!(
        "  step A {a_s:.3} s ({} fallbacks), step B {b_s:.3} s (tau {:.2} px, {} layers)",
        a_stats.fallbacks, b_stats.tau, b_stats.layers
    );
    println!(
        "  MSE noisy {mse_in:.6} -> SBMF {mse_out:.6}: {:.1}% lower; SSIM noisy {ssim_in:.4} -> SBMF {ssim_out:.4}",
        100.0 * (1.0 - mse_out / mse_in)
    );
    // Step A alone (a pixel mean of its colours), to separate the two steps' effects.
    let step_a_img = rt_core::Image::from_fn(w as usize, h as usize, |x, y| {
        let range = records.pixel_range(y * w as usize + x);
        let n = range.len().max(1) as f32;
        colour[range].iter().copied().sum::<rt_core::Rgb>() / n
    });
    println!(
        "  step A alone: MSE {:.6}, SSIM {:.4}",
        rt_metrics::mse(&step_a_img, &reference).expect("mse"),
        rt_metrics::ssim(&step_a_img, &reference).expect("ssim")
    );
    if let Some(dir) = out {
        let dir = std::path::Path::new(dir);
        std::fs::create_dir_all(dir).expect("out dir");
        let o = OutputOptions::default();
        for (name, img) in [
            ("noisy", &noisy),
            ("sbmf", &filtered),
            ("step-a", &step_a_img),
            ("reference", &reference),
        ] {
            rt_film::write_rgb(&dir.join(format!("dof-{name}.png")), img, &o).expect("write");
        }
    }
}

/// Step B's time and SAT lookups for a maximum CoC of 4, 8 and 16 pixels.
fn timing(
    sbmf: &Sbmf,
    integrator: &PathIntegrator,
    base: rt_core::Scene,
    (tw, th): (u32, u32),
    spp: u32,
    repeats: usize,
) {
    let scene = base.with_resolution(tw, th);
    let r = Renderer::new(&scene);
    let buffers = FilmBuffers::for_outputs(AovSet::default()).with_samples();
    let (mut film, _) = r.render(integrator, buffers, spp, 1);
    let records = film.take_sample_records().expect("records kept");
    let (colour, _) = sbmf
        .step_a(&records, tw as usize, th as usize)
        .expect("step A");
    println!("DoF step at {tw}x{th}, {spp} spp, min of {repeats} runs:");
    // The radii are interleaved within each round, so that a change of machine load during
    // the measurement hits all three alike; each keeps its fastest run.
    let taus = [4.0f32, 8.0, 16.0];
    let filters: Vec<Sbmf> = taus
        .iter()
        .map(|&tau| {
            let mut p = sbmf.params().clone();
            p.max_coc = tau;
            Sbmf::new(p).expect("params")
        })
        .collect();
    let mut times = vec![f64::INFINITY; taus.len()];
    let mut lookups = vec![0; taus.len()];
    for _ in 0..repeats {
        for (k, s) in filters.iter().enumerate() {
            let t = Instant::now();
            let (_, st) = s
                .step_b(&records, &colour, tw as usize, th as usize)
                .expect("step B");
            times[k] = times[k].min(t.elapsed().as_secs_f64());
            lookups[k] = st.sat_lookups;
        }
    }
    for (k, tau) in taus.iter().enumerate() {
        println!(
            "  max CoC {tau:>4} px: {:.2} ms, {} SAT lookups",
            times[k] * 1e3,
            lookups[k]
        );
    }
    let (lo, hi) = times
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    println!("  spread (max/min - 1): {:.1}%", 100.0 * (hi / lo - 1.0));
}
