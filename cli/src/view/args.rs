//! Arguments of `render view`, and the checks clap cannot make (each a one-line error).

use anyhow::{bail, Result};
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of `render view`.
#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// The animated scene (TOML).
    #[arg(value_name = "SCENE.toml")]
    pub scene: PathBuf,

    /// Samples per pixel per frame (not the scene's `[render] spp`: the viewer is real-time).
    /// With --frame-budget: the most 1-spp passes a frame takes [default there: 64].
    #[arg(long)]
    pub spp: Option<u32>,

    /// Temporal denoiser and its options, svgf[:key=value...] (docs/denoising.md), or none
    /// for the noisy frames.
    #[arg(long, value_name = "svgf[:options]|none", default_value = "svgf")]
    pub denoiser: String,

    /// Image size WxH (the window shows it 1:1). [default: the scene camera's resolution]
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,

    /// Most frames per second the window renders (it sleeps between frames).
    /// [default: no cap]
    #[arg(long, value_name = "N")]
    pub fps_cap: Option<f64>,

    /// Advance the animation one frame (1 / --fps seconds) per rendered frame instead of
    /// following the wall clock (the default in the window). --headless always steps.
    #[arg(long)]
    pub step: bool,

    /// Frames per second of the animation: frame f is at time f / fps (with --step and
    /// --headless).
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,

    /// Exposure in stops before the sRGB tone mapping (the PNG rule of `render`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,

    /// Camera by name. [default: the scene's first]
    #[arg(long)]
    pub camera: Option<String>,

    /// Light transport, as `render --integrator` [default: path].
    #[arg(long, value_name = "SPEC", value_parser = crate::args::parse_integrator)]
    pub integrator: Option<rt_integrators::IntegratorSpec>,

    /// Maximum bounces. [default: `[render] max_depth`, else 16]
    #[arg(long)]
    pub max_depth: Option<u32>,

    /// Acceleration structure, as `render --accel`. [default: the one `render` picks]
    #[arg(long, value_name = "SPEC")]
    pub accel: Option<String>,

    /// Worker threads. [default: all cores]
    #[arg(long)]
    pub threads: Option<usize>,

    /// Seed of the sample streams.
    #[arg(long)]
    pub seed: Option<u64>,

    /// Render without a window: the frames of --frames, each within --frame-budget if given,
    /// then print frames per second, mean and worst frame time, mean spp and overruns.
    #[arg(long)]
    pub headless: bool,

    /// With --headless: frames A..B (half-open).
    #[arg(long, value_name = "A..B", value_parser = crate::args::parse_frames, default_value = "0..60", requires = "headless")]
    pub frames: std::ops::Range<u32>,

    /// With --headless: per-frame time budget in milliseconds. A frame renders one 1-spp pass,
    /// then more while the last pass's time says the next fits the budget minus the previous
    /// frame's guide and denoise time (docs/real-time.md). Frames are then not deterministic.
    #[arg(
        long,
        value_name = "MS",
        allow_hyphen_values = true,
        requires = "headless"
    )]
    pub frame_budget: Option<String>,

    /// With --headless: write each frame, e.g. 'out/f_{frame:04}.png' (.png or .exr).
    #[arg(short, long, requires = "headless")]
    pub output: Option<PathBuf>,

    /// With --headless: only the summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Most passes a budgeted frame takes when --spp does not say.
pub const BUDGET_MAX_SPP: u32 = 64;

impl ViewArgs {
    /// `--frame-budget` as a duration: a positive, finite number of milliseconds.
    pub fn budget(&self) -> Result<Option<Duration>> {
        let Some(text) = &self.frame_budget else {
            return Ok(None);
        };
        match text.trim().parse::<f64>() {
            Ok(ms) if ms.is_finite() && ms > 0.0 && ms <= 3.6e6 => {
                Ok(Some(Duration::from_secs_f64(ms / 1000.0)))
            }
            _ => bail!(
                "--frame-budget must be a positive number of milliseconds (at most an hour), got `{text}`"
            ),
        }
    }

    /// `--size` as (width, height), if given.
    pub fn size(&self) -> Result<Option<(u32, u32)>> {
        let Some(s) = &self.size else {
            return Ok(None);
        };
        let (w, h) = rt_session::split_size(s).ok_or_else(|| {
            anyhow::anyhow!("--size must be WIDTHxHEIGHT such as 256x256, got `{s}`")
        })?;
        rt_session::ImageSize::Pixels(w, h).validate("--size")?;
        Ok(Some((w, h)))
    }

    /// The other checks: fps, cap, exposure, spp, output pattern.
    pub fn check(&self) -> Result<()> {
        rt_session::job::check_fps(self.fps)?;
        if let Some(cap) = self.fps_cap {
            if !(cap.is_finite() && cap > 0.0) {
                bail!("--fps-cap must be a positive number of frames per second, got {cap}");
            }
        }
        if !self.exposure.is_finite() {
            bail!("--exposure must be a finite number");
        }
        if self.spp == Some(0) {
            bail!("--spp must be at least 1");
        }
        if let Some(out) = &self.output {
            if !rt_session::frames::names_frame(out) {
                bail!(
                    "{}: -o must name the frame, e.g. -o 'out/f_{{frame:04}}.png'",
                    out.display()
                );
            }
            let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("");
            if !["png", "exr"].iter().any(|e| ext.eq_ignore_ascii_case(e)) {
                bail!("{}: output must end in .png or .exr", out.display());
            }
        }
        Ok(())
    }
}
