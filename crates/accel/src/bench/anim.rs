//! Seconds per frame of an animated scene (Dammertz 2011, Figs. 4.16 and 4.17): per frame, the
//! structure's update (the top level of `two-level` and `clusters`, a full rebuild of a flat
//! structure) and the trace of a fixed workload of rays generated from that frame's camera.
//!
//! Every frame: the scene moves to `frame / fps`; a flat `bvh8` built over the world copies is
//! the reference, which generates the frame's rays ([`super::generate`]: one jittered primary
//! ray per pixel, a diffuse bounce and a shadow segment from each primary hit) and against
//! which every contender's answers are checked on a sample of rays, before any timing. Then
//! `repeat` rounds time every contender's update and trace, the contenders in a rotated order
//! each round so that a burst of machine load hits them alike; each contender keeps its
//! fastest update and fastest trace of the frame. Timings run on one thread.
//!
//! The update times what a renderer pays per frame: [`Accel::update`] for a structure that
//! follows rigid motion in place, a new build over the scene's triangles for one that cannot
//! (the old structure is dropped outside the timed interval).

use super::measure::{self, CheckResult};
use super::{generate, Lights, RaySet};
use crate::{AccelKind, AccelSpec, BuildError, TwoLevel};
use rt_core::{glam::Vec3, Aabb, Accel, Scene, TraversalCounters};
use std::ops::Range;
use std::time::Instant;

/// A contender fails the check when more than this fraction of the checked rays of a frame
/// disagree with the reference (a few may differ legitimately: an instanced triangle is
/// intersected with the inverse-transformed ray, the reference tests its world copy, so a ray
/// grazing an edge may go either way).
pub const MAX_MISMATCH_FRACTION: f64 = 1e-3;

/// How a contender follows the animation from one frame to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Follow {
    /// [`Accel::update`]: the structure moves its parts in place (two-level, clusters).
    Update,
    /// A new build of this spec over the scene's triangles (a flat structure).
    Rebuild(AccelSpec),
}

/// One structure under test.
pub struct Contender {
    /// The name in reports: the spec, with clustering's `t` always written out.
    pub name: String,
    /// The structure, as of the last frame.
    pub accel: Box<dyn Accel>,
    /// How it follows the animation.
    pub follow: Follow,
    /// Leaves of the top level (two-level kinds): placements, or entry points when clustered.
    pub entries: Option<usize>,
    /// Seconds of the first build (object BVHs included), on the pool it was built on.
    pub build_seconds: f64,
}

impl Contender {
    /// Builds `spec` over `scene` as it is now: two-level kinds follow by update, the others
    /// are rebuilt every frame.
    pub fn build(spec: &AccelSpec, scene: &Scene) -> Result<Self, BuildError> {
        let t = Instant::now();
        let (accel, entries): (Box<dyn Accel>, Option<usize>) = match spec.kind {
            AccelKind::TwoLevel => {
                let a = TwoLevel::build(scene, &spec.build, &spec.wide, spec.top);
                let n = a.entry_count();
                (Box::new(a), Some(n))
            }
            AccelKind::Clusters => {
                let a = TwoLevel::build_clustered(scene, &spec.build, &spec.wide, spec.cluster_t);
                let n = a.entry_count();
                (Box::new(a), Some(n))
            }
            _ => (spec.build(&scene.triangles)?, None),
        };
        let build_seconds = t.elapsed().as_secs_f64();
        Ok(Self {
            name: Self::name_of(spec),
            accel,
            follow: if spec.kind.is_two_level() {
                Follow::Update
            } else {
                Follow::Rebuild(*spec)
            },
            entries,
            build_seconds,
        })
    }

    /// The spec as text, `clusters:t=T` even at the default `t` (the sweep's axis).
    pub fn name_of(spec: &AccelSpec) -> String {
        let text = spec.to_string();
        if spec.kind == AccelKind::Clusters && !text.contains(":t=") {
            format!("{text}:t={}", spec.cluster_t)
        } else {
            text
        }
    }

