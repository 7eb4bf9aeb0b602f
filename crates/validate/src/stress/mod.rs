//! Numerical stress tests: the same cases run with a small budget in `cargo test`
//! (`tests/tests/stress.rs`) and with a large one from `render stress --long`.
//!
//! Three kinds of case (see `docs/experiments.md`, "Numerical stress tests"):
//!
//! - **Transformations** ([`transform`]): the Cornell box scaled by 10⁻⁴ and 10⁴, and scaled by
//!   100 and moved 10⁵ from the origin, must render the same image as the original within
//!   noise ([`compare`]: a z-test on blocks of pixels whose tolerance comes from the film's
//!   per-pixel variance of the mean). A control case injects acne into 5 % of all rays
//!   and must be caught by the same test.
//! - **Self-intersection** ([`crate::self_hit`]): rays leaving huge triangles, bounce rays of
//!   `gen:mixed` (and of the conference room when `../shared/data` has it), and shadow rays
//!   between points of one huge plane: the count of false hits must be zero.
//! - **Bad geometry** ([`bad_geometry`]): grazing rays, shared edges and vertices of a closed
//!   box seen from inside (no light may leak in: every pixel exactly zero), coplanar and
//!   overlapping triangles, zero-area and sliver triangles, huge and tiny triangles together,
//!   shading normals pointing the wrong way, NaN texels, emitters of zero and of the largest
//!   allowed radiance, rendered by every integrator: no NaN or infinity anywhere in the film
//!   and no discarded sample; lit scenes must be lit (a positive mean within the bound of
//!   their sources) and, but for two cases with open findings, as bright as bidirectional
//!   path tracing makes them within noise; a box open to the sky must be as bright as its
//!   one-bounce light.
//!
//! Each case returns a [`CaseReport`] whose `Display` is the one line `render stress` prints.
//! A case that panics is caught and reported as failed, so one bad case does not hide the rest.

pub mod bad_geometry;
pub mod compare;
pub mod transform;

use crate::{self_hit, LoadError};
use rt_core::{Accel, Scene};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::Integrator;
use std::fmt;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How much work the cases do: `cargo test` runs [`Budget::ci`], `render stress --long`
/// [`Budget::long`].
#[derive(Clone, Debug)]
pub struct Budget {
    /// Samples per pixel of the compared renders (the bad-geometry renders take a quarter).
    pub spp: u32,
    /// Image side of the transformation and bad-geometry renders.
    pub resolution: u32,
    /// Rays per surface in the huge-triangle and plane shadow-ray cases.
    pub rays_per_surface: usize,
    /// Primary ray grid of the bounce-ray cases (bounce rays per hit: 4).
    pub bounce_grid: (u32, u32),
    /// Also run the extreme transformations (10⁻⁶, 10⁶, 10⁶ from the origin).
    pub extreme: bool,
    /// Where to look for `scenes/conference/conference.obj` (the shared test meshes; `None`:
    /// [`crate::data::default_dir`]).
    pub data_dir: Option<PathBuf>,
}

impl Budget {
    /// The short run of `cargo test --release` (a few seconds on two cores).
    pub fn ci() -> Self {
        Self {
            spp: 256,
            resolution: 32,
            rays_per_surface: 40_000,
            bounce_grid: (128, 96),
            extreme: false,
            data_dir: None,
        }
    }

    /// The long run of `render stress --long`.
    pub fn long() -> Self {
        Self {
            spp: 1024,
            resolution: 64,
            rays_per_surface: 1_000_000,
            bounce_grid: (512, 384),
            extreme: true,
            data_dir: None,
        }
    }
}

/// One measured quantity of a case and the bound it must respect.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// What was measured.
    pub what: String,
    /// The measurement.
    pub value: f64,
    /// The bound.
    pub tolerance: f64,
    /// The value must be at least the tolerance (a control that must detect something)
    /// rather than at most.
    pub at_least: bool,
}

impl Check {
    /// `value ≤ tolerance`.
    pub fn at_most(what: impl Into<String>, value: f64, tolerance: f64) -> Self {
        Self {
            what: what.into(),
            value,
            tolerance,
            at_least: false,
        }
    }

    /// `value ≥ tolerance`.
    pub fn at_least(what: impl Into<String>, value: f64, tolerance: f64) -> Self {
        Self {
            at_least: true,
            ..Self::at_most(what, value, tolerance)
        }
    }

    /// True if the bound holds (NaN never passes).
    pub fn passed(&self) -> bool {
        if self.at_least {
            self.value >= self.tolerance
        } else {
            self.value <= self.tolerance
        }
    }
}

