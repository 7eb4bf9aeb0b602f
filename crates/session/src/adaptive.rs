//! Rendering until an error threshold or a time limit is met (`render --error V`,
//! `--time-limit S`), with samples per pixel as a cap: passes of two samples (so the film's
//! even half holds exactly half of every active pixel's samples), each followed, from
//! [`FIRST_DECISION_SPP`] on, by one decision of the hierarchical stopping criterion
//! ([`rt_film::stopping`]), which takes the pixels of finished blocks out of the next pass. Light-path techniques cannot aim their
//! splats, so for them every pass covers the whole image and the criterion only decides when
//! to stop.
//!
//! The image is deterministic for a given threshold: which pixels sample in a pass depends
//! only on the film, which depends only on the seed and the settings. A time limit makes the
//! sample count, and so the image, depend on the machine.

use rt_core::SampleStream;
use rt_film::stopping::{BadThreshold, Block, BlockMap, StoppingCriterion};
use rt_film::Film;
use rt_integrators::{Ctx, RenderStats, SamplePass, Technique};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Samples per pixel before the first decision. The thesis decides from the start, but the
/// halves' difference of one or two samples each is so noisy that blocks finished on a lucky
/// estimate: on `scenes/interior.toml` adaptive sampling then needed 131–163 % of the uniform
/// samples for the same MSE, and 90–99 % with this (penumbra: 55 % at RMS 0.0027 either way;
/// `docs/experiments.md`, "Stopping criterion").
pub const FIRST_DECISION_SPP: u32 = 16;

/// Longest time limit a stop rule accepts: a day.
pub const MAX_TIME_LIMIT: f64 = 86_400.0;

/// When an adaptive render stops: validated once, by [`StopRule::new`], wherever it comes from
/// (`render --error --time-limit`, an experiment's method).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StopRule {
    /// Error threshold of the stopping criterion (`ε_t`); `None`: no criterion.
    pub error: Option<f32>,
    /// Wall-clock limit of the passes; `None`: none.
    pub time_limit: Option<Duration>,
    /// Most samples any pixel takes.
    pub max_spp: u32,
}

/// A stop rule's value out of range.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StopRuleError {
    /// An error threshold that is not a positive finite number.
    #[error("must be a positive finite number, got {0} (the hierarchical stopping criterion's threshold; the thesis uses 2e-4)")]
    Error(f32),
    /// A time limit that is not a positive number of seconds up to [`MAX_TIME_LIMIT`].
    #[error("must be a positive number of seconds, at most {MAX_TIME_LIMIT}, got {0}")]
    TimeLimit(f64),
}

impl StopRuleError {
    /// The message with the value's name in front: `error_name` or `time_name`, as the
    /// caller's vocabulary calls them (`--error`, `time_limit`).
    pub fn named(&self, error_name: &str, time_name: &str) -> String {
        match self {
            StopRuleError::Error(_) => format!("{error_name} {self}"),
            StopRuleError::TimeLimit(_) => format!("{time_name} {self}"),
        }
    }
}

impl StopRule {
    /// A rule stopping at error threshold `error`, after `time_limit` seconds, or at
    /// `max_spp` samples per pixel, whichever comes first; the values are checked here.
    pub fn new(
        error: Option<f32>,
        time_limit: Option<f64>,
        max_spp: u32,
    ) -> Result<StopRule, StopRuleError> {
        if let Some(e) = error {
            if StoppingCriterion::new(1, 1, e).is_err() {
                return Err(StopRuleError::Error(e));
            }
        }
        if let Some(t) = time_limit {
            if !(t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT) {
                return Err(StopRuleError::TimeLimit(t));
            }
        }
        Ok(StopRule {
            error,
            time_limit: time_limit.map(Duration::from_secs_f64),
            max_spp,
        })
    }
}

/// Why an adaptive render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Every block met the error threshold.
    Converged,
    /// The time limit was reached.
    TimeLimit,
    /// The cap on samples per pixel was reached.
    SampleCap,
    /// The caller's stop flag was set ([`render_adaptive_until`]).
    Stopped,
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StopReason::Converged => "converged",
            StopReason::TimeLimit => "time limit",
            StopReason::SampleCap => "sample cap",
            StopReason::Stopped => "stopped",
        })
    }
}