    /// Brings the structure to the scene's current time; returns the structure a rebuild
    /// replaced, for the caller to drop once its clock has stopped.
    fn follow(&mut self, scene: &Scene) -> Result<Option<Box<dyn Accel>>, AnimError> {
        match self.follow {
            Follow::Update => {
                if !self.accel.update(scene) {
                    return Err(AnimError::CannotUpdate {
                        name: self.name.clone(),
                    });
                }
                Ok(None)
            }
            Follow::Rebuild(spec) => {
                let fresh = spec.build(&scene.triangles)?;
                Ok(Some(std::mem::replace(&mut self.accel, fresh)))
            }
        }
    }
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct AnimOptions {
    /// Frames, half-open; frame `f` at time `f / fps`.
    pub frames: Range<u32>,
    /// Frames per second.
    pub fps: f64,
    /// The scene camera whose view generates the rays (it may be animated).
    pub camera: usize,
    /// Primary rays per frame: one per pixel of this grid.
    pub width: u32,
    /// Height of the primary ray grid.
    pub height: u32,
    /// Seed of the jitter, bounce and light samples (the same every frame).
    pub seed: u64,
    /// Rays of every set checked per frame (0: no check).
    pub check: usize,
    /// Timed rounds per frame; the fastest update and trace count.
    pub repeat: u32,
    /// Also count each contender's traversal work per frame (an untimed pass more).
    pub count: bool,
    /// Which rays a frame traces.
    pub workload: Workload,
}

/// The rays traced per frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Workload {
    /// One primary ray per pixel, a diffuse bounce and a shadow segment from each primary hit:
    /// what a path tracer's first bounce costs.
    #[default]
    Full,
    /// Primary rays only, as the thesis timed Figs. 4.16 and 4.17.
    Primary,
}

/// One contender in one frame: the fastest of the rounds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTime {
    /// The frame number.
    pub frame: u32,
    /// Seconds to follow the animation to this frame.
    pub update: f64,
    /// Seconds to trace the frame's rays.
    pub trace: f64,
    /// Rays that hit or were occluded (the same for every contender up to ties).
    pub hits: u64,
    /// Traversal work of the frame's rays, with [`AnimOptions::count`] and a structure that
    /// counts.
    pub counters: Option<TraversalCounters>,
}

/// One contender over all frames.
#[derive(Clone, Debug)]
pub struct ContenderResult {
    /// [`Contender::name`].
    pub name: String,
    /// [`Contender::entries`].
    pub entries: Option<usize>,
    /// [`Contender::build_seconds`].
    pub build_seconds: f64,
    /// Bytes of the structure after the last frame.
    pub bytes: usize,
    /// Per frame, in frame order.
    pub frames: Vec<FrameTime>,
    /// The checks of all frames together.
    pub check: CheckResult,
}

impl ContenderResult {
    /// Mean over the frames of the fastest update.
    pub fn update(&self) -> f64 {
        mean(self.frames.iter().map(|f| f.update))
    }

    /// Mean over the frames of the fastest trace.
    pub fn trace(&self) -> f64 {
        mean(self.frames.iter().map(|f| f.trace))
    }

    /// Seconds per frame: update plus trace.
    pub fn total(&self) -> f64 {
        self.update() + self.trace()
    }

    /// Traversal work of all frames together, if counted.
    pub fn counters(&self) -> Option<TraversalCounters> {
        self.frames
            .iter()
            .try_fold(TraversalCounters::default(), |mut sum, f| {
                sum += f.counters?;
                Some(sum)
            })
    }
}

fn mean(v: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = v.len().max(1) as f64;
    v.sum::<f64>() / n
}

/// The rays of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameRays {
    /// The frame number.
    pub frame: u32,
    /// Primary rays (one per pixel).
    pub primary: usize,
    /// Diffuse bounces (one per primary hit; 0 with [`Workload::Primary`]).
    pub incoherent: usize,
    /// Shadow segments (one per primary hit facing the light sample; 0 with
    /// [`Workload::Primary`]).
    pub shadow: usize,
}

impl FrameRays {
    /// All rays of the frame.
    pub fn total(&self) -> usize {
        self.primary + self.incoherent + self.shadow
    }
}

