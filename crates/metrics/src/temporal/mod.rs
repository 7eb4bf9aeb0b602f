//! Temporal metrics of image sequences: how much a sequence flickers, how far its
//! frame-to-frame changes are from a reference's, and how long it lags behind a sudden change.
//!
//! | metric | definition | for |
//! |---|---|---|
//! | [`temporal_error`] | mean over consecutive frame pairs of the mean absolute Rec. 709 luminance difference (linear values) | fixed camera, static scene (Schied et al. 2017; Voorhuis 2018) |
//! | [`temporal_relmse`] | mean over steps of relMSE(`f_t − f_{t−1}`, `r_t − r_{t−1}`): `(x − y)² / (y² + ε)` with `y` the reference difference | moving camera or changing light (ours) |
//! | [`lag`] | frames after an event until the per-frame error is at most `factor` × its steady state (the median of a window before the event) | a light toggle (ours, after A-SVGF's test) |
//!
//! [`SequenceComparison`] computes the first two and the per-frame [`compare`](crate::compare)
//! metrics frame by frame, holding only the previous pair of frames. Every sum is taken in
//! `f64` in a fixed order, so results are the same bits for any thread count. Inputs are checked
//! first; problems are [`TemporalError`]s that say which sequence and frame.
//!
//! ```
//! use rt_core::Rgb;
//! use rt_metrics::temporal::{lag, temporal_error, LagOptions};
//! use rt_metrics::RgbImage;
//! // A grey frame flickering between 0.4 and 0.5 (grey luminance equals the value).
//! let frames: Vec<RgbImage> = [0.4, 0.5, 0.4]
//!     .iter()
//!     .map(|&v| RgbImage::from_fn(4, 4, move |_, _| Rgb::splat(v)))
//!     .collect();
//! let t = temporal_error(&frames)?;
//! assert!((t.mean - 0.1).abs() < 1e-6);
//! assert_eq!(t.per_pair.len(), 2);
//! // Errors steady at 1, jumping to 8 at frame 3, then 4, 3, 2: back within 2x at k = 3.
//! let errors = [1.0, 1.0, 1.0, 8.0, 4.0, 3.0, 2.0, 1.0];
//! let l = lag(&errors, 3, &LagOptions { factor: 2.0, window: 3 })?;
//! assert_eq!(l.frames, Some(3));
//! # Ok::<(), rt_metrics::temporal::TemporalError>(())
//! ```

mod error;
mod frames;
mod lag;
mod sequence;
mod temporal_error;
mod temporal_relmse;

pub use error::{Result, TemporalError};
pub use lag::{lag, Lag, LagOptions};
pub use sequence::{FrameMetrics, SequenceComparison, SequenceMetrics, StepMetrics};
pub use temporal_error::{luminance_change_in, temporal_error};
pub use temporal_relmse::temporal_relmse;

/// A temporal metric per pair of consecutive frames and its mean.
#[derive(Clone, Debug, PartialEq)]
pub struct TemporalSeries {
    /// The mean of `per_pair`, summed in order.
    pub mean: f64,
    /// `per_pair[i]`: the value for frames `i` and `i + 1`.
    pub per_pair: Vec<f64>,
}

impl TemporalSeries {
    /// The series of `per_pair` values (at least one) with their mean.
    pub(crate) fn from_pairs(per_pair: Vec<f64>) -> Self {
        let sum: f64 = per_pair.iter().sum();
        Self {
            mean: sum / per_pair.len() as f64,
            per_pair,
        }
    }
}
