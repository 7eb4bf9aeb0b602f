//! `render view --headless`: the viewer's frames without a window, one animation frame per
//! rendered frame, through the scene camera; optionally within a per-frame time budget
//! (`SequenceRenderer::set_budget`). Prints a line per frame (unless -q) and a summary:
//! frames per second, mean and worst frame time, mean spp per frame and, with a budget, how
//! many frames overran it. Frame time is the wall-clock time of moving the scene and
//! rendering, guiding and denoising the frame; writing `-o` files is not counted.

use super::{View, ViewArgs};
use anyhow::{Context, Result};
use rt_film::OutputOptions;
use rt_session::frames::frame_path;
use std::time::{Duration, Instant};

/// Renders `args.frames`.
pub fn run(args: &ViewArgs, mut view: View, budget: Option<Duration>) -> Result<()> {
    let path = view.path.display().to_string();
    let mut times = Vec::with_capacity(args.frames.len());
    let mut spp_sum = 0u64;
    for f in args.frames.clone() {
        let t = Instant::now();
        let camera = view.scene_camera(f)?;
        let out = view.render(f, &camera)?;
        let dt = t.elapsed();
        times.push(dt);
        spp_sum += u64::from(out.spp);
        if let Some(pattern) = &args.output {
            let file = frame_path(pattern, f);
            if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("{}: cannot create the directory", dir.display()))?;
            }
            rt_film::write_rgb(
                &file,
                &out.image,
                &OutputOptions {
                    exposure: args.exposure,
                },
            )?;
        }
        if !args.quiet {
            println!(
                "{path}: frame {f}: {} spp, {:.1} ms ({:.1} render, {:.1} guides, {:.1} {})",
                out.spp,
                ms(dt),
                ms(out.times.render),
                ms(out.times.guides),
                ms(out.times.denoise),
                view.denoiser,
            );
        }
    }
    let n = times.len() as f64;
    let total: Duration = times.iter().sum();
    let worst = times.iter().max().copied().unwrap_or_default();
    let (w, h) = view.size;
    let mut line = format!(
        "{path}: {} frames {w}x{h}, {}: {:.2} frames per second; frame time mean {:.1} ms, worst {:.1} ms; mean {:.2} spp per frame",
        times.len(),
        view.denoiser,
        n / total.as_secs_f64().max(1e-9),
        ms(total) / n,
        ms(worst),
        spp_sum as f64 / n,
    );
    match budget {
        Some(b) => {
            let over = times.iter().filter(|t| **t > b).count();
            line.push_str(&format!(
                "; {over} of {} frames over the {:.1} ms budget",
                times.len(),
                ms(b)
            ));
        }
        None => line.push_str("; no budget"),
    }
    println!("{line}");
    Ok(())
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}
