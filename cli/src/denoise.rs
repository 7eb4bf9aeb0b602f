//! `render denoise IN.exr --denoiser NAME[:options] -o OUT`: one denoiser applied to a saved
//! frame (an EXR written by `render --aov ...`), so a denoising experiment never re-renders.
//! The frame's channels are read bit for bit (`rt_film::NoisyFrame::from_exr`); the denoiser
//! is named as everywhere else (`rt_denoise::DenoiserSpec`).

use anyhow::{anyhow, Result};
use rt_denoise::{DenoiseError, DenoiserSpec, NoisyFrame};
use rt_film::{write_rgb, OutputOptions};
use std::path::PathBuf;
use std::time::Instant;

/// `render denoise` arguments.
#[derive(clap::Args, Debug)]
pub struct DenoiseArgs {
    /// The noisy frame: an EXR written by `render SCENE --aov ... -o F.exr` (`--aov denoise`
    /// writes every channel any denoiser reads).
    #[arg(value_name = "IN.exr")]
    pub input: PathBuf,

    /// The denoiser and its options, e.g. `atrous`, `gaussian:sigma=4`, `box:radius=2`.
    #[arg(long, value_name = "NAME[:options]")]
    pub denoiser: String,

    /// Where to write the result (.exr linear, or .png tone mapped).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,

    /// PNG exposure in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
}

/// Runs `render denoise`.
pub fn run(args: &DenoiseArgs) -> Result<()> {
    let spec: DenoiserSpec = args
        .denoiser
        .parse()
        .map_err(|e: DenoiseError| anyhow!("--denoiser {}: {e}", args.denoiser))?;
    let denoiser = spec
        .build()
        .map_err(|e| anyhow!("--denoiser {}: {e}", args.denoiser))?;
    let frame = NoisyFrame::from_exr(&args.input)?;
    let start = Instant::now();
    let out = denoiser
        .denoise(&frame)
        .map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    let elapsed = start.elapsed();
    let opts = OutputOptions {
        exposure: args.exposure,
    };
    write_rgb(&args.output, &out, &opts)?;
    println!(
        "{} ({}x{}) denoised by {} in {:.1} ms -> {}",
        args.input.display(),
        frame.width(),
        frame.height(),
        denoiser.name(),
        elapsed.as_secs_f64() * 1e3,
        args.output.display()
    );
    Ok(())
}
