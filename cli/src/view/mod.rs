//! `render view SCENE.toml`: the real-time mode (issue 14, seed 002's use case). A window
//! path traces the animated scene at a few samples per pixel per frame through
//! `rt_session::SequenceRenderer`, denoises with SVGF, plays the animation and orbits the
//! camera with the mouse; `--headless` renders a sequence, optionally within a per-frame time
//! budget, and reports frames per second.
//!
//! Files: `args.rs` (arguments and their checks), `orbit.rs` (orbit camera maths),
//! `tonemap.rs` (linear RGB to window pixels), `window.rs` (winit event loop and softbuffer
//! drawing), `headless.rs` (the windowless loop and its summary); this file loads the scene
//! and builds the renderer both share.

mod args;
mod headless;
mod orbit;
mod tonemap;
mod window;

pub use args::ViewArgs;

use anyhow::{anyhow, bail, Result};
use rt_accel::AccelSpec;
use rt_core::{Camera, Scene};
use rt_session::{pick_camera, Overrides, SequenceFrame, SequenceRenderer};
use rt_temporal::TemporalSpec;
use std::path::PathBuf;

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
    let mut view = View::load(args, spp, fps, size)?;
    view.renderer.set_budget(budget);
    if args.headless {
        headless::run(args, view)
    } else {
        window::run(args, view)
    }
}

/// The scene, the renderer and what they render: shared by the window and the headless loop.
pub struct View {
    /// The scene file, for messages.
    pub path: PathBuf,
    scene: Scene,
    renderer: SequenceRenderer,
    camera: Option<String>,
    /// Image size.
    pub size: (u32, u32),
    /// Samples per pixel per frame (the most, with a budget).
    pub spp: u32,
    /// The denoiser's name, or "none".
    pub denoiser: String,
    pool: rayon::ThreadPool,
}

impl View {
    fn load(args: &ViewArgs, spp: u32, fps: f64, size: Option<(u32, u32)>) -> Result<View> {
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
        let scene = loaded.scene;
        let camera = pick_camera(&scene, &path, args.camera.as_deref())?;
        let size = size.unwrap_or((camera.width, camera.height));
        let text = &args.denoiser;
        let denoiser = if text == "none" {
            None
        } else {
            let spec: TemporalSpec = text
                .parse()
                .map_err(|e| anyhow!("--denoiser {text}: {e}"))?;
            if !spec.is_temporal() {
                bail!("--denoiser {text}: render view takes a temporal denoiser (svgf[:options]) or none");
            }
            Some(
                spec.build()
                    .map_err(|e| anyhow!("--denoiser {text}: {e}"))?,
            )
        };
        let denoiser_name = denoiser
            .as_ref()
            .map_or("none".to_string(), |d| d.name().to_string());
        let renderer = SequenceRenderer::new(
            settings.integrator.build(),
            settings.accel,
            denoiser,
            args.camera.clone(),
            settings.spp,
            settings.seed,
            fps,
        )
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
        let pool = rt_session::job::thread_pool(settings.threads)?;
        Ok(View {
            path,
            scene,
            renderer,
            camera: args.camera.clone(),
            size,
            spp: settings.spp,
            denoiser: denoiser_name,
            pool,
        })
    }

    /// The scene's camera at frame `f`'s time, at the view's size.
    pub fn scene_camera(&mut self, f: u32) -> Result<Camera> {
        self.scene.set_time(self.renderer.time_of(f));
        let c = pick_camera(&self.scene, &self.path, self.camera.as_deref())?;
        Ok(c.resized(self.size.0, self.size.1))
    }

    /// Renders frame `f` through `camera`.
    pub fn render(&mut self, f: u32, camera: &Camera) -> Result<SequenceFrame> {
        let (renderer, scene) = (&mut self.renderer, &mut self.scene);
        self.pool
            .install(|| renderer.render_with(scene, f, Some(camera)))
            .map_err(|e| anyhow!("{}: frame {f}: {e}", self.path.display()))
    }

    /// Renders `frames` one after another through the scene camera at the view's size
    /// (`rt_session::SequenceRenderer::run`), calling `each` with every frame and its time.
    pub fn run(
        &mut self,
        frames: std::ops::Range<u32>,
        each: &mut (dyn FnMut(&SequenceFrame, std::time::Duration) -> Result<()> + Send),
    ) -> Result<rt_session::RunSummary> {
        let (renderer, scene, size) = (&mut self.renderer, &mut self.scene, Some(self.size));
        let path = self.path.display().to_string();
        self.pool
            .install(|| renderer.run(scene, frames, size, each))
            .map_err(|e: anyhow::Error| anyhow!("{path}: {e}"))
    }

    /// Forgets the denoiser's history (the animation restarts).
    pub fn reset(&mut self) {
        self.renderer.reset();
    }

    /// The time of frame `f` in seconds.
    pub fn time_of(&self, f: u32) -> f32 {
        self.renderer.time_of(f)
    }
}
