//! Rendering one configuration: the part that `render`, `render reference` and
//! `render experiment` share. A configuration is a loaded scene, a camera (optionally resized),
//! an acceleration structure, an estimator (integrator and its parameters), a seed and stream,
//! and a budget: a number of samples per pixel or a time. Budgets are rendered progressively
//! into one film, so a list of budgets costs only its largest, and the image at N spp is bit for
//! bit the one a single N-spp render gives.

use crate::args::IntegratorKind;
use anyhow::{anyhow, bail, Context, Result};
use clap::ValueEnum;
use rt_accel::AccelSpec;
use rt_core::{Camera, SampleStream, Scene};
use rt_film::{AovSet, Film};
use rt_integrators::{AoIntegrator, Ctx, Integrator, PathIntegrator, SamplePass};
use rt_scene::RenderDesc;
use std::path::Path;

/// Largest image side an override may ask for; beyond it the film alone would not fit in memory.
pub const MAX_SIDE: u32 = 1 << 15;

/// Largest sample count of one render (the same limit as `--spp`).
pub const MAX_SPP: u32 = 1 << 20;

/// Largest bounce limit (the same limit as `--max-depth`).
pub const MAX_DEPTH: u32 = 10_000;

/// Bounce limit when nothing sets one (as for `render`).
pub const DEFAULT_MAX_DEPTH: u32 = 16;

/// Settings that `render reference` flags and experiment methods may set. Each one left unset
/// falls back to the scene's `[render]` table, then to `render`'s default, exactly as for
/// `render` itself.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Integrator.
    pub integrator: Option<IntegratorKind>,
    /// Bounce limit.
    pub max_depth: Option<u32>,
    /// `ao` occluder distance (never in `[render]`; unlimited by default).
    pub ao_distance: Option<f32>,
    /// Seed.
    pub seed: Option<u64>,
    /// Acceleration structure.
    pub accel: Option<AccelSpec>,
}

impl Overrides {
    /// The estimator. Errors about `[render]` values name the scene file.
    pub fn estimator(&self, desc: &RenderDesc, scene_path: &Path) -> Result<Estimator> {
        let table = |key: &str| format!("{}: [render] {key}", scene_path.display());
        let integrator = match (self.integrator, &desc.integrator) {
            (Some(i), _) => i,
            (None, Some(s)) => {
                parse_integrator(s).map_err(|e| anyhow!("{} = {e}", table("integrator")))?
            }
            (None, None) => IntegratorKind::Path,
        };
        let max_depth = self
            .max_depth
            .or(desc.max_depth)
            .unwrap_or(DEFAULT_MAX_DEPTH);
        if max_depth > MAX_DEPTH {
            bail!(
                "{}: must be at most {MAX_DEPTH}, got {max_depth}",
                table("max_depth")
            );
        }
        let ao_distance = self.ao_distance.unwrap_or(f32::INFINITY);
        if ao_distance.is_nan() || ao_distance <= 0.0 {
            bail!("ao_distance must be positive, got {ao_distance}");
        }
        Ok(Estimator {
            integrator,
            max_depth,
            ao_distance,
        })
    }

    /// The 32-bit stream seed.
    pub fn seed(&self, desc: &RenderDesc) -> u32 {
        fold_seed(self.seed.or(desc.seed).unwrap_or(0))
    }

    /// The acceleration structure.
    pub fn accel(&self, desc: &RenderDesc, scene_path: &Path) -> Result<AccelSpec> {
        if let Some(a) = self.accel {
            return Ok(a);
        }
        match &desc.accel {
            Some(s) => s
                .parse::<AccelSpec>()
                .map_err(|e| anyhow!("{}: [render] accel = \"{s}\": {e}", scene_path.display())),
            None => Ok(AccelSpec::default()),
        }
    }
}

/// Folds a 64-bit seed into the 32-bit stream key without discarding the high half (as
/// `render --seed` does).
pub fn fold_seed(seed: u64) -> u32 {
    (seed ^ (seed >> 32)) as u32
}

