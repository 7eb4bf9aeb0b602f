//! `render SCENE --spp B --gree [OPTIONS]`: one image denoised by GREE (`rt_session::gree`),
//! written with its label map and error maps when asked for, and a summary of where the
//! samples and the time went.

use crate::args::Args;
use crate::job::Job;
use anyhow::{anyhow, bail, Result};
use rt_core::{Image, Rgb, RgbImage};
use rt_denoise::Bank;
use rt_film::{write_rgb, OutputOptions};
use rt_integrators::{Ctx, Technique};
use rt_session::{parse_gree_options, render_gree, GreeRun};
use std::path::Path;

/// Renders `ctx` with GREE as `args` and `job` say and writes the outputs.
pub fn render(args: &Args, job: &Job, ctx: &Ctx<'_>, technique: &dyn Technique) -> Result<()> {
    let scene_path = job.scene_path.display();
    let Some(integrator) = technique.camera_integrator() else {
        bail!(
            "{scene_path}: --gree renders filter caches pixel by pixel, which the {} technique cannot (use wavefront, path, path-bsdf, direct or ao)",
            technique.name()
        );
    };
    if job.stop.is_some() {
        bail!("--gree spends a fixed budget (--spp); it cannot be combined with --error or --time-limit");
    }
    if job.settings.aovs != rt_film::AovSet::default() {
        bail!("--gree writes the composite only; save a noisy frame's AOVs with a render without --gree");
    }
    let text = args.gree.as_deref().unwrap_or_default();
    let params = parse_gree_options(text, job.settings.spp, job.settings.seed)
        .map_err(|e| anyhow!("{e}"))?;
    let bank = match &args.bank {
        Some(p) => Bank::from_file(p)?,
        None => Bank::default_gree()?,
    };
    let run = render_gree(ctx, integrator, &bank, &params, job.settings.seed, &|_| {})
        .map_err(|e| anyhow!("{scene_path}: {e}"))?;
    let opts = OutputOptions {
        exposure: job.exposure,
    };
    write_rgb(&job.output, &run.composite.image, &opts)?;
    let names: Vec<&str> = bank.members().iter().map(|m| m.name()).collect();
    if let Some(p) = &args.labels {
        write_labels(p, &run)?;
    }
    if let Some(dir) = &args.error_maps {
        write_error_maps(dir, &run, &names)?;
    }
    if !job.quiet {
        print_summary(job, &run, &names, args.labels.is_some());
    }
    Ok(())
}

/// A distinct colour per label (golden-angle hues), the same in the PNG and the legend.
fn label_colour(label: u16) -> Rgb {
    let h = (label as f32 * 0.618_034).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    // Linear values whose sRGB encoding is the saturated hue at 80 % value.
    Rgb::new(r, g, b) * 0.6
}

fn write_labels(path: &Path, run: &GreeRun) -> Result<()> {
    let (w, h) = run.frame.colour.size();
    let img = Image::new(
        w,
        h,
        run.composite
            .labels
            .iter()
            .map(|&l| label_colour(l))
            .collect(),
    )?;
    write_rgb(path, &img, &OutputOptions::default())?;
    Ok(())
}

/// Each filter's dense error map as EXR (the value in every channel) and as a false-colour PNG
/// on one log scale shared by all filters (1st to 99th percentile of all values), so that the
/// maps compare at a glance.
fn write_error_maps(dir: &Path, run: &GreeRun, names: &[&str]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow!("{}: {e}", dir.display()))?;
    let (w, h) = run.frame.colour.size();
    let mut all: Vec<f32> = run
        .composite
        .error_maps
        .iter()
        .flatten()
        .copied()
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    all.sort_by(f32::total_cmp);
    let at = |q: f64| {
        all.get(((all.len().saturating_sub(1)) as f64 * q) as usize)
            .copied()
            .unwrap_or(1.0)
    };
    let (lo, hi) = (at(0.01).max(1e-12).log10(), at(0.99).max(1e-12).log10());
    let span = (hi - lo).max(1e-6);
    for (i, (map, name)) in run.composite.error_maps.iter().zip(names).enumerate() {
        let file = format!("{i:02}-{}", name.replace([':', '=', '/'], "_"));
        let raw = RgbImage::new(w, h, map.iter().map(|&v| Rgb::splat(v)).collect())?;
        write_rgb(
            &dir.join(format!("{file}.exr")),
            &raw,
            &OutputOptions::default(),
        )?;
        let colour = raw.map(|v| {
            let t = (v.x.max(1e-12).log10() - lo) / span;
            rt_metrics::viridis(t as f64)
        });
        write_rgb(
            &dir.join(format!("{file}.png")),
            &colour,
            &OutputOptions::default(),
        )?;
    }
    Ok(())
}

fn print_summary(job: &Job, run: &GreeRun, names: &[&str], legend: bool) {
    let (w, h) = run.frame.colour.size();
    let pixels = (w * h) as f64;
    let b = run.budget;
    let t = &run.composite.timings;
    let bank: f64 = run.bank.times.iter().map(|d| d.as_secs_f64()).sum();
    let own = t.own().as_secs_f64();
    println!(
        "{}: {w}x{h} GREE b={} (n={} spp, {} caches x {} spp, s={}): {} samples traced ({:.2} spp), {:.2} s render, {:.2} s caches, {:.2} s bank ({} filters), {:.3} s GREE (placement {:.3}, errors {:.3}, interpolation {:.3}, graph cut {:.3}, fusion {:.3}; {:.1} % of denoising) -> {}",
        job.scene_path.display(),
        job.settings.spp,
        b.n,
        run.composite.caches.len(),
        b.c,
        b.sparsity,
        run.samples_traced(),
        run.samples_traced() as f64 / pixels,
        run.render.elapsed.as_secs_f64(),
        run.caches.elapsed.as_secs_f64(),
        bank,
        names.len(),
        own,
        t.placement.as_secs_f64(),
        t.errors.as_secs_f64(),
        t.interpolation.as_secs_f64(),
        t.graph_cut.as_secs_f64(),
        t.fusion.as_secs_f64(),
        100.0 * own / (own + bank).max(1e-12),
        job.output.display(),
    );
    let mut share = vec![0usize; names.len()];
    for &l in &run.composite.labels {
        share[l as usize] += 1;
    }
    for (i, name) in names.iter().enumerate() {
        let c = label_colour(i as u16)
            .to_array()
            .map(rt_core::color::linear_to_srgb);
        let hex = if legend {
            format!(
                " #{:02x}{:02x}{:02x}",
                (c[0] * 255.0) as u8,
                (c[1] * 255.0) as u8,
                (c[2] * 255.0) as u8
            )
        } else {
            String::new()
        };
        println!(
            "  label {i:2}{hex} {name}: {:.1} % of pixels, {:.3} s",
            100.0 * share[i] as f64 / pixels,
            run.bank.times[i].as_secs_f64()
        );
    }
}
