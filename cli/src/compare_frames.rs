//! `render compare A B --frames S..E [--event F]`: each frame of the sequence A against the
//! same frame of the reference B, then the temporal metrics of `rt_metrics::temporal`
//! (temporal error of A and of B, temporal relMSE, and the lag after `--event`), as lines or
//! one JSON object. Frames are read one pair at a time; only the previous pair is kept.

use crate::compare::{crop, explain, CompareArgs};
use anyhow::{anyhow, bail, Result};
use rt_core::RgbImage;
use rt_metrics::temporal::{
    lag, FrameMetrics, Lag, LagOptions, SequenceComparison, SequenceMetrics, TemporalError,
};
use rt_metrics::{error_image, CompareOptions, FalseColourOptions, Role};
use rt_session::frames::{frame_path, names_frame};
use serde::Serialize;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The lag as measured, with the settings it depends on.
struct LagReport {
    event: u32,
    lag: Lag,
    opts: LagOptions,
}

/// Refuses, before any file is read, what cannot give a result.
fn check_args(args: &CompareArgs, frames: &Range<u32>) -> Result<()> {
    if !names_frame(&args.test) {
        bail!(
            "{}: --frames needs an A that names the frame, e.g. 'a_{{frame:04}}.exr'",
            args.test.display()
        );
    }
    if frames.len() < 2 {
        bail!(
            "--frames {}..{} holds one frame; the temporal metrics need at least two",
            frames.start,
            frames.end
        );
    }
    if let Some(path) = &args.error_image {
        if !names_frame(path) {
            bail!(
                "{}: with --frames, --error-image must name the frame, e.g. 'err_{{frame:04}}.png'",
                path.display()
            );
        }
    }
    if let Some(event) = args.event {
        if !frames.contains(&event) {
            bail!(
                "--event {event} is not one of --frames {}..{}",
                frames.start,
                frames.end
            );
        }
        let before = event - frames.start;
        if before < args.lag_window {
            bail!(
                "--event {event}: the lag's steady state needs --lag-window {} frames before it, but --frames {}..{} has {before}",
                args.lag_window,
                frames.start,
                frames.end
            );
        }
    }
    Ok(())
}

/// Reads one frame (cropped to `--region`).
fn load(path: &Path, region: Option<&[usize]>) -> Result<RgbImage> {
    let image = rt_film::read_rgb(path)?;
    match region {
        Some(r) => crop(image, r, path),
        None => Ok(image),
    }
}

/// Runs `render compare --frames`.
pub fn run(args: &CompareArgs, frames: Range<u32>) -> Result<()> {
    check_args(args, &frames)?;
    let opts = CompareOptions {
        epsilon: args.epsilon,
        peak: args.peak,
    };
    let mut sequence = SequenceComparison::new(opts).map_err(|e| anyhow!("{e}"))?;
    let region = args.region.as_deref();
    // A reference without a frame placeholder serves every frame; it is read once.
    let fixed_reference = match names_frame(&args.reference) {
        true => None,
        false => Some(load(&args.reference, region)?),
    };
    for f in frames.clone() {
        let (a, b) = (frame_path(&args.test, f), frame_path(&args.reference, f));
        let test = load(&a, region)?;
        let reference = match &fixed_reference {
            Some(r) => r.clone(),
            None => load(&b, region)?,
        };
        if let Some(pattern) = &args.error_image {
            let colours = FalseColourOptions {
                epsilon: args.epsilon,
                ..Default::default()
            };
            let img = error_image(&test, &reference, &colours).map_err(|e| explain(e, &a, &b))?;
            rt_film::write_rgb(
                &frame_path(pattern, f),
                &img,
                &rt_film::OutputOptions::default(),
            )
            // The message already holds the cause; `{:#}` would print it twice.
            .map_err(|e| anyhow!("{e}"))?;
        }
        sequence
            .push(test, reference)
            .map_err(|e| explain_frame(e, args, f))?;
    }
    // check_args made sure of two frames.
    let metrics = sequence.finish().map_err(|e| anyhow!("{e}"))?;
    let lag = match args.event {
        None => None,
        Some(event) => {
            let opts = LagOptions {
                factor: args.lag_factor,
                window: args.lag_window as usize,
            };
            let relmse = metrics.per_frame(|m| m.relmse);
            let lag = lag(&relmse, (event - frames.start) as usize, &opts)
                .map_err(|e| anyhow!("--event {event}: {e}"))?;
            Some(LagReport { event, lag, opts })
        }
    };
    print!(
        "{}",
        report(frames.start, &metrics, lag.as_ref(), &opts, args.json)
    );
    Ok(())
}

