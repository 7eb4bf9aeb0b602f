//! Rendering an animation frame after frame, with a denoiser that may remember earlier frames:
//! what `render --frames`, `render view` and sequence experiments share.
//!
//! Per frame: the scene moves to the frame's time, the structure follows (in place when it
//! can, rebuilt otherwise), the integrator renders the frame's samples into a film that keeps
//! only what the denoiser reads, the guide pass describes every pixel's primary hit and its
//! motion since the previous frame (only for denoisers that read guides), and the denoiser
//! filters it. A temporal denoiser's sample 0 of every pixel goes through the pixel centre, so
//! it is the ray the guide buffers describe.
//!
//! **Time budget** ([`SequenceRenderer::set_budget`], `render view --frame-budget`): the
//! frame's samples are then rendered as 1-spp passes, indices `0..1`, `1..2`, ..., into one
//! film, which gives the same bits as one pass `0..n` (`SamplePass`). The first pass always
//! runs; pass `k + 1` runs while `spent + last + reserve <= budget`, where `spent` is the time
//! since the frame started (the update included), `last` the duration of pass `k` and
//! `reserve` the previous frame's guide and denoise time (the stages still to come; zero on
//! the first frame), and never beyond `spp` passes. How many passes fit depends on the clock,
//! so budgeted frames are not deterministic; without a budget they are.

use crate::following::FollowingAccel;
use crate::settings::frame_seed;
use rt_accel::AccelSpec;
use rt_core::{Camera, RgbImage, SampleStream, Scene};
use rt_film::{AovSet, Film, FilmBuffers, GuideBuffers, NoisyFrame};
use rt_integrators::{
    render_guides, Ctx, GuideOptions, PreviousView, RenderStats, SamplePass, Technique,
};
use rt_temporal::{TemporalDenoiser, TemporalError, TemporalFrame, EXTRA_SAMPLE_CHANNELS};
use std::ops::Range;
use std::time::{Duration, Instant};

/// Why a sequence cannot be rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SequenceError {
    /// The structure cannot be built over the scene.
    #[error("--accel {accel}: {message}")]
    Accel {
        /// The structure asked for.
        accel: String,
        /// Why.
        message: String,
    },
    /// No camera of that name (after the scene moved to the frame's time).
    #[error("no camera named \"{0}\"")]
    NoCamera(String),
    /// The denoiser reads the lighting split and the technique does not write it.
    #[error("{denoiser} reads the lighting split (direct, indirect, emission), which the {technique} technique does not write")]
    SplitUnsupported {
        /// The denoiser.
        denoiser: String,
        /// The technique.
        technique: String,
    },
    /// The denoiser failed on a frame.
    #[error(transparent)]
    Denoise(#[from] TemporalError),
}

/// How long each stage of a frame took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// Moving the scene and the structure to the frame's time.
    pub update: Duration,
    /// Rendering the samples.
    pub render: Duration,
    /// The guide pass.
    pub guides: Duration,
    /// The denoiser.
    pub denoise: Duration,
}

impl FrameTimes {
    /// All stages together.
    pub fn total(&self) -> Duration {
        self.update + self.render + self.guides + self.denoise
    }
}

/// One rendered frame.
#[derive(Debug)]
pub struct SequenceFrame {
    /// Frame number.
    pub frame: u32,
    /// The image: denoised if there is a denoiser, else the film's mean.
    pub image: RgbImage,
    /// The noisy frame the denoiser read (its colour is the film's mean).
    pub noisy: NoisyFrame,
    /// The guide buffers, if the denoiser reads them or [`SequenceRenderer::set_guides`] asked
    /// for them.
    pub guides: Option<GuideBuffers>,
    /// Samples 1, 2, ... of every pixel as one-sample frames, when the denoiser samples with
    /// guide rays at several samples per pixel ([`TemporalFrame::extra`]); empty otherwise.
    pub extra: Vec<NoisyFrame>,
    /// Samples and rays of the render.
    pub stats: RenderStats,
    /// Stage times.
    pub times: FrameTimes,
    /// Samples per pixel rendered (fewer than the renderer's `spp` when a time budget stopped
    /// the passes early).
    pub spp: u32,
}

/// How a run of frames went ([`SequenceRenderer::run`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// Each frame's wall-clock time.
    pub times: Vec<Duration>,
    /// Samples per pixel of all frames together.
    pub spp: u64,
    /// Image size.
    pub size: (u32, u32),
    /// The denoiser's name, or `none`.
    pub denoiser: String,
    /// The per-frame time budget, if any.
    pub budget: Option<Duration>,
}

