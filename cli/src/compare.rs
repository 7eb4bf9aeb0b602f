//! `render compare A B`: how far image A is from the reference B, or with `--frames` sequence
//! A from sequence B with the temporal metrics. The arguments and the checks that need no file
//! are here; the comparison and the report are `rt_experiment::compare`. Definitions:
//! docs/experiments.md.

use anyhow::{anyhow, bail, Result};
use rt_experiment::compare::{report, sequence_report, CompareError, Comparison, LagReport};
use rt_metrics::temporal::{lag, LagOptions};
use rt_metrics::{CompareOptions, DEFAULT_EPSILON, DEFAULT_PEAK};
use std::path::PathBuf;

/// `render compare` arguments.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The image to measure (.exr, .png or .jpg).
    #[arg(value_name = "A")]
    pub test: PathBuf,

    /// The reference (ground truth) A is measured against; relMSE divides by it.
    #[arg(value_name = "B")]
    pub reference: PathBuf,

    /// Print one JSON object (keys mse, relmse, rmse, psnr, ssim, relmse_epsilon, psnr_peak;
    /// psnr is null for identical images) instead of `name value` lines.
    #[arg(long)]
    pub json: bool,

    /// Also write a false-colour image of the per-pixel relative squared error (viridis, log
    /// scale from 1e-4 to 10); .png or .exr.
    #[arg(long, value_name = "FILE")]
    pub error_image: Option<PathBuf>,

    /// relMSE's epsilon: the mean of (a-b)^2 / (b^2 + epsilon).
    #[arg(long, default_value_t = DEFAULT_EPSILON, value_parser = positive)]
    pub epsilon: f64,

    /// PSNR's peak value: 10 log10(peak^2 / MSE).
    #[arg(long, default_value_t = DEFAULT_PEAK, value_parser = positive)]
    pub peak: f64,

    /// Measure only the pixels x0..x1 × y0..y1 (half-open, row 0 at the top) of both images,
    /// e.g. a dark, indirectly lit corner.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_delimiter = ',')]
    pub region: Option<Vec<usize>>,

    /// Compare sequences: frames S..E (half-open) of A and B, whose names hold `{frame}` or
    /// `{frame:0N}` (e.g. 'out/f_{frame:04}.exr'); a B without one is the reference of every
    /// frame. Prints each frame's metrics, then the temporal error of A and of B and the
    /// temporal relMSE.
    #[arg(long, value_name = "S..E", value_parser = crate::args::parse_frames)]
    pub frames: Option<std::ops::Range<u32>>,

    /// With --frames: the first frame after a sudden change (e.g. a light toggles); also
    /// prints the lag, the frames until A's relMSE is back within --lag-factor times its
    /// steady state.
    #[arg(long, value_name = "F", requires = "frames")]
    pub event: Option<u32>,

    /// The lag's steady state: the median per-frame relMSE over this many frames before
    /// --event.
    #[arg(long, value_name = "N", default_value_t = 10, requires = "event", value_parser = clap::value_parser!(u32).range(1..))]
    pub lag_window: u32,

    /// The lag's threshold: recovered when relMSE <= factor x the steady state.
    #[arg(long, value_name = "FACTOR", default_value_t = 2.0, requires = "event", value_parser = positive)]
    pub lag_factor: f64,
}

pub(crate) fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("must be a positive number".into()),
    }
}

/// Runs `render compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    let region = match args.region.as_deref().map(<[usize; 4]>::try_from) {
        Some(Err(_)) => bail!("--region takes four numbers: x0,y0,x1,y1"),
        r => r.and_then(Result::ok),
    };
    let comparison = Comparison {
        test: args.test.clone(),
        reference: args.reference.clone(),
        region,
        options: CompareOptions {
            epsilon: args.epsilon,
            peak: args.peak,
        },
        error_image: args.error_image.clone(),
    };
    let flag = |e: CompareError| match e {
        CompareError::Region { .. } => anyhow!("--region {e}"),
        other => other.into(),
    };
    let Some(frames) = args.frames.clone() else {
        let metrics = comparison.images().map_err(flag)?;
        print!("{}", report(&metrics, &comparison.options, args.json));
        return Ok(());
    };
    let event = args.event.map(|e| (e, args.lag_window));
    comparison.check_sequence(&frames, event)?;
    // check_sequence made sure of two frames.
    let metrics = comparison.sequences(frames.clone()).map_err(flag)?;
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
    let opts = &comparison.options;
    print!(
        "{}",
        sequence_report(frames.start, &metrics, lag.as_ref(), opts, args.json)
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_must_be_positive() {
        assert_eq!(positive("0.02"), Ok(0.02));
        for bad in ["0", "-1", "nan", "inf", "x"] {
            assert!(positive(bad).is_err(), "{bad}");
        }
    }
}