/// What an adaptive render did.
#[derive(Clone, Debug)]
pub struct Adaptive {
    /// The passes' statistics summed (samples: camera samples and light paths taken).
    pub stats: RenderStats,
    /// Samples per pixel of the pixels that sampled longest.
    pub spp: u32,
    /// Why it stopped.
    pub reason: StopReason,
    /// Time spent in the stopping criterion's decisions.
    pub decisions: Duration,
    /// Blocks still sampling when it stopped (empty when converged).
    pub active_blocks: Vec<Block>,
    /// Blocks that met the threshold, in the order they did (empty without a criterion).
    pub finished_blocks: Vec<Block>,
}

impl Adaptive {
    /// The final blocks as per-pixel maps over a `width × height` film; `None` without a
    /// stopping criterion (a time limit alone has no blocks).
    pub fn block_map(&self, width: u32, height: u32) -> Option<BlockMap> {
        if self.active_blocks.is_empty() && self.finished_blocks.is_empty() {
            return None;
        }
        Some(BlockMap::new(
            width,
            height,
            &self.finished_blocks,
            &self.active_blocks,
        ))
    }
}

/// Renders into `film` (which must keep half-buffers when `rule.error` is set) until `rule`
/// says stop. `progress` is called with the fraction of the cap done so far.
pub fn render_adaptive(
    ctx: &Ctx<'_>,
    technique: &dyn Technique,
    film: &mut Film,
    seed: u32,
    rule: &StopRule,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Adaptive, BadThreshold> {
    let never = AtomicBool::new(false);
    render_adaptive_until(ctx, technique, film, seed, rule, progress, &never)
}

/// [`render_adaptive`] that also ends after the pass in which `stop` is set
/// ([`StopReason::Stopped`]), for callers that interrupt renders (the Python module's Ctrl-C).
pub fn render_adaptive_until(
    ctx: &Ctx<'_>,
    technique: &dyn Technique,
    film: &mut Film,
    seed: u32,
    rule: &StopRule,
    progress: &(dyn Fn(f64) + Sync),
    stop: &AtomicBool,
) -> Result<Adaptive, BadThreshold> {
    let mut criterion = rule
        .error
        .map(|v| StoppingCriterion::new(film.width(), film.height(), v))
        .transpose()?;
    let start = Instant::now();
    let mut stats = RenderStats::default();
    let mut decisions = Duration::ZERO;
    let mut spp = 0u32;
    let cap = rule.max_spp.max(1);
    let reason = loop {
        if spp >= cap {
            break StopReason::SampleCap;
        }
        let n = 2.min(cap - spp);
        let pixels = match &criterion {
            Some(c) if !technique.splats() => Some(Arc::from(c.mask())),
            _ => None,
        };
        let pass = SamplePass {
            indices: spp..spp + n,
            stream: SampleStream::Render,
            pixels,
            centre_first: false,
        };
        let s = technique.render_pass(ctx, film, seed, &pass, &|_| {});
        stats.samples += s.samples;
        stats.rays += s.rays;
        stats.discarded += s.discarded;
        spp += n;
        progress(f64::from(spp) / f64::from(cap));
        if let Some(c) = criterion
            .as_mut()
            .filter(|_| spp >= FIRST_DECISION_SPP.min(cap))
        {
            let t = Instant::now();
            c.decide(film);
            decisions += t.elapsed();
            if c.converged() {
                break StopReason::Converged;
            }
        }
        if rule.time_limit.is_some_and(|t| start.elapsed() >= t) {
            break StopReason::TimeLimit;
        }
        if stop.load(Ordering::Relaxed) {
            break StopReason::Stopped;
        }
    };
    stats.elapsed = start.elapsed();
    Ok(Adaptive {
        stats,
        spp,
        reason,
        decisions,
        active_blocks: criterion
            .as_ref()
            .map(|c| c.active().to_vec())
            .unwrap_or_default(),
        finished_blocks: criterion.map(|c| c.finished().to_vec()).unwrap_or_default(),
    })
}
