//! `render compare` without the CLI: image A measured against the reference B (MSE, relMSE,
//! RMSE, PSNR, SSIM from `rt-metrics`), or the frames of sequence A against those of B with the
//! temporal metrics of `rt_metrics::temporal`; the reports as `name value` lines or one JSON
//! object. Errors name the files. Definitions: docs/experiments.md.

use rt_metrics::temporal::{
    FrameMetrics, Lag, LagOptions, SequenceComparison, SequenceMetrics, TemporalError,
};
use rt_metrics::{
    error_image, CompareOptions, FalseColourOptions, Metrics, MetricsError, RgbImage, Role,
};
use rt_session::frames::frame_path;
use serde::Serialize;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Why two images or sequences cannot be compared. One line naming the files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    /// An image that cannot be read or written.
    #[error(transparent)]
    Image(#[from] rt_film::FilmError),
    /// Two images that cannot be compared (sizes, bad values), with the files named.
    #[error("{0}")]
    Images(String),
    /// A region that is not inside the image.
    #[error("{x0},{y0},{x1},{y1} is not a non-empty rectangle inside the {width}x{height} image {}", path.display(), x0 = region[0], y0 = region[1], x1 = region[2], y1 = region[3])]
    Region {
        /// x0, y0, x1, y1.
        region: [usize; 4],
        /// Width of the image.
        width: usize,
        /// Height of the image.
        height: usize,
        /// The image.
        path: PathBuf,
    },
    /// A sequence comparison that cannot give a result (too few frames, an event outside
    /// them), refused before any file is read.
    #[error("{0}")]
    Refused(String),
    /// The sequence's metrics refused (too few frames, bad options).
    #[error(transparent)]
    Temporal(#[from] TemporalError),
}

/// `image` cut to `region` (x0, y0, x1, y1; half-open, row 0 at the top).
pub fn crop(image: RgbImage, region: [usize; 4], path: &Path) -> Result<RgbImage, CompareError> {
    let [x0, y0, x1, y1] = region;
    let (w, h) = (image.width(), image.height());
    if x0 >= x1 || y0 >= y1 || x1 > w || y1 > h {
        return Err(CompareError::Region {
            region,
            width: w,
            height: h,
            path: path.to_path_buf(),
        });
    }
    let px = image.pixels();
    Ok(RgbImage::from_fn(x1 - x0, y1 - y0, |x, y| {
        px[(y0 + y) * w + x0 + x]
    }))
}

/// Reads an image (cropped to `region`).
pub fn load(path: &Path, region: Option<[usize; 4]>) -> Result<RgbImage, CompareError> {
    let image = rt_film::read_rgb(path)?;
    match region {
        Some(r) => crop(image, r, path),
        None => Ok(image),
    }
}

/// Restates a metrics error with the file names the user typed.
pub fn explain(e: MetricsError, test: &Path, reference: &Path) -> CompareError {
    let file = |role| match role {
        Role::Test => test.display(),
        Role::Reference => reference.display(),
    };
    CompareError::Images(match e {
        MetricsError::SizeMismatch {
            test: (tw, th),
            reference: (rw, rh),
        } => format!(
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
        } => format!(
            "{} has a non-finite value ({value}) at pixel ({x}, {y}), channel {channel}",
            file(role)
        ),
        MetricsError::Empty {
            role,
            width,
            height,
        } => format!("{} is empty ({width}x{height})", file(role)),
        other => other.to_string(),
    })
}

/// Two images to compare, or two sequences (`test` and `reference` then name the frame, a
/// `reference` without a placeholder serving every frame).
#[derive(Clone, Debug)]
pub struct Comparison {
    /// A: the image measured.
    pub test: PathBuf,
    /// B: the reference.
    pub reference: PathBuf,
    /// Only these pixels (x0, y0, x1, y1) of both.
    pub region: Option<[usize; 4]>,
    /// relMSE's epsilon and PSNR's peak.
    pub options: CompareOptions,
    /// Where to write the false-colour error image (for a sequence, a name with the frame).
    pub error_image: Option<PathBuf>,
}

impl Comparison {
    fn write_error_image(
        &self,
        test: &RgbImage,
        reference: &RgbImage,
        path: &Path,
        files: (&Path, &Path),
    ) -> Result<(), CompareError> {
        let colours = FalseColourOptions {
            epsilon: self.options.epsilon,
            ..Default::default()
        };
        let img =
            error_image(test, reference, &colours).map_err(|e| explain(e, files.0, files.1))?;
        rt_film::write_rgb(path, &img, &rt_film::OutputOptions::default())?;
        Ok(())
    }

    /// Refuses, before any file is read, a comparison of `frames` (with the lag after `event`
    /// over a steady state of `window` frames before it) that cannot give a result. The
    /// messages name `render compare`'s flags, as the user gave them.
    pub fn check_sequence(
        &self,
        frames: &Range<u32>,
        event: Option<(u32, u32)>,
    ) -> Result<(), CompareError> {
        let refuse = |m: String| Err(CompareError::Refused(m));
        let names = rt_session::frames::names_frame;
        if !names(&self.test) {
            return refuse(format!(
                "{}: --frames needs an A that names the frame, e.g. 'a_{{frame:04}}.exr'",
                self.test.display()
            ));
        }
        let (start, end) = (frames.start, frames.end);
        if frames.len() < 2 {
            return refuse(format!(
                "--frames {start}..{end} holds one frame; the temporal metrics need at least two"
            ));
        }
        if let Some(path) = self.error_image.as_ref().filter(|p| !names(p)) {
            return refuse(format!(
                "{}: with --frames, --error-image must name the frame, e.g. 'err_{{frame:04}}.png'",
                path.display()
            ));
        }
        let Some((event, window)) = event else {
            return Ok(());
        };
        if !frames.contains(&event) {
            return refuse(format!(
                "--event {event} is not one of --frames {start}..{end}"
            ));
        }
        let before = event - start;
        if before < window {
            return refuse(format!(
                "--event {event}: the lag's steady state needs --lag-window {window} frames before it, but --frames {start}..{end} has {before}"
            ));
        }
        Ok(())
    }

    /// The metrics of A against B, and the error image if asked for. A missing file whose
    /// name holds a frame placeholder is refused with a hint at sequences.
    pub fn images(&self) -> Result<Metrics, CompareError> {
        for path in [&self.test, &self.reference] {
            if rt_session::frames::names_frame(path) && !path.exists() {
                return Err(CompareError::Refused(format!(
                    "{}: names a frame; add --frames S..E to compare sequences",
                    path.display()
                )));
            }
        }
        let test = load(&self.test, self.region)?;
        let reference = load(&self.reference, self.region)?;
        let files = (self.test.as_path(), self.reference.as_path());
        let metrics = rt_metrics::compare(&test, &reference, &self.options)
            .map_err(|e| explain(e, files.0, files.1))?;
        if let Some(path) = &self.error_image {
            self.write_error_image(&test, &reference, path, files)?;
        }
        Ok(metrics)
    }

    /// Frames `frames` of A against B's, with the temporal metrics; one error image per frame
    /// if asked for. Frames are read one pair at a time.
    pub fn sequences(&self, frames: Range<u32>) -> Result<SequenceMetrics, CompareError> {
        let mut sequence = SequenceComparison::new(self.options)?;
        // A reference without a frame placeholder serves every frame; it is read once.
        let fixed_reference = match rt_session::frames::names_frame(&self.reference) {
            true => None,
            false => Some(load(&self.reference, self.region)?),
        };
        for f in frames {
            let (a, b) = (frame_path(&self.test, f), frame_path(&self.reference, f));
            let test = load(&a, self.region)?;
            let reference = match &fixed_reference {
                Some(r) => r.clone(),
                None => load(&b, self.region)?,
            };
            if let Some(pattern) = &self.error_image {
                self.write_error_image(&test, &reference, &frame_path(pattern, f), (&a, &b))?;
            }
            sequence
                .push(test, reference)
                .map_err(|e| self.explain_frame(e, f))?;
        }
        Ok(sequence.finish()?)
    }

    /// Restates a frame's error with the files of that frame (and of the one before it).
    fn explain_frame(&self, e: TemporalError, frame: u32) -> CompareError {
        let file = |role, f| -> PathBuf {
            match role {
                Role::Test => frame_path(&self.test, f),
                Role::Reference => frame_path(&self.reference, f),
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
            } => CompareError::Images(format!(
                "{} is {w}x{h} but {} is {pw}x{ph}",
                file(role, frame).display(),
                file(role, frame - 1).display()
            )),
            other => CompareError::Images(format!("frame {frame}: {other}")),
        }
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
pub fn report(m: &Metrics, opts: &CompareOptions, json: bool) -> String {
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

/// The lag as measured, with the settings it depends on.
pub struct LagReport {
    /// The first frame after the change.
    pub event: u32,
    /// The measured lag.
    pub lag: Lag,
    /// Its settings.
    pub opts: LagOptions,
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

/// The JSON form of a sequence; fields serialise in this order.
#[derive(Serialize)]
struct JsonSequence {
    frames: Vec<JsonFrame>,
    mean_mse: f64,
    mean_relmse: f64,
    mean_ssim: f64,
    temporal_error_a: f64,
    temporal_error_b: f64,
    temporal_relmse: f64,
    /// Null without an event.
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

/// A sequence's output: one line per frame (`frame F` then `name value` pairs; from the second
/// frame on also the step from the frame before), then the sequence's `name value` lines and
/// the settings they depend on. Numbers in Rust's shortest round-trip form.
pub fn sequence_report(
    first: u32,
    m: &SequenceMetrics,
    lag: Option<&LagReport>,
    opts: &CompareOptions,
    json: bool,
) -> String {
    let numbered = || (first..).zip(&m.frames);
    if json {
        let r = JsonSequence {
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
}