/// Everything measured.
#[derive(Clone, Debug)]
pub struct AnimReport {
    /// Triangles of the scene (world copies included).
    pub triangles: usize,
    /// Per contender, in the order given.
    pub contenders: Vec<ContenderResult>,
    /// Per frame.
    pub rays: Vec<FrameRays>,
}

/// Why the measurement stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnimError {
    /// Nothing to measure.
    #[error("no frames to measure (the range {start}..{end} is empty)")]
    NoFrames {
        /// First frame.
        start: u32,
        /// One past the last.
        end: u32,
    },
    /// Frames per second that do not give a time.
    #[error("frames per second must be a positive number, got {0}")]
    Fps(f64),
    /// Zero rounds.
    #[error("the number of timed rounds must be at least 1")]
    Repeat,
    /// The camera index is out of range.
    #[error("the scene has no camera number {0}")]
    Camera(usize),
    /// A structure that neither updates nor rebuilds.
    #[error("{name}: the structure cannot follow this scene's animation by update")]
    CannotUpdate {
        /// The contender.
        name: String,
    },
    /// The camera sees nothing, so there is no workload.
    #[error("frame {frame}: no primary ray hits the scene (does the camera see any geometry?)")]
    NoRays {
        /// The frame.
        frame: u32,
    },
    /// A contender answers differently from the reference.
    #[error(
        "{name}: frame {frame}: {mismatches} of {checked} checked rays disagree with the flat \
         bvh8 (more than {limit}%), e.g. {example}"
    )]
    Mismatch {
        /// The contender.
        name: String,
        /// The frame.
        frame: u32,
        /// Rays that disagree.
        mismatches: usize,
        /// Rays checked.
        checked: usize,
        /// [`MAX_MISMATCH_FRACTION`] in per cent.
        limit: f64,
        /// The first disagreement.
        example: String,
    },
    /// The timing thread could not start.
    #[error("cannot start the timing thread: {0}")]
    Threads(String),
    /// A rebuild failed.
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// The workload of the scene at its current time: the primary, incoherent and shadow sets, or
/// the primary set alone.
fn frame_rays(
    scene: &Scene,
    reference: &dyn Accel,
    options: &AnimOptions,
    frame: u32,
) -> Result<Vec<RaySet>, AnimError> {
    let camera = scene
        .cameras
        .get(options.camera)
        .ok_or(AnimError::Camera(options.camera))?;
    let camera = camera.resized(options.width, options.height);
    let bounds = Aabb::from_points(scene.triangles.iter().flatten());
    let fallback = bounds.center() + Vec3::Y * bounds.extent().length();
    let lights = Lights::of(scene, fallback);
    let [primary, incoherent, shadow, _uniform] =
        generate(scene, &camera, reference, &lights, options.seed).into_sets();
    if incoherent.rays.is_empty() {
        return Err(AnimError::NoRays { frame });
    }
    Ok(match options.workload {
        Workload::Full => vec![primary, incoherent, shadow],
        Workload::Primary => vec![primary],
    })
}