impl std::fmt::Display for RunSummary {
    /// Frames per second, mean and worst frame time, mean spp per frame and, with a budget,
    /// how many frames overran it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1000.0;
        let n = self.times.len().max(1) as f64;
        let total: Duration = self.times.iter().sum();
        let worst = self.times.iter().max().copied().unwrap_or_default();
        let (w, h) = self.size;
        write!(
            f,
            "{} frames {w}x{h}, {}: {:.2} frames per second; frame time mean {:.1} ms, worst {:.1} ms; mean {:.2} spp per frame",
            self.times.len(),
            self.denoiser,
            self.times.len() as f64 / total.as_secs_f64().max(1e-9),
            ms(total) / n,
            ms(worst),
            self.spp as f64 / n,
        )?;
        match self.budget {
            Some(b) => {
                let over = self.times.iter().filter(|t| **t > b).count();
                let frames = self.times.len();
                write!(
                    f,
                    "; {over} of {frames} frames over the {:.1} ms budget",
                    ms(b)
                )
            }
            None => f.write_str("; no budget"),
        }
    }
}

/// A sequence being rendered: the structure, the denoiser's memory and the previous view carry
/// from frame to frame.
pub struct SequenceRenderer {
    technique: Box<dyn Technique>,
    structure: FollowingAccel,
    denoiser: Option<Box<dyn TemporalDenoiser>>,
    aovs: AovSet,
    guide_options: GuideOptions,
    camera: Option<String>,
    spp: u32,
    seed: u32,
    fps: f64,
    previous: Option<(Camera, f32)>,
    budget: Option<Duration>,
    /// Render the guide pass even when the denoiser does not read it.
    always_guides: bool,
    /// The last frame's guide and denoise time: what a budgeted frame keeps free for them.
    reserve: Duration,
}