/// The camera named `name`, or the scene's first one.
pub fn camera<'s>(scene: &'s Scene, scene_path: &Path, name: Option<&str>) -> Result<&'s Camera> {
    match name {
        Some(name) => scene
            .cameras
            .iter()
            .find(|c| c.name == name)
            .with_context(|| {
                let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
                format!(
                    "{}: no camera named \"{name}\" (cameras: {})",
                    scene_path.display(),
                    names.join(", ")
                )
            }),
        None => scene
            .cameras
            .first()
            .with_context(|| format!("{}: the scene has no camera", scene_path.display())),
    }
}

/// How big to render, relative to the camera's own resolution. Experiments render small images
/// so that a grid of runs and its references fit in minutes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ImageSize {
    /// The camera's resolution.
    #[default]
    Native,
    /// Exactly this width and height. The field of view stays vertical, so a different aspect
    /// ratio shows more or less to the sides.
    Pixels(u32, u32),
    /// The camera's resolution times this factor, rounded, at least one pixel.
    Scale(f64),
}

impl ImageSize {
    /// Checks the values; `what` names where they came from for the message.
    pub fn validate(&self, what: &str) -> Result<()> {
        match *self {
            ImageSize::Native => {}
            ImageSize::Pixels(w, h) => {
                if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
                    bail!(
                        "{what}: resolution must be between 1 and {MAX_SIDE} per side, got {w}x{h}"
                    );
                }
            }
            ImageSize::Scale(s) => {
                if !(s.is_finite() && s > 0.0 && s <= 16.0) {
                    bail!("{what}: scale must be in (0, 16], got {s}");
                }
            }
        }
        Ok(())
    }

    /// `camera` resized. Only the film changes: position, orientation, vertical field of view
    /// and lens stay, so a scaled image shows the same view.
    pub fn apply(&self, camera: &Camera) -> Camera {
        let (w, h) = match *self {
            ImageSize::Native => (camera.width, camera.height),
            ImageSize::Pixels(w, h) => (w, h),
            ImageSize::Scale(s) => {
                let side = |n: u32| ((n as f64 * s).round() as u32).clamp(1, MAX_SIDE);
                (side(camera.width), side(camera.height))
            }
        };
        let mut c = camera.clone();
        c.width = w;
        c.height = h;
        c
    }
}

/// Parses `WxH` (`--resolution 128x96`).
pub fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let err = || format!("expected WIDTHxHEIGHT such as 128x96, got \"{s}\"");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(err)?;
    let w: u32 = w.trim().parse().map_err(|_| err())?;
    let h: u32 = h.trim().parse().map_err(|_| err())?;
    ImageSize::Pixels(w, h)
        .validate("--resolution")
        .map_err(|e| e.to_string())?;
    Ok((w, h))
}

/// The integrator and the parameters that change what it converges to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimator {
    /// Which integrator.
    pub integrator: IntegratorKind,
    /// Bounce limit (path tracers; `direct` is always one bounce).
    pub max_depth: u32,
    /// Occluder distance of `ao` (infinite: unlimited).
    pub ao_distance: f32,
}

/// What an estimator converges to. Two estimators with the same target can be measured
/// against one reference; otherwise the error levels off at the difference of the two images.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// Light transport with at most this many bounces (`path`, `path-bsdf`, and `direct` = 1).
    Radiance {
        /// Bounce limit.
        bounces: u32,
    },
    /// Ambient occlusion with this occluder distance.
    Occlusion {
        /// Occluder distance.
        distance: f32,
    },
}

impl Estimator {
    /// The integrator's name as `--integrator` spells it.
    pub fn name(&self) -> String {
        integrator_name(self.integrator)
    }

    /// Builds the integrator.
    pub fn build(&self) -> Box<dyn Integrator> {
        match self.integrator {
            IntegratorKind::Path => Box::new(PathIntegrator::new(self.max_depth)),
            IntegratorKind::PathBsdf => Box::new(PathIntegrator::bsdf_only(self.max_depth)),
            IntegratorKind::Direct => Box::new(PathIntegrator::direct()),
            IntegratorKind::Ao => Box::new(AoIntegrator {
                max_distance: self.ao_distance,
            }),
        }
    }

