//! The viewer's window: a winit event loop (X11) drawing through softbuffer.
//!
//! Each redraw renders one frame and shows it, then asks for the next (at most `--fps-cap` a
//! second). The animation follows the wall clock by default: frame `f` is `f` milliseconds
//! after the start ([`WALL_CLOCK_FPS`]), advanced by at least one per rendered frame so every
//! frame has its own sample streams; with `--step` each rendered frame is the next animation
//! frame at `--fps`. The animation plays once and holds its last pose; `R` restarts it (and the
//! denoiser's history). Until the mouse first drags or zooms, the view follows the scene's
//! (possibly animated) camera; from then on it is the orbit (`rt_session::viewer::orbit`),
//! which starts from the scene camera as it was at that moment. Left drag turns about the look-at point, the wheel
//! zooms, `Escape`/`Q` or closing the window quits. The title shows frames per second.

use super::ViewArgs;
use anyhow::{anyhow, bail, Result};
use rt_session::viewer::display::blit;
use rt_session::viewer::LiveView;
use std::num::NonZeroU32;
use std::rc::Rc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Animation frames per second when following the wall clock: one per millisecond.
pub const WALL_CLOCK_FPS: f64 = 1000.0;
/// How often the title's frame rate is refreshed.
const TITLE_EVERY: Duration = Duration::from_millis(500);
/// Pixels per wheel line for touchpads that scroll in pixels.
const PIXELS_PER_LINE: f32 = 40.0;

/// Fails with one line when there is no X display to open (this build of winit speaks X11
/// only; Wayland sessions provide one through XWayland).
pub fn check_display() -> Result<()> {
    if std::env::var_os("DISPLAY").is_none_or(|d| d.is_empty()) {
        let wayland = std::env::var_os("WAYLAND_DISPLAY").is_some_and(|d| !d.is_empty());
        bail!(
            "render view needs an X11 display and DISPLAY is not set{}; use --headless to render without a window",
            if wayland {
                " (WAYLAND_DISPLAY is, but this build speaks X11 only: XWayland sets DISPLAY)"
            } else {
                ""
            }
        );
    }
    Ok(())
}

/// Opens the window and runs until it closes.
pub fn run(args: &ViewArgs, view: LiveView) -> Result<()> {
    let display = std::env::var("DISPLAY").unwrap_or_default();
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!("render view: cannot open X display {display}: {e}; use --headless to render without a window")
    })?;
    let mut app = App::new(args, view);
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("render view: {e}"))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// What the window shows: softbuffer's surface over the window.
type Surface = softbuffer::Surface<Rc<Window>, Rc<Window>>;

struct App<'a> {
    args: &'a ViewArgs,
    view: LiveView,
    window: Option<(Rc<Window>, Surface)>,
    dragging: bool,
    cursor: Option<PhysicalPosition<f64>>,
    last_frame_at: Option<Instant>,
    /// Frames and time since the title last changed.
    counted: (u32, Instant),
    error: Option<anyhow::Error>,
}

impl<'a> App<'a> {
    fn new(args: &'a ViewArgs, mut view: LiveView) -> Self {
        view.set_stepping(args.step);
        App {
            args,
            view,
            window: None,
            dragging: false,
            cursor: None,
            last_frame_at: None,
            counted: (0, Instant::now()),
            error: None,
        }
    }

    fn title(&self, fps: Option<f64>) -> String {
        format!("render view: {}", self.view.status(fps))
    }

    /// Renders the next frame and shows it.
    fn draw(&mut self) -> Result<()> {
        self.last_frame_at = Some(Instant::now());
        let out = self.view.render_next()?;
        let Some((window, surface)) = &mut self.window else {
            return Ok(());
        };
        let size = window.inner_size();
        let (Some(sw), Some(sh)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height))
        else {
            return Ok(()); // minimised
        };
        surface
            .resize(sw, sh)
            .map_err(|e| anyhow!("render view: {e}"))?;
        let mut buffer = surface
            .buffer_mut()
            .map_err(|e| anyhow!("render view: {e}"))?;
        blit(
            out.image.pixels(),
            (out.image.width(), out.image.height()),
            &mut buffer,
            (size.width as usize, size.height as usize),
            self.args.exposure,
        );
        buffer.present().map_err(|e| anyhow!("render view: {e}"))?;
        self.counted.0 += 1;
        let since = self.counted.1.elapsed();
        if since >= TITLE_EVERY {
            let fps = f64::from(self.counted.0) / since.as_secs_f64();
            let title = self.title(Some(fps));
            if let Some((window, _)) = &self.window {
                window.set_title(&title);
            }
            self.counted = (0, Instant::now());
        }
        Ok(())
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.error = Some(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let (w, h) = self.view.size;
        let attributes = Window::default_attributes()
            .with_title(self.title(None))
            .with_inner_size(PhysicalSize::new(w, h))
            .with_resizable(false);
        let made = event_loop
            .create_window(attributes)
            .map_err(|e| anyhow!("render view: cannot open a window: {e}"))
            .and_then(|window| {
                let window = Rc::new(window);
                let context = softbuffer::Context::new(window.clone())
                    .map_err(|e| anyhow!("render view: {e}"))?;
                let surface = softbuffer::Surface::new(&context, window.clone())
                    .map_err(|e| anyhow!("render view: {e}"))?;
                Ok((window, surface))
            });
        match made {
            Ok((window, surface)) => {
                window.request_redraw();
                self.window = Some((window, surface));
                self.view.restart();
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        logical_key,
                        state: ElementState::Pressed,
                        ..
                    },
                ..
            } => {
                match logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Character(c) if c.eq_ignore_ascii_case("q") => event_loop.exit(),
                    Key::Character(c) if c.eq_ignore_ascii_case("r") => {
                        self.view.restart();
                    }
                    _ => {}
                }
                Ok(())
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                let moved = self.cursor.replace(position);
                match moved {
                    Some(from) if self.dragging => {
                        let (dx, dy) = (position.x - from.x, position.y - from.y);
                        self.view.drag(dx as f32, dy as f32).map_err(Into::into)
                    }
                    _ => Ok(()),
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / PIXELS_PER_LINE,
                };
                self.view.zoom(lines).map_err(Into::into)
            }
            WindowEvent::RedrawRequested => self.draw(),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some((window, _)) = &self.window else {
            return;
        };
        let due = match (self.args.fps_cap, self.last_frame_at) {
            (Some(cap), Some(at)) => Some(at + Duration::from_secs_f64(1.0 / cap)),
            _ => None,
        };
        match due {
            Some(due) if Instant::now() < due => {
                event_loop.set_control_flow(ControlFlow::WaitUntil(due));
            }
            _ => {
                event_loop.set_control_flow(ControlFlow::Wait);
                window.request_redraw();
            }
        }
    }
}
