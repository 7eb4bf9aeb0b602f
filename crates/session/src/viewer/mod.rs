//! What an interactive viewer of an animated scene needs besides its window: [`LiveView`]
//! (the scene, a [`SequenceRenderer`] and its thread pool, rendering frame `f` from the scene's
//! camera or a given one), the [`orbit`] camera a mouse turns, and [`display`], linear RGB
//! packed and scaled into a window's `0x00RRGGBB` pixels by the PNG rule. `render view` is one
//! client (its window and its headless loop); the window toolkit stays with the caller.

pub mod display;
pub mod orbit;

use orbit::Orbit;

use crate::{pick_camera, RunSummary, SequenceError, SequenceFrame, SequenceRenderer};
use crate::{JobError, SessionError, Settings};
use rt_core::{Camera, Scene};
use rt_temporal::TemporalDenoiser;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Why a live view could not start or render a frame. One line naming the scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ViewError {
    /// No such camera.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The thread pool could not start.
    #[error(transparent)]
    Job(#[from] JobError),
    /// The renderer refused its settings or failed on a frame.
    #[error("{}: {}{source}", path.display(), frame.map_or(String::new(), |f| format!("frame {f}: ")))]
    Sequence {
        /// The scene file.
        path: PathBuf,
        /// The frame, if one was rendering.
        frame: Option<u32>,
        /// Why.
        #[source]
        source: SequenceError,
    },
}

/// An animated scene being rendered frame by frame at a fixed size.
pub struct LiveView {
    /// The scene file (for messages).
    pub path: PathBuf,
    scene: Scene,
    renderer: SequenceRenderer,
    camera: Option<String>,
    /// The frame size.
    pub size: (u32, u32),
    /// Samples per pixel per frame (the cap when a time budget is set).
    pub spp: u32,
    /// The temporal denoiser's name, or `none`.
    pub denoiser: String,
    pool: rayon::ThreadPool,
    /// What the interactive loop has done so far.
    live: Live,
}

/// The interactive state: where the animation is and whether the mouse took the camera.
struct Live {
    /// Frame numbers follow each other (`true`) or the wall clock in milliseconds since
    /// `started` (frame f at f ms, so every frame has its own number and sample streams).
    step: bool,
    /// When the animation (re)started.
    started: Instant,
    /// The last frame rendered.
    frame: Option<u32>,
    /// Samples the last frame took.
    last_spp: u32,
    /// `None` while the view follows the scene camera.
    orbit: Option<Orbit>,
}

impl LiveView {
    /// The view of `scene` (loaded from `path`) with `settings` through `camera` (the first by
    /// default) at `size` (the camera's by default), frame `f` at time `f / fps`.
    pub fn new(
        path: &Path,
        scene: Scene,
        settings: &Settings,
        denoiser: Option<Box<dyn TemporalDenoiser>>,
        camera: Option<String>,
        size: Option<(u32, u32)>,
        fps: f64,
    ) -> Result<Self, ViewError> {
        let picked = pick_camera(&scene, path, camera.as_deref())?;
        let size = size.unwrap_or((picked.width, picked.height));
        let denoiser_name = denoiser
            .as_ref()
            .map_or("none".to_string(), |d| d.name().to_string());
        let renderer = SequenceRenderer::new(
            settings.integrator.build(),
            settings.accel,
            denoiser,
            camera.clone(),
            settings.spp,
            settings.seed,
            fps,
        )
        .map_err(|source| ViewError::Sequence {
            path: path.to_path_buf(),
            frame: None,
            source,
        })?;
        let pool = crate::job::thread_pool(settings.threads)?;
        Ok(Self {
            path: path.to_path_buf(),
            scene,
            renderer,
            camera,
            size,
            spp: settings.spp,
            denoiser: denoiser_name,
            pool,
            live: Live {
                step: false,
                started: Instant::now(),
                frame: None,
                last_spp: 0,
                orbit: None,
            },
        })
    }

    /// Stops each frame's sampling after `budget` (at most [`LiveView::spp`] samples).
    pub fn set_budget(&mut self, budget: Option<Duration>) {
        self.renderer.set_budget(budget);
    }

    /// The scene's own camera at frame `f`, at the view's size.
    pub fn scene_camera(&mut self, f: u32) -> Result<Camera, ViewError> {
        self.scene.set_time(self.renderer.time_of(f));
        let c = pick_camera(&self.scene, &self.path, self.camera.as_deref())?;
        Ok(c.resized(self.size.0, self.size.1))
    }

    /// Frame `f` seen through `camera`.
    pub fn render(&mut self, f: u32, camera: &Camera) -> Result<SequenceFrame, ViewError> {
        let (renderer, scene) = (&mut self.renderer, &mut self.scene);
        self.pool
            .install(|| renderer.render_with(scene, f, Some(camera)))
            .map_err(|source| ViewError::Sequence {
                path: self.path.clone(),
                frame: Some(f),
                source,
            })
    }

    /// Frames `frames` through the scene's camera, each handed to `each` with its time
    /// ([`SequenceRenderer::run`]).
    pub fn run<E: From<SequenceError> + Send>(
        &mut self,
        frames: Range<u32>,
        each: &mut (dyn FnMut(&SequenceFrame, Duration) -> Result<(), E> + Send),
    ) -> Result<RunSummary, E> {
        let (renderer, scene, size) = (&mut self.renderer, &mut self.scene, Some(self.size));
        self.pool
            .install(|| renderer.run(scene, frames, size, each))
    }

    /// Forgets the history (after a jump in time or a camera move).
    pub fn reset(&mut self) {
        self.renderer.reset();
    }

    /// Interactive frames follow each other (`true`) or the wall clock in milliseconds.
    pub fn set_stepping(&mut self, step: bool) {
        self.live.step = step;
    }

    /// Starts the animation again from frame 0 with no history.
    pub fn restart(&mut self) {
        self.reset();
        self.live.frame = None;
        self.live.started = Instant::now();
    }

    /// The next interactive frame number: one after the last, or the wall clock's if later.
    fn next_frame(&self) -> u32 {
        let after = self.live.frame.map_or(0, |f| f.saturating_add(1));
        if self.live.step {
            return after;
        }
        let ms = self
            .live
            .started
            .elapsed()
            .as_millis()
            .min(u128::from(u32::MAX)) as u32;
        ms.max(after)
    }

    /// Renders the next interactive frame through the orbit camera, or the scene's while the
    /// mouse has not taken it.
    pub fn render_next(&mut self) -> Result<SequenceFrame, ViewError> {
        let f = self.next_frame();
        let scene_camera = self.scene_camera(f)?;
        let (w, h) = self.size;
        let camera = match &self.live.orbit {
            Some(o) => o.camera(&scene_camera, w, h),
            None => scene_camera,
        };
        let out = self.render(f, &camera)?;
        self.live.frame = Some(f);
        self.live.last_spp = out.spp;
        Ok(out)
    }

    /// The orbit, starting from the scene camera as it is now the first time it is needed.
    fn orbit(&mut self) -> Result<Orbit, ViewError> {
        if let Some(o) = self.live.orbit {
            return Ok(o);
        }
        let c = self.scene_camera(self.live.frame.unwrap_or(0))?;
        Ok(Orbit::from_camera(&c))
    }

    /// Turns the orbit camera by a drag of `dx`, `dy` pixels.
    pub fn drag(&mut self, dx: f32, dy: f32) -> Result<(), ViewError> {
        self.live.orbit = Some(self.orbit()?.dragged(dx, dy));
        Ok(())
    }

    /// Zooms the orbit camera by `lines` wheel lines.
    pub fn zoom(&mut self, lines: f32) -> Result<(), ViewError> {
        self.live.orbit = Some(self.orbit()?.zoomed(lines));
        Ok(())
    }

    /// One line for a window title: the scene's file name, `fps` (measured by the caller),
    /// samples per pixel, denoiser and animation time.
    pub fn status(&self, fps: Option<f64>) -> String {
        let name = self
            .path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let fps = fps.map_or_else(|| "-".to_string(), |f| format!("{f:.1}"));
        let time = self.time_of(self.live.frame.unwrap_or(0));
        format!(
            "{name}: {fps} fps, {} spp, {}, t = {time:.2} s",
            self.live.last_spp.max(self.spp),
            self.denoiser
        )
    }

    /// The time of frame `f`.
    pub fn time_of(&self, f: u32) -> f32 {
        self.renderer.time_of(f)
    }
}