    /// What the integrator converges to.
    pub fn target(&self) -> Target {
        match self.integrator {
            IntegratorKind::Path | IntegratorKind::PathBsdf => Target::Radiance {
                bounces: self.max_depth,
            },
            IntegratorKind::Direct => Target::Radiance { bounces: 1 },
            IntegratorKind::Ao => Target::Occlusion {
                distance: self.ao_distance,
            },
        }
    }
}

/// `--integrator`'s spelling of `kind`.
pub fn integrator_name(kind: IntegratorKind) -> String {
    kind.to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default()
}

/// Parses an integrator name as `--integrator` does; the error lists the names.
pub fn parse_integrator(name: &str) -> Result<IntegratorKind, String> {
    IntegratorKind::from_str(name, true).map_err(|_| {
        let names: Vec<String> = IntegratorKind::value_variants()
            .iter()
            .map(|&k| integrator_name(k))
            .collect();
        format!("\"{name}\" is not one of {}", names.join(", "))
    })
}

/// How much to render: samples per pixel, or a time.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// Stop at each of these sample counts (ascending, distinct).
    Spp(Vec<u32>),
    /// Stop as soon as the render time reaches each of these seconds (ascending, distinct).
    Seconds(Vec<f64>),
}

impl Budgets {
    /// How many stops.
    pub fn len(&self) -> usize {
        match self {
            Budgets::Spp(v) => v.len(),
            Budgets::Seconds(v) => v.len(),
        }
    }
}

/// Where a progressive render stands at one of its stops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Checkpoint {
    /// Index of the budget just reached.
    pub budget: usize,
    /// Samples per pixel so far.
    pub spp: u32,
    /// Render time so far (the passes only: not scene loading, acceleration structure build,
    /// or what the caller does at checkpoints).
    pub seconds: f64,
    /// Camera samples so far.
    pub samples: u64,
    /// Rays traced so far (closest-hit and shadow).
    pub rays: u64,
    /// Samples dropped as non-finite or negative so far.
    pub discarded: u64,
}

/// One configuration ready to render.
pub struct Session<'a> {
    /// Scene, acceleration structure and camera (already resized).
    pub ctx: Ctx<'a>,
    /// The estimator.
    pub integrator: &'a dyn Integrator,
    /// Seed of the sample streams.
    pub seed: u32,
    /// Normal or reference streams.
    pub stream: SampleStream,
    /// AOVs the film keeps (references keep `variance`).
    pub aovs: AovSet,
}