/// Restates a frame's error with the files of that frame (and of the one before it).
fn explain_frame(e: TemporalError, args: &CompareArgs, frame: u32) -> anyhow::Error {
    let file = |role, f| -> PathBuf {
        match role {
            Role::Test => frame_path(&args.test, f),
            Role::Reference => frame_path(&args.reference, f),
        }
    };
    match e {
        TemporalError::Frame { cause, .. } => explain(
            cause,
            &file(Role::Test, frame),
            &file(Role::Reference, frame),
        ),
        TemporalError::FrameSize {
            role,
            size: (w, h),
            previous: (pw, ph),
            ..
        } => anyhow!(
            "{} is {w}x{h} but {} is {pw}x{ph}",
            file(role, frame).display(),
            file(role, frame - 1).display()
        ),
        other => anyhow!("frame {frame}: {other}"),
    }
}

/// One frame in the JSON form; the step fields are null on the first frame.
#[derive(Serialize)]
struct JsonFrame {
    frame: u32,
    mse: f64,
    relmse: f64,
    rmse: f64,
    psnr: Option<f64>,
    ssim: f64,
    temporal_error_a: Option<f64>,
    temporal_error_b: Option<f64>,
    temporal_relmse: Option<f64>,
}

#[derive(Serialize)]
struct JsonLag {
    event: u32,
    /// Null when the error never came back within the threshold.
    frames: Option<usize>,
    steady_state: f64,
    threshold: f64,
    window: usize,
    factor: f64,
}

/// The JSON form; fields serialise in this order.
#[derive(Serialize)]
struct JsonReport {
    frames: Vec<JsonFrame>,
    mean_mse: f64,
    mean_relmse: f64,
    mean_ssim: f64,
    temporal_error_a: f64,
    temporal_error_b: f64,
    temporal_relmse: f64,
    /// Null without --event.
    lag: Option<JsonLag>,
    relmse_epsilon: f64,
    psnr_peak: f64,
}

fn json_frame(frame: u32, f: &FrameMetrics) -> JsonFrame {
    let m = &f.metrics;
    JsonFrame {
        frame,
        mse: m.mse,
        relmse: m.relmse,
        rmse: m.rmse,
        psnr: m.psnr.is_finite().then_some(m.psnr),
        ssim: m.ssim,
        temporal_error_a: f.step.map(|s| s.temporal_error_test),
        temporal_error_b: f.step.map(|s| s.temporal_error_reference),
        temporal_relmse: f.step.map(|s| s.temporal_relmse),
    }
}

/// The output: one line per frame (`frame F` then `name value` pairs; from the second frame on
/// also the step from the frame before), then the sequence's `name value` lines and the settings
/// they depend on. Numbers in Rust's shortest round-trip form.
fn report(
    first: u32,
    m: &SequenceMetrics,
    lag: Option<&LagReport>,
    opts: &CompareOptions,
    json: bool,
) -> String {
    let numbered = || (first..).zip(&m.frames);
    if json {
        let r = JsonReport {
            frames: numbered().map(|(i, f)| json_frame(i, f)).collect(),
            mean_mse: m.mean(|m| m.mse),
            mean_relmse: m.mean(|m| m.relmse),
            mean_ssim: m.mean(|m| m.ssim),
            temporal_error_a: m.temporal_error_test.mean,
            temporal_error_b: m.temporal_error_reference.mean,
            temporal_relmse: m.temporal_relmse.mean,
            lag: lag.map(|l| JsonLag {
                event: l.event,
                frames: l.lag.frames,
                steady_state: l.lag.steady_state,
                threshold: l.lag.threshold,
                window: l.opts.window,
                factor: l.opts.factor,
            }),
            relmse_epsilon: opts.epsilon,
            psnr_peak: opts.peak,
        };
        // Serialising plain numbers cannot fail.
        return serde_json::to_string(&r).unwrap_or_default() + "\n";
    }
    let mut out = String::new();
    for (i, f) in numbered() {
        let x = &f.metrics;
        out += &format!(
            "frame {i} mse {} relmse {} rmse {} psnr {} ssim {}",
            x.mse, x.relmse, x.rmse, x.psnr, x.ssim
        );
        if let Some(s) = f.step {
            out += &format!(
                " temporal_error_a {} temporal_error_b {} temporal_relmse {}",
                s.temporal_error_test, s.temporal_error_reference, s.temporal_relmse
            );
        }
        out += "\n";
    }
    out += &format!(
        "mean_mse {}\nmean_relmse {}\nmean_ssim {}\ntemporal_error_a {}\ntemporal_error_b {}\ntemporal_relmse {}\n",
        m.mean(|m| m.mse),
        m.mean(|m| m.relmse),
        m.mean(|m| m.ssim),
        m.temporal_error_test.mean,
        m.temporal_error_reference.mean,
        m.temporal_relmse.mean
    );
    if let Some(l) = lag {
        let frames = l.lag.frames.map_or("none".to_string(), |k| k.to_string());
        out += &format!(
            "lag {frames}\nlag_event {}\nlag_steady_state {}\nlag_threshold {}\nlag_window {}\nlag_factor {}\n",
            l.event, l.lag.steady_state, l.lag.threshold, l.opts.window, l.opts.factor
        );
    }
    out += &format!("relmse_epsilon {}\npsnr_peak {}\n", opts.epsilon, opts.peak);
    out
}
