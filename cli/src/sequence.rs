//! `render SCENE --frames A..B --denoiser svgf[:options] -o 'f_{frame:04}.exr'`: a sequence
//! rendered frame after frame through `rt_session::SequenceRenderer`, so a temporal denoiser
//! sees the frames in order and carries its history; one line per frame.

use crate::args::Args;
use crate::frame_pattern::frame_path;
use crate::job::Job;
use anyhow::{anyhow, bail, Context, Result};
use rt_core::Scene;
use rt_film::{AovSet, OutputOptions};
use rt_session::SequenceRenderer;
use rt_temporal::TemporalSpec;
use std::time::Instant;

/// The parsed `--denoiser` if it is a temporal one (SVGF); `None` for per-frame denoisers
/// (and for the scene's `[render] denoiser`, always one), which the plain render path runs.
pub fn temporal_spec(job: &Job) -> Result<Option<TemporalSpec>> {
    let Some(text) = &job.settings.denoiser else {
        return Ok(None);
    };
    let spec: TemporalSpec = text
        .parse()
        .map_err(|e| anyhow!("--denoiser {text}: {e}"))?;
    Ok(spec.is_temporal().then_some(spec))
}

/// Renders the frames of `job` with the temporal denoiser `spec`.
pub fn run(
    args: &Args,
    job: &Job,
    spec: &TemporalSpec,
    scene: &mut Scene,
    frames: &[Option<u32>],
) -> Result<()> {
    let text = job.settings.denoiser.as_deref().unwrap_or_default();
    let path = job.scene_path.display();
    if job.settings.aovs != AovSet::default() {
        bail!("--denoiser {text} writes the denoised image only; save noisy frames' AOVs with a render without it");
    }
    if job.stop.is_some() {
        bail!("--denoiser {text}: a sequence renders a fixed number of samples per frame (--spp); --error and --time-limit do not apply");
    }
    if args.shutter != 0.0 {
        bail!("--denoiser {text}: its guide buffers describe one instant; motion blur (--shutter) would not match them");
    }
    let denoiser = spec
        .build()
        .map_err(|e| anyhow!("--denoiser {text}: {e}"))?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = job.settings.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("cannot start worker threads")?;
    // One cache for the sequence, as for a plain job: it carries over from frame to frame.
    let cache = crate::cache::for_job(args.cache.as_deref(), &job.settings.integrator, scene)?;
    let mut renderer = SequenceRenderer::new(
        crate::cache::technique(&job.settings.integrator, cache)?,
        job.settings.accel,
        Some(denoiser),
        job.camera.clone(),
        job.settings.spp,
        job.settings.seed,
        args.fps,
    )
    .map_err(|e| anyhow!("{path}: --denoiser {text}: {e}"))?;
    let started = Instant::now();
    for f in frames {
        let frame = f.unwrap_or(0);
        let out = pool
            .install(|| renderer.render(scene, frame))
            .map_err(|e| anyhow!("{path}: frame {frame}: {e}"))?;
        let output = match f {
            Some(f) => frame_path(&job.output, *f),
            None => job.output.clone(),
        };
        rt_film::write_rgb(
            &output,
            &out.image,
            &OutputOptions {
                exposure: job.exposure,
            },
        )?;
        if !job.quiet {
            let t = out.times;
            println!(
                "{path}: frame {frame}: {}x{} {} spp {}, {:.3} s render, {:.3} s guides, {:.3} s {}, {:.3} s update -> {}",
                out.image.width(),
                out.image.height(),
                job.settings.spp,
                job.settings.integrator,
                t.render.as_secs_f64(),
                t.guides.as_secs_f64(),
                t.denoise.as_secs_f64(),
                renderer.denoiser_name().unwrap_or_default(),
                t.update.as_secs_f64(),
                output.display()
            );
        }
    }
    if !job.quiet && frames.len() > 1 {
        let secs = started.elapsed().as_secs_f64();
        println!(
            "{path}: {} frames in {secs:.2} s ({:.2} frames per second)",
            frames.len(),
            frames.len() as f64 / secs
        );
    }
    Ok(())
}