impl fmt::Display for Check {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let num = |x: f64| {
            if x == x.trunc() && x.abs() < 1e15 {
                format!("{x:.0}")
            } else if x.abs() >= 1e-3 && x.abs() < 1e5 {
                format!("{x:.3}")
            } else {
                format!("{x:.3e}")
            }
        };
        let op = if self.at_least { ">=" } else { "<=" };
        write!(
            f,
            "{} {} (tol {op} {})",
            self.what,
            num(self.value),
            num(self.tolerance)
        )
    }
}

/// What a case measured.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// The checks; the case passes if all pass.
    pub checks: Vec<Check>,
    /// Samples the film discarded as NaN, infinite or negative (for cases that render); the
    /// case fails unless it is zero.
    pub discarded: Option<u64>,
    /// Why the case did not run (missing optional data); a skipped case passes, but under
    /// `RT_REQUIRE_DATA=1` missing data is an error instead of a skip.
    pub skipped: Option<String>,
}

/// The result of one case: the line `render stress` prints.
#[derive(Clone, Debug)]
pub struct CaseReport {
    /// Case name.
    pub name: String,
    /// What it measured; `Err` if it could not run or panicked.
    pub outcome: Result<Outcome, String>,
    /// Wall-clock time.
    pub elapsed: Duration,
}

impl CaseReport {
    /// True if the case ran (or was skipped), every check passed and no sample was discarded.
    pub fn passed(&self) -> bool {
        match &self.outcome {
            Ok(o) => o.checks.iter().all(Check::passed) && o.discarded.unwrap_or(0) == 0,
            Err(_) => false,
        }
    }
}

impl fmt::Display for CaseReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let status = match &self.outcome {
            Ok(o) if o.skipped.is_some() => "skip",
            _ if self.passed() => "pass",
            _ => "FAIL",
        };
        write!(f, "{:<34} {status}  ", self.name)?;
        match &self.outcome {
            Ok(o) => {
                if let Some(why) = &o.skipped {
                    write!(f, "{why}")?;
                }
                let checks: Vec<String> = o.checks.iter().map(Check::to_string).collect();
                write!(f, "{}", checks.join("; "))?;
                match o.discarded {
                    Some(d) => write!(f, "  discarded {d}")?,
                    None => write!(f, "  discarded -")?,
                }
            }
            Err(e) => write!(f, "{e}")?,
        }
        write!(f, "  {:.2} s", self.elapsed.as_secs_f64())
    }
}

/// A named stress case.
#[derive(Clone, Copy)]
pub struct Case {
    /// Name printed in the report.
    pub name: &'static str,
    run: fn(&Budget, u64) -> Result<Outcome, LoadError>,
}

impl Case {
    /// Runs the case, catching panics (reported as failures with the panic message).
    pub fn run(&self, budget: &Budget, seed: u64) -> CaseReport {
        let start = Instant::now();
        let result =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (self.run)(budget, seed)));
        let outcome = match result {
            Ok(Ok(o)) => Ok(o),
            Ok(Err(e)) => Err(format!("error: {e}")),
            Err(payload) => {
                let msg = payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown payload".into());
                Err(format!("panicked: {msg}"))
            }
        };
        CaseReport {
            name: self.name.to_string(),
            outcome,
            elapsed: start.elapsed(),
        }
    }
}

/// Runs `cases` in order on `pool`, handing each report to `each`; returns the names of the
/// cases that failed.
pub fn run_cases(
    cases: &[Case],
    budget: &Budget,
    seed: u64,
    pool: &rayon::ThreadPool,
    each: &mut dyn FnMut(&CaseReport),
) -> Vec<String> {
    let mut failed = Vec::new();
    for case in cases {
        let report = pool.install(|| case.run(budget, seed));
        each(&report);
        if !report.passed() {
            failed.push(report.name);
        }
    }
    failed
}

/// Every case, in report order.
pub fn cases() -> Vec<Case> {
    let mut v = transform::cases();
    v.extend(self_hit_cases());
    v.extend(bad_geometry::cases());
    v
}

/// The cases whose name starts with `prefix` (all for an empty prefix).
pub fn cases_named(prefix: &str) -> Vec<Case> {
    cases()
        .into_iter()
        .filter(|c| c.name.starts_with(prefix))
        .collect()
}