/// Measures `contenders` over `options.frames` of `scene` (which is left at the last frame).
/// Rays, the reference and the checks run on `pool`; the timings on a thread of their own,
/// in the rotated order described in the module documentation. `progress` gets one line per
/// frame.
pub fn run(
    scene: &mut Scene,
    contenders: &mut [Contender],
    options: &AnimOptions,
    pool: &rayon::ThreadPool,
    progress: &mut dyn FnMut(&str),
) -> Result<AnimReport, AnimError> {
    let Range { start, end } = options.frames;
    if start >= end {
        return Err(AnimError::NoFrames { start, end });
    }
    if !(options.fps.is_finite() && options.fps > 0.0) {
        return Err(AnimError::Fps(options.fps));
    }
    if options.repeat == 0 {
        return Err(AnimError::Repeat);
    }
    if options.camera >= scene.cameras.len() {
        return Err(AnimError::Camera(options.camera));
    }
    let reference_spec = AccelSpec::new(AccelKind::Bvh8);
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| AnimError::Threads(e.to_string()))?;
    let mut results: Vec<ContenderResult> = contenders
        .iter()
        .map(|c| ContenderResult {
            name: c.name.clone(),
            entries: c.entries,
            build_seconds: c.build_seconds,
            bytes: 0,
            // Grown frame by frame: the range comes from the user unchecked in size.
            frames: Vec::new(),
            check: CheckResult::default(),
        })
        .collect();
    let mut rays = Vec::new();
    for frame in options.frames.clone() {
        scene.set_time((f64::from(frame) / options.fps) as f32);
        let reference = pool.install(|| reference_spec.build(&scene.triangles))?;
        let sets = pool.install(|| frame_rays(scene, reference.as_ref(), options, frame))?;
        let count = |name: &str| {
            sets.iter()
                .find(|s| s.name == name)
                .map_or(0, |s| s.rays.len())
        };
        rays.push(FrameRays {
            frame,
            primary: count("primary"),
            incoherent: count("incoherent"),
            shadow: count("shadow"),
        });
        // Untimed: follow, check. This also warms the caches for the timed rounds.
        for (c, r) in contenders.iter_mut().zip(&mut results) {
            pool.install(|| c.follow(scene))?;
            if c.follow == Follow::Rebuild(reference_spec) || options.check == 0 {
                continue;
            }
            let check = pool.install(|| {
                measure::check(c.accel.as_ref(), reference.as_ref(), &sets, options.check)
            });
            if check.mismatches as f64 > MAX_MISMATCH_FRACTION * check.checked.max(1) as f64 {
                return Err(AnimError::Mismatch {
                    name: c.name.clone(),
                    frame,
                    mismatches: check.mismatches,
                    checked: check.checked,
                    limit: MAX_MISMATCH_FRACTION * 100.0,
                    example: check.examples.first().cloned().unwrap_or_default(),
                });
            }
            r.check.checked += check.checked;
            r.check.mismatches += check.mismatches;
            r.check.ties += check.ties;
            if r.check.examples.len() < 3 {
                r.check.examples.extend(check.examples.into_iter().take(3));
            }
        }
        drop(reference);
        let mut best = vec![
            FrameTime {
                frame,
                update: f64::INFINITY,
                trace: f64::INFINITY,
                hits: 0,
                counters: None,
            };
            contenders.len()
        ];
        let n = contenders.len();
        // On one thread: a flat rebuild would otherwise spread over the global pool.
        single.install(|| -> Result<(), AnimError> {
            for round in 0..options.repeat as usize {
                for k in 0..n {
                    // Rotated by round and frame: no contender always runs first or last.
                    let i = (k + round + frame as usize) % n;
                    let c = &mut contenders[i];
                    let t = Instant::now();
                    let replaced = c.follow(scene)?;
                    let update = t.elapsed().as_secs_f64();
                    drop(replaced);
                    let mut trace = 0.0;
                    let mut hits = 0;
                    for set in &sets {
                        let timing = measure::time(c.accel.as_ref(), set, None, 1);
                        trace += timing.seconds;
                        hits += timing.hits;
                    }
                    let b = &mut best[i];
                    b.update = b.update.min(update);
                    b.trace = b.trace.min(trace);
                    b.hits = hits;
                }
            }
            Ok(())
        })?;
        if options.count {
            for (c, b) in contenders.iter().zip(&mut best) {
                b.counters = pool.install(|| {
                    sets.iter()
                        .map(|set| measure::count(c.accel.as_ref(), set))
                        .try_fold(TraversalCounters::default(), |mut sum, n| {
                            sum += n?;
                            Some(sum)
                        })
                });
            }
        }
        let total_rays: usize = sets.iter().map(|s| s.rays.len()).sum();
        let mut line = format!("frame {frame}: {total_rays} rays;");
        for (r, b) in results.iter_mut().zip(best) {
            line.push_str(&format!(
                " {} {:.1}+{:.1} ms",
                r.name,
                b.update * 1e3,
                b.trace * 1e3
            ));
            r.frames.push(b);
        }
        progress(&line);
    }
    for (c, r) in contenders.iter().zip(&mut results) {
        r.bytes = c.accel.memory_bytes();
    }
    Ok(AnimReport {
        triangles: scene.triangle_count(),
        contenders: results,
        rays,
    })
}
