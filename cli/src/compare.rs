//! `render compare A B`: how far image A is from the reference B (MSE, relMSE, RMSE, PSNR,
//! SSIM from `rt-metrics`), printed as `name value` lines or one JSON object, plus an optional
//! false-colour error image. With `--frames`, A and B are numbered sequences and
//! `compare_frames.rs` adds the temporal metrics. Definitions: docs/experiments.md.

use anyhow::{anyhow, Result};
use rt_film::read_rgb as load_rgb;
use rt_metrics::{
    compare, error_image, CompareOptions, FalseColourOptions, Metrics, MetricsError, RgbImage,
    Role, DEFAULT_EPSILON, DEFAULT_PEAK,
};
use rt_session::frames::names_frame;
use serde::Serialize;
use std::path::{Path, PathBuf};

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

/// `image` cut to `region` (x0, y0, x1, y1), or a line saying why it cannot be.
pub(crate) fn crop(image: RgbImage, region: &[usize], path: &Path) -> Result<RgbImage> {
    let &[x0, y0, x1, y1] = region else {
        return Err(anyhow!("--region takes four numbers: x0,y0,x1,y1"));
    };
    let (w, h) = (image.width(), image.height());
    if x0 >= x1 || y0 >= y1 || x1 > w || y1 > h {
        return Err(anyhow!(
            "--region {x0},{y0},{x1},{y1} is not a non-empty rectangle inside the {w}x{h} image {}",
            path.display()
        ));
    }
    let px = image.pixels();
    Ok(RgbImage::from_fn(x1 - x0, y1 - y0, |x, y| {
        px[(y0 + y) * w + x0 + x]
    }))
}

pub(crate) fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("must be a positive number".into()),
    }
}

/// Runs `render compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    if let Some(frames) = &args.frames {
        return crate::compare_frames::run(args, frames.clone());
    }
    for path in [&args.test, &args.reference] {
        if names_frame(path) && !path.exists() {
            return Err(anyhow!(
                "{}: names a frame; add --frames S..E to compare sequences",
                path.display()
            ));
        }
    }
    let mut test = load_rgb(&args.test)?;
    let mut reference = load_rgb(&args.reference)?;
    if let Some(region) = &args.region {
        test = crop(test, region, &args.test)?;
        reference = crop(reference, region, &args.reference)?;
    }
    let explain = |e| explain(e, &args.test, &args.reference);
    let opts = CompareOptions {
        epsilon: args.epsilon,
        peak: args.peak,
    };
    let metrics = compare(&test, &reference, &opts).map_err(explain)?;
    if let Some(path) = &args.error_image {
        let colours = FalseColourOptions {
            epsilon: args.epsilon,
            ..Default::default()
        };
        let img = error_image(&test, &reference, &colours).map_err(explain)?;
        rt_film::write_rgb(path, &img, &rt_film::OutputOptions::default())
            // The message already holds the cause; `{:#}` would print it twice.
            .map_err(|e| anyhow!("{e}"))?;
    }
    print!("{}", report(&metrics, &opts, args.json));
    Ok(())
}

/// Restates a metrics error with the file names the user typed.
pub(crate) fn explain(e: MetricsError, test: &Path, reference: &Path) -> anyhow::Error {
    let file = |role| match role {
        Role::Test => test.display(),
        Role::Reference => reference.display(),
    };
    match e {
        MetricsError::SizeMismatch {
            test: (tw, th),
            reference: (rw, rh),
        } => anyhow!(
            "{} is {tw}x{th} but {} is {rw}x{rh}",
            test.display(),
            reference.display()
        ),
        MetricsError::NonFinite {
            role,
            x,
            y,
            channel,
            value,
        } => anyhow!(
            "{} has a non-finite value ({value}) at pixel ({x}, {y}), channel {channel}",
            file(role)
        ),
        MetricsError::Empty {
            role,
            width,
            height,
        } => anyhow!("{} is empty ({width}x{height})", file(role)),
        other => other.into(),
    }
}

/// The JSON form; fields serialise in this order.
#[derive(Serialize)]
struct JsonReport {
    mse: f64,
    relmse: f64,
    rmse: f64,
    /// `None` (null) when the images are identical: JSON has no infinity.
    psnr: Option<f64>,
    ssim: f64,
    relmse_epsilon: f64,
    psnr_peak: f64,
}

/// The output: the five metrics in a fixed order, then the settings they depend on. Numbers
/// are printed in Rust's shortest round-trip form, so they parse back to the same `f64`.
fn report(m: &Metrics, opts: &CompareOptions, json: bool) -> String {
    if json {
        let r = JsonReport {
            mse: m.mse,
            relmse: m.relmse,
            rmse: m.rmse,
            psnr: m.psnr.is_finite().then_some(m.psnr),
            ssim: m.ssim,
            relmse_epsilon: opts.epsilon,
            psnr_peak: opts.peak,
        };
        // Serialising plain numbers cannot fail.
        serde_json::to_string(&r).unwrap_or_default() + "\n"
    } else {
        format!(
            "mse {}\nrelmse {}\nrmse {}\npsnr {}\nssim {}\nrelmse_epsilon {}\npsnr_peak {}\n",
            m.mse, m.relmse, m.rmse, m.psnr, m.ssim, opts.epsilon, opts.peak
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const M: Metrics = Metrics {
        mse: 0.25,
        relmse: 0.5,
        rmse: 0.5,
        psnr: f64::INFINITY,
        ssim: 0.75,
    };

    #[test]
    fn text_report() {
        let text = report(&M, &CompareOptions::default(), false);
        assert_eq!(
            text,
            "mse 0.25\nrelmse 0.5\nrmse 0.5\npsnr inf\nssim 0.75\n\
             relmse_epsilon 0.01\npsnr_peak 1\n"
        );
    }

    #[test]
    fn json_report() {
        let text = report(&M, &CompareOptions::default(), true);
        assert_eq!(
            text,
            "{\"mse\":0.25,\"relmse\":0.5,\"rmse\":0.5,\"psnr\":null,\"ssim\":0.75,\
             \"relmse_epsilon\":0.01,\"psnr_peak\":1.0}\n"
        );
        let finite = Metrics { psnr: 6.0, ..M };
        assert!(report(&finite, &CompareOptions::default(), true).contains("\"psnr\":6.0"));
    }

    #[test]
    fn errors_name_the_files() {
        let (a, b) = (Path::new("A.exr"), Path::new("B.exr"));
        let e = explain(
            MetricsError::SizeMismatch {
                test: (64, 64),
                reference: (32, 32),
            },
            a,
            b,
        );
        assert_eq!(e.to_string(), "A.exr is 64x64 but B.exr is 32x32");
        let e = explain(
            MetricsError::NonFinite {
                role: Role::Reference,
                x: 3,
                y: 4,
                channel: 'G',
                value: f32::NAN,
            },
            a,
            b,
        );
        assert_eq!(
            e.to_string(),
            "B.exr has a non-finite value (NaN) at pixel (3, 4), channel G"
        );
    }

    #[test]
    fn options_must_be_positive() {
        assert_eq!(positive("0.02"), Ok(0.02));
        for bad in ["0", "-1", "nan", "inf", "x"] {
            assert!(positive(bad).is_err(), "{bad}");
        }
    }
}