fn self_hit_cases() -> Vec<Case> {
    vec![
        Case {
            name: "self-hit/huge-triangles",
            run: |b, seed| {
                let per = self_hit::huge_triangles(b.rays_per_surface, seed);
                Ok(self_hit_outcome("self-hits", per))
            },
        },
        Case {
            name: "self-hit/plane-shadow-rays",
            run: |b, seed| {
                let per = self_hit::plane_shadow_rays(b.rays_per_surface, seed);
                Ok(self_hit_outcome("occluded by their own plane", per))
            },
        },
        Case {
            name: "self-hit/gen-mixed-bounces",
            run: |b, seed| {
                let scene = rt_scene::procedural::generate("mixed")
                    .map_err(|e| LoadError::new("gen:mixed", e))?;
                Ok(bounce_outcome(&scene, b, seed))
            },
        },
        Case {
            name: "self-hit/conference-bounces",
            run: |b, seed| {
                let dir = b.data_dir.clone().unwrap_or_else(crate::data::default_dir);
                let rel = "scenes/conference/conference.obj";
                // Under RT_REQUIRE_DATA=1 a missing mesh is an error, so the case fails.
                let path = crate::data::locate(&dir, rel)
                    .map_err(|e| LoadError::new("the conference room", e))?;
                let Some(path) = path else {
                    return Ok(Outcome {
                        skipped: Some(format!("{} not found", dir.join(rel).display())),
                        ..Outcome::default()
                    });
                };
                let scene = crate::mesh_scene(&path)?;
                Ok(bounce_outcome(&scene, b, seed))
            },
        },
    ]
}

fn self_hit_outcome(what: &str, per: Vec<(&str, self_hit::SelfHits)>) -> Outcome {
    let mut total = self_hit::SelfHits::default();
    for (_, s) in &per {
        total += *s;
    }
    let worst = per
        .iter()
        .filter(|(_, s)| s.hits > 0)
        .map(|(n, s)| format!("{n}: {}", s.hits))
        .collect::<Vec<_>>();
    let label = if worst.is_empty() {
        format!("{what} of {} rays", total.rays)
    } else {
        format!("{what} of {} rays ({})", total.rays, worst.join(", "))
    };
    Outcome {
        checks: vec![Check::at_most(label, total.hits as f64, 0.0)],
        ..Outcome::default()
    }
}

/// Bounce-ray self-hits of `scene` seen from an automatic camera: the scene's own camera, or
/// for a bare mesh one inside its bounds looking along the long horizontal axis.
fn bounce_outcome(scene: &Scene, b: &Budget, seed: u64) -> Outcome {
    let accel = crate::default_accel(scene);
    let camera = scene
        .cameras
        .first()
        .cloned()
        .unwrap_or_else(|| crate::inside_camera(scene, accel.as_ref()));
    let s = self_hit::bounce_rays(scene, accel.as_ref(), &camera, b.bounce_grid, 4, seed);
    Outcome {
        checks: vec![Check::at_most(
            format!("self-hits of {} bounce rays", s.rays),
            s.hits as f64,
            0.0,
        )],
        ..Outcome::default()
    }
}

/// Renders `scene`'s first camera with `accel` into a fresh film with every first-hit AOV.
pub fn render_film(
    scene: &Scene,
    accel: &dyn Accel,
    integrator: &dyn Integrator,
    spp: u32,
    seed: u32,
) -> (Film, rt_integrators::RenderStats) {
    let aovs = AovSet::denoise();
    // Every buffer a film can keep, so that every one is checked for invalid values.
    let buffers = FilmBuffers::for_outputs(aovs).with_variance().with_halves();
    crate::Renderer::new(scene)
        .with_accel(accel)
        .render(integrator, buffers, spp, seed)
}

/// Number of NaN, infinite or negative values anywhere in the film's outputs: means,
/// variances, half-buffers and first-hit AOVs (negative allowed only where a coordinate or a
/// normal component may be negative).
pub fn invalid_values(film: &Film) -> u64 {
    let bad_rgb = |c: rt_core::Rgb| {
        c.to_array()
            .iter()
            .filter(|x| !(x.is_finite() && **x >= 0.0))
            .count() as u64
    };
    let bad_vec = |v: rt_core::glam::Vec3| v.to_array().iter().filter(|x| !x.is_finite()).count();
    let mut n = 0;
    let rgb_images = [
        Some(film.mean_image()),
        film.variance_image(),
        film.half_image(0),
        film.half_image(1),
        film.albedo_image(),
    ];
    for image in rgb_images.iter().flatten() {
        n += image.iter().map(|&c| bad_rgb(c)).sum::<u64>();
    }
    for image in [film.normal_image(), film.position_image()]
        .iter()
        .flatten()
    {
        n += image.iter().map(|&v| bad_vec(v) as u64).sum::<u64>();
    }
    if let Some(depth) = film.depth_image() {
        n += depth
            .iter()
            .filter(|d| !(d.is_finite() && **d >= 0.0))
            .count() as u64;
    }
    n
}