impl Session<'_> {
    /// Renders into one film, pass after pass, and calls `checkpoint` each time the next of
    /// `budgets` is reached; returns the final film. Call it inside the thread pool that should
    /// do the work. `progress` gets the fraction of the largest budget done (from worker
    /// threads).
    ///
    /// Sample budgets are exact. A time budget is reached by passes whose size is predicted
    /// from the time per sample so far, never more than doubling the samples taken (a bad
    /// prediction overshoots by at most one pass), rounded to whole samples per pixel: the
    /// reported time is the real one, within about half a sample's time of the budget.
    pub fn render(
        &self,
        budgets: &Budgets,
        progress: &(dyn Fn(f64) + Sync),
        checkpoint: &mut dyn FnMut(&Film, &Checkpoint) -> Result<()>,
    ) -> Result<Film> {
        let camera = self.ctx.camera;
        let mut film = Film::new(camera.width, camera.height, self.aovs);
        let mut at = Checkpoint::default();
        let rows = camera.height.max(1) as f64;
        let pass = |film: &mut Film,
                    at: &mut Checkpoint,
                    n: u32,
                    done_fraction: &(dyn Fn(f64) -> f64 + Sync)| {
            let pass = SamplePass {
                indices: at.spp..at.spp + n,
                stream: self.stream,
            };
            let stats = rt_integrators::render_samples(
                &self.ctx,
                self.integrator,
                film,
                self.seed,
                &pass,
                &|r| progress(done_fraction(r as f64 / rows)),
            );
            at.spp += n;
            at.seconds += stats.elapsed.as_secs_f64();
            at.samples += stats.samples;
            at.rays += stats.rays.rays + stats.rays.shadow_rays;
            at.discarded += stats.discarded;
        };
        match budgets {
            Budgets::Spp(list) => {
                let last = f64::from(list.last().copied().unwrap_or(1).max(1));
                for (i, &spp) in list.iter().enumerate() {
                    if spp > at.spp {
                        let count = spp - at.spp;
                        let (from, n) = (f64::from(at.spp), f64::from(count));
                        pass(&mut film, &mut at, count, &|f| (from + f * n) / last);
                    }
                    at.budget = i;
                    checkpoint(&film, &at)?;
                }
            }
            Budgets::Seconds(list) => {
                let last = list.last().copied().unwrap_or(1.0).max(1e-9);
                for (i, &budget) in list.iter().enumerate() {
                    while at.spp < MAX_SPP {
                        let n = if at.spp == 0 {
                            1
                        } else {
                            let per_spp = at.seconds / f64::from(at.spp);
                            let fit = ((budget - at.seconds) / per_spp.max(1e-12)).round();
                            fit.clamp(0.0, f64::from(at.spp.min(MAX_SPP - at.spp))) as u32
                        };
                        if n == 0 {
                            break;
                        }
                        let t0 = at.seconds;
                        pass(&mut film, &mut at, n, &|_| t0 / last);
                        progress((at.seconds / last).min(1.0));
                    }
                    at.budget = i;
                    checkpoint(&film, &at)?;
                }
            }
        }
        Ok(film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::glam::Vec3;

    fn cam() -> Camera {
        Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 512, 384, 0.0, 1.0)
    }

    #[test]
    fn image_size_overrides() {
        let c = cam();
        let s = ImageSize::Scale(0.25).apply(&c);
        assert_eq!((s.width, s.height), (128, 96));
        assert_eq!(s.fov_y_deg, c.fov_y_deg);
        let p = ImageSize::Pixels(32, 32).apply(&c);
        assert_eq!((p.width, p.height), (32, 32));
        let tiny = ImageSize::Scale(0.0001).apply(&c);
        assert_eq!((tiny.width, tiny.height), (1, 1));
        assert!(ImageSize::Scale(0.0).validate("x").is_err());
        assert!(ImageSize::Scale(f64::NAN).validate("x").is_err());
        assert!(ImageSize::Pixels(0, 4).validate("x").is_err());
        assert!(ImageSize::Pixels(4, 4).validate("x").is_ok());
    }

    #[test]
    fn resolution_flag() {
        assert_eq!(parse_resolution("128x96"), Ok((128, 96)));
        assert_eq!(parse_resolution("8X8"), Ok((8, 8)));
        for bad in ["128", "x96", "0x4", "ax4", "4x4x4"] {
            assert!(parse_resolution(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn integrator_names_round_trip() {
        for &k in IntegratorKind::value_variants() {
            assert_eq!(parse_integrator(&integrator_name(k)), Ok(k));
        }
        let e = parse_integrator("bdpt").unwrap_err();
        assert_eq!(e, "\"bdpt\" is not one of path, path-bsdf, direct, ao");
    }

    #[test]
    fn targets_tell_comparable_estimators() {
        let e = |integrator, max_depth| Estimator {
            integrator,
            max_depth,
            ao_distance: f32::INFINITY,
        };
        let path = e(IntegratorKind::Path, 8);
        assert_eq!(path.target(), e(IntegratorKind::PathBsdf, 8).target());
        assert_ne!(path.target(), e(IntegratorKind::Path, 4).target());
        assert_eq!(
            e(IntegratorKind::Direct, 8).target(),
            e(IntegratorKind::Path, 1).target()
        );
        assert_ne!(path.target(), e(IntegratorKind::Ao, 8).target());
    }
}