impl SequenceRenderer {
    /// A renderer of `spp` samples per pixel per frame with `technique` over `accel`, the
    /// camera named `camera` (the scene's first without one), frame `f` at time `f / fps`, its
    /// samples from [`frame_seed`]`(seed, f)`, denoised by `denoiser` if given.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        technique: Box<dyn Technique>,
        accel: AccelSpec,
        denoiser: Option<Box<dyn TemporalDenoiser>>,
        camera: Option<String>,
        spp: u32,
        seed: u32,
        fps: f64,
    ) -> Result<Self, SequenceError> {
        let aovs = denoiser
            .as_ref()
            .map_or(AovSet::default(), |d| AovSet::for_channels(d.needs()));
        if let Some(d) = &denoiser {
            if aovs.any_split() && !technique.writes_split() {
                return Err(SequenceError::SplitUnsupported {
                    denoiser: d.name().to_string(),
                    technique: technique.name().to_string(),
                });
            }
        }
        Ok(Self {
            technique,
            structure: FollowingAccel::new(accel),
            denoiser,
            aovs,
            guide_options: GuideOptions::default(),
            camera,
            spp: spp.max(1),
            seed,
            fps,
            previous: None,
            budget: None,
            always_guides: false,
            reserve: Duration::ZERO,
        })
    }

    /// Renders every later frame within `budget` (`None`: always `spp` samples per pixel), as
    /// the module documentation describes; `spp` is then the most passes a frame takes.
    pub fn set_budget(&mut self, budget: Option<Duration>) {
        self.budget = budget;
    }

    /// Renders the guide pass for every frame (`SequenceFrame::guides`) whether or not the
    /// denoiser reads it: an experiment measures every method over the same regions (the
    /// specular pixels) with it. It does not change the images.
    pub fn set_guides(&mut self, always: bool) {
        self.always_guides = always;
    }

    /// The denoiser's name, if any.
    pub fn denoiser_name(&self) -> Option<&str> {
        self.denoiser.as_deref().map(|d| d.name())
    }

    /// Forgets the previous frames (the next frame starts a new history).
    pub fn reset(&mut self) {
        self.previous = None;
        if let Some(d) = &mut self.denoiser {
            d.reset();
        }
    }

    /// The time of frame `f`.
    pub fn time_of(&self, f: u32) -> f32 {
        (f64::from(f) / self.fps) as f32
    }

    /// Renders frame `f` of `scene` (moving it to the frame's time).
    pub fn render(&mut self, scene: &mut Scene, f: u32) -> Result<SequenceFrame, SequenceError> {
        self.render_with(scene, f, None)
    }

    /// Renders frames `frames` of `scene` one after another through the scene's camera at
    /// each frame's time, at `size` if given (`render view --headless`), calling `each` with
    /// every frame and its wall-clock time (moving the scene, rendering, guiding and
    /// denoising; not what `each` does). Returns the run's timings.
    pub fn run<E: From<SequenceError>>(
        &mut self,
        scene: &mut Scene,
        frames: Range<u32>,
        size: Option<(u32, u32)>,
        each: &mut dyn FnMut(&SequenceFrame, Duration) -> Result<(), E>,
    ) -> Result<RunSummary, E> {
        let mut run = RunSummary {
            denoiser: self.denoiser_name().unwrap_or("none").to_string(),
            budget: self.budget,
            ..RunSummary::default()
        };
        for f in frames {
            let t = Instant::now();
            scene.set_time(self.time_of(f));
            let camera = (scene.camera(self.camera.as_deref()))
                .ok_or_else(|| SequenceError::NoCamera(self.camera.clone().unwrap_or_default()))?;
            let (w, h) = size.unwrap_or((camera.width, camera.height));
            let camera = camera.resized(w, h);
            let out = self.render_with(scene, f, Some(&camera))?;
            let dt = t.elapsed();
            run.size = (w, h);
            run.times.push(dt);
            run.spp += u64::from(out.spp);
            each(&out, dt)?;
        }
        Ok(run)
    }

    /// Renders frame `f` seen by `camera` instead of the scene's (an interactive viewer's
    /// orbit), at `camera`'s resolution.
    pub fn render_with(
        &mut self,
        scene: &mut Scene,
        f: u32,
        camera: Option<&Camera>,
    ) -> Result<SequenceFrame, SequenceError> {
        let mut times = FrameTimes::default();
        let frame_start = Instant::now();
        let t = frame_start;
        let time = self.time_of(f);
        scene.set_time(time);
        self.structure
            .follow(rt_accel::BuildInput::SceneToReorder(scene))
            .map_err(|e| SequenceError::Accel {
                accel: self.structure.spec().to_string(),
                message: e.to_string(),
            })?;
        times.update = t.elapsed();
        let camera = match camera {
            Some(c) => c.clone(),
            None => scene
                .camera(self.camera.as_deref())
                .cloned()
                .ok_or_else(|| {
                    SequenceError::NoCamera(self.camera.clone().unwrap_or_else(|| "(none)".into()))
                })?,
        };
        let accel = self.structure.current().expect("followed above");
        let ctx = Ctx {
            scene,
            accel,
            camera: &camera,
        };
        let wants_guides = self.denoiser.as_ref().is_some_and(|d| d.needs_guides());
        let t = Instant::now();
        // A guide-sampling denoiser at several samples per pixel gets sample 0 (the guide
        // ray) in the frame and every further sample as a one-sample frame of its own.
        let apart = wants_guides
            && self.spp > 1
            && self.denoiser.as_ref().is_some_and(|d| d.guide_samples());
        let mut film = Film::new(
            camera.width,
            camera.height,
            FilmBuffers::for_outputs(self.aovs),
        );
        let (stats, extra, spp) =
            self.render_samples(&ctx, &mut film, f, wants_guides, apart, frame_start);
        times.render = t.elapsed();
        let t = Instant::now();
        let guides = (wants_guides || self.always_guides).then(|| {
            let previous = self.previous.as_ref().map(|(c, time)| PreviousView {
                camera: c,
                time: *time,
            });
            render_guides(&ctx, previous.as_ref(), &self.guide_options)
        });
        times.guides = t.elapsed();
        let mut noisy = NoisyFrame::from_film(&film, self.aovs);
        if !extra.is_empty() {
            // The noisy image is the mean of all the frame's samples, as without the split.
            let n = 1.0 + extra.len() as f32;
            for (i, c) in noisy.colour.pixels_mut().iter_mut().enumerate() {
                let sum: rt_core::Rgb = extra.iter().map(|e| e.colour.pixels()[i]).sum();
                *c = (*c + sum) / n;
            }
        }
        let t = Instant::now();
        let image = match &mut self.denoiser {
            Some(d) => d.push(&TemporalFrame {
                frame: &noisy,
                guides: guides.as_ref(),
                extra: &extra,
            })?,
            None => noisy.colour.clone(),
        };
        times.denoise = t.elapsed();
        self.reserve = times.guides + times.denoise;
        self.previous = Some((camera, time));
        Ok(SequenceFrame {
            frame: f,
            image,
            noisy,
            guides,
            extra,
            stats,
            times,
            spp,
        })
    }

    /// The frame's samples: sample 0 (or all of them) into `film`; with `apart`, every
    /// further sample into a one-sample frame of its own (returned, for the denoiser). Without
    /// a budget the film's samples go in one pass; with one, 1-spp passes while the next fits
    /// (the rule in the module documentation). The stats of all passes together and how many
    /// samples per pixel ran.
    fn render_samples(
        &self,
        ctx: &Ctx<'_>,
        film: &mut Film,
        f: u32,
        centre_first: bool,
        apart: bool,
        frame_start: Instant,
    ) -> (RenderStats, Vec<NoisyFrame>, u32) {
        let seed = frame_seed(self.seed, f);
        let pass = |film: &mut Film, indices: Range<u32>, centre_first| {
            let pass = SamplePass {
                indices,
                stream: SampleStream::Render,
                pixels: None,
                centre_first,
            };
            self.technique.render_pass(ctx, film, seed, &pass, &|_| {})
        };
        let step = if apart || self.budget.is_some() {
            1
        } else {
            self.spp
        };
        let extra_aovs = AovSet::for_channels(&EXTRA_SAMPLE_CHANNELS);
        let mut total = RenderStats::default();
        let mut extra = Vec::new();
        let mut done = 0;
        while done < self.spp {
            let t = Instant::now();
            let indices = done..done + step;
            total += if apart && done > 0 {
                let mut one = Film::new(
                    ctx.camera.width,
                    ctx.camera.height,
                    FilmBuffers::for_outputs(extra_aovs),
                );
                let stats = pass(&mut one, indices, false);
                extra.push(NoisyFrame::from_film(&one, extra_aovs));
                stats
            } else {
                pass(film, indices, centre_first)
            };
            done += step;
            let last = t.elapsed();
            if self
                .budget
                .is_some_and(|budget| frame_start.elapsed() + last + self.reserve > budget)
            {
                break;
            }
        }
        (total, extra, done)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rt_core::Rgb;
    use rt_integrators::IntegratorSpec;
    use rt_temporal::TemporalSpec;
    use std::path::Path;

    /// A small moving scene at a small resolution: the shared lit floor with a moving ball.
    pub(crate) fn moving_ball() -> String {
        format!(
            "{}{}",
            rt_testkit::scenes::LIT_FLOOR,
            r#"
            [[geometry]]
            name = "ball"
            shape = "sphere"
            center = [0, 0.3, 0]
            radius = 0.3
            material = "white"
            [[animation]]
            target = "ball"
            keys = [ { time = 0.0 }, { time = 1.0, translate = [0.5, 0, 0] } ]
        "#
        )
    }

    fn scene() -> Scene {
        rt_scene::load_str(&moving_ball(), Path::new("."), Path::new("test.toml"))
            .unwrap()
            .scene
    }

    fn renderer(spp: u32, budget: Option<Duration>) -> SequenceRenderer {
        let technique = "path".parse::<IntegratorSpec>().unwrap().build();
        let svgf = "svgf".parse::<TemporalSpec>().unwrap().build().unwrap();
        let mut r = SequenceRenderer::new(
            technique,
            AccelSpec::default(),
            Some(svgf),
            None,
            spp,
            7,
            24.0,
        )
        .unwrap();
        r.set_budget(budget);
        r
    }

    /// Three frames' (spp, noisy colour, denoised image).
    fn frames(spp: u32, budget: Option<Duration>) -> Vec<(u32, Vec<Rgb>, Vec<Rgb>)> {
        let mut scene = scene();
        let mut r = renderer(spp, budget);
        (0..3)
            .map(|f| {
                let out = r.render(&mut scene, f).unwrap();
                let noisy = out.noisy.colour.pixels().to_vec();
                (out.spp, noisy, out.image.pixels().to_vec())
            })
            .collect()
    }

    #[test]
    fn a_budget_that_never_runs_out_gives_the_bits_of_one_multi_spp_pass() {
        let plain = frames(3, None);
        let budgeted = frames(3, Some(Duration::from_secs(3600)));
        assert!(plain.iter().all(|f| f.0 == 3));
        assert_eq!(plain, budgeted);
    }

    #[test]
    fn an_exhausted_budget_still_renders_one_pass() {
        let one = frames(1, None);
        let budgeted = frames(16, Some(Duration::ZERO));
        assert!(budgeted.iter().all(|f| f.0 == 1), "spp per frame must be 1");
        assert_eq!(one, budgeted);
    }
}
