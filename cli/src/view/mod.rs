//! `render view SCENE.toml`: the real-time mode (issue 14, seed 002's use case). A window
//! path traces the animated scene at a few samples per pixel per frame through
//! `rt_session::SequenceRenderer`, denoises with SVGF, plays the animation and orbits the
//! camera with the mouse; `--headless` renders a sequence, optionally within a per-frame time
//! budget, and reports frames per second.
//!
//! Files: `args.rs` (arguments and their checks), `window.rs` (winit event loop and softbuffer
//! drawing), `headless.rs` (the windowless loop's output and summary); this file loads the
//! scene into the `rt_session::viewer::LiveView` both drive (the orbit camera and the window
//! pixels are `rt_session::viewer` too).

mod args;
mod headless;
mod window;

pub use args::ViewArgs;

use anyhow::{anyhow, bail, Result};
use rt_accel::AccelSpec;
use rt_session::viewer::LiveView;
use rt_session::Overrides;
use rt_temporal::TemporalSpec;

/// Runs `render view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    args.check()?;
    let budget = args.budget()?;
    let size = args.size()?;
    if !args.headless {
        // Before the scene loads: without a display there is nothing to wait for.
        window::check_display()?;
    }
    let spp = args.spp.unwrap_or(if budget.is_some() {
        args::BUDGET_MAX_SPP
    } else {
        1
    });
    // The window follows the wall clock in milliseconds (frame f at f ms), so every frame has
    // its own number, and so its own sample streams, however fast frames come.
    let fps = if args.headless || args.step {
        args.fps
    } else {
        window::WALL_CLOCK_FPS
    };
    let mut view = load(args, spp, fps, size)?;
    view.set_budget(budget);
    if args.headless {
        headless::run(args, view)
    } else {
        window::run(args, view)
    }
}

/// The scene, the renderer and what they render: shared by the window and the headless loop.
/// The view the arguments ask for.
fn load(args: &ViewArgs, spp: u32, fps: f64, size: Option<(u32, u32)>) -> Result<LiveView> {
    let path = args.scene.clone();
    let loaded = rt_session::load_scene(&path, None, &[])?.loaded;
    if !args.quiet {
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
    }
    let accel = match &args.accel {
        Some(a) => Some(
            a.parse::<AccelSpec>()
                .map_err(|e| anyhow!("--accel {a}: {e}"))?,
        ),
        None => None,
    };
    let settings = Overrides {
        integrator: args.integrator,
        max_depth: args.max_depth,
        ao_distance: None,
        spp: Some(spp),
        threads: args.threads,
        seed: args.seed,
        accel,
        aovs: None,
        output: None,
        // The window's denoiser is its own `--denoiser` (temporal); `[render] denoiser`
        // is for still images.
        denoiser: Some("none".into()),
    }
    .resolve(&loaded, &path)?;
    let text = &args.denoiser;
    let denoiser = if text == "none" {
        None
    } else {
        let spec: TemporalSpec = text
            .parse()
            .map_err(|e| anyhow!("--denoiser {text}: {e}"))?;
        if !spec.is_temporal() {
            bail!(
                "--denoiser {text}: render view takes a temporal denoiser (svgf[:options]) or none"
            );
        }
        Some(
            spec.build()
                .map_err(|e| anyhow!("--denoiser {text}: {e}"))?,
        )
    };
    let camera = args.camera.clone();
    Ok(LiveView::new(
        &path,
        loaded.scene,
        &settings,
        denoiser,
        camera,
        size,
        fps,
    )?)
}
