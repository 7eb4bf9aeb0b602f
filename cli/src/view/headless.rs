//! `render view --headless`: the viewer's frames without a window, one animation frame per
//! rendered frame, through the scene camera, optionally within a per-frame time budget
//! (`rt_session::viewer::LiveView::run` renders them). Prints a line per frame (unless -q),
//! writes `-o` files (not counted in the frame time) and the run's summary: frames per second,
//! mean and worst frame time, mean spp per frame and, with a budget, how many frames overran
//! it.

use super::ViewArgs;
use anyhow::{anyhow, Context, Result};
use rt_film::OutputOptions;
use rt_session::frames::frame_path;
use rt_session::viewer::LiveView;

/// Renders `args.frames`.
pub fn run(args: &ViewArgs, mut view: LiveView) -> Result<()> {
    let path = view.path.display().to_string();
    let denoiser = view.denoiser.clone();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1000.0;
    let summary = view.run(args.frames.clone(), &mut |out, dt| {
        if let Some(pattern) = &args.output {
            let file = frame_path(pattern, out.frame);
            if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("{}: cannot create the directory", dir.display()))?;
            }
            let exposure = args.exposure;
            rt_film::write_rgb(&file, &out.image, &OutputOptions { exposure })?;
        }
        if !args.quiet {
            let t = out.times;
            println!(
                "{path}: frame {}: {} spp, {:.1} ms ({:.1} render, {:.1} guides, {:.1} {})",
                out.frame,
                out.spp,
                ms(dt),
                ms(t.render),
                ms(t.guides),
                ms(t.denoise),
                denoiser,
            );
        }
        Ok(())
    });
    let summary = summary.map_err(|e: anyhow::Error| anyhow!("{path}: {e}"))?;
    println!("{path}: {summary}");
    Ok(())
}
