//! Lag: how many frames a temporal filter needs to catch up after the scene changes.

use super::error::{positive, Result, TemporalError};

/// Settings of [`lag`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagOptions {
    /// The error has recovered when it is at most `factor` × the steady state (default 2, the
    /// issue's "within 2×"); must be positive.
    pub factor: f64,
    /// The steady state is the median of this many per-frame errors just before the event
    /// (default 10); at least 1.
    pub window: usize,
}

impl Default for LagOptions {
    fn default() -> Self {
        Self {
            factor: 2.0,
            window: 10,
        }
    }
}

/// What [`lag`] measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lag {
    /// Frames from the event until the error is back within the threshold: `k` when frame
    /// `event + k` is the first such frame (0 if the event frame already is). `None` when no
    /// frame from the event to the end of the sequence is.
    pub frames: Option<usize>,
    /// The median error over the window before the event.
    pub steady_state: f64,
    /// `factor × steady_state`.
    pub threshold: f64,
}

/// Median of a short list (the mean of the two middle values for an even count).
fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Lag after an event (e.g. a light switched on or off) in a sequence of per-frame errors
/// `errors[t]` (e.g. each frame's relMSE against its own reference frame): the number of frames
/// from the event until the error is back within `factor` × its steady state.
///
/// - `event` indexes `errors`: the first frame rendered after the change.
/// - The steady state is the **median** of the `window` errors just before the event,
///   `errors[event − window .. event]`. The median rather than the mean, so that one noisy
///   frame (a firefly) in the window does not move the threshold much.
/// - The lag is the smallest `k ≥ 0` with `errors[event + k] ≤ factor × steady state`: the
///   first frame back within the threshold, whether or not a later frame leaves it again
///   (per-frame errors of noisy frames do).
///
/// The measure is ours, after the light-toggle scene of Schied et al., "Gradient Estimation for
/// Real-Time Adaptive Temporal Filtering" (HPG 2018), whose A-SVGF was built to shorten it; the
/// factor 2 is the target. With an exponential moving average of weight α and an error
/// that decays as `(1 − α)^k`, the lag grows like `ln(jump / steady) / −ln(1 − α)`.
///
/// Errors: every value must be finite and ≥ 0; `event` must index `errors`; there must be
/// `window` errors before it.
pub fn lag(errors: &[f64], event: usize, opts: &LagOptions) -> Result<Lag> {
    let factor = positive("factor", opts.factor)?;
    if opts.window == 0 {
        return Err(TemporalError::InvalidOption {
            name: "window",
            requirement: "at least 1",
            value: 0.0,
        });
    }
    if let Some((index, &value)) = errors
        .iter()
        .enumerate()
        .find(|(_, e)| !(e.is_finite() && **e >= 0.0))
    {
        return Err(TemporalError::BadError { index, value });
    }
    if event >= errors.len() {
        return Err(TemporalError::EventOutOfRange {
            event,
            frames: errors.len(),
        });
    }
    if event < opts.window {
        return Err(TemporalError::TooFewFrames {
            what: "the steady state before the event",
            needed: opts.window,
            got: event,
        });
    }
    let steady_state = median(&errors[event - opts.window..event]);
    let threshold = factor * steady_state;
    let frames = errors[event..].iter().position(|&e| e <= threshold);
    Ok(Lag {
        frames,
        steady_state,
        threshold,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A steady error `s` before frame `event`, then `s + jump · (1 − alpha)^k` at `event + k`:
    /// what an exponential moving average with weight alpha leaves of a sudden change.
    fn recovery(s: f64, jump: f64, alpha: f64, event: usize, len: usize) -> Vec<f64> {
        (0..len)
            .map(|t| {
                if t < event {
                    s
                } else {
                    s + jump * (1.0 - alpha).powi((t - event) as i32)
                }
            })
            .collect()
    }

    #[test]
    fn exponential_recovery_has_the_exact_lag() {
        // Within 2s when jump · 0.8^k ≤ s, i.e. k ≥ ln(100) / ln(1.25) = 20.64: k = 21.
        let e = recovery(0.01, 1.0, 0.2, 30, 80);
        let l = lag(&e, 30, &LagOptions::default()).unwrap();
        assert_eq!(l.frames, Some(21));
        assert_eq!(l.steady_state, 0.01);
        assert_eq!(l.threshold, 0.02);
        // Factor 5: jump · 0.8^k ≤ 4s, k ≥ ln(25) / ln(1.25) = 14.43: k = 15.
        let opts = LagOptions {
            factor: 5.0,
            window: 10,
        };
        assert_eq!(lag(&e, 30, &opts).unwrap().frames, Some(15));
        // alpha = 0.5: k ≥ ln(100) / ln(2) = 6.64: k = 7.
        let e = recovery(0.01, 1.0, 0.5, 12, 40);
        assert_eq!(lag(&e, 12, &LagOptions::default()).unwrap().frames, Some(7));
    }

    #[test]
    fn no_recovery_is_none() {
        // 0.8^k ≤ 0.01 needs k = 21 frames; the sequence ends 15 frames after the event.
        let e = recovery(0.01, 1.0, 0.2, 30, 45);
        let l = lag(&e, 30, &LagOptions::default()).unwrap();
        assert_eq!(l.frames, None);
    }

    #[test]
    fn no_disturbance_is_zero_lag() {
        let e = vec![0.5; 20];
        assert_eq!(lag(&e, 10, &LagOptions::default()).unwrap().frames, Some(0));
    }

    #[test]
    fn the_steady_state_is_the_median_of_the_window() {
        // Window [3, 1, 100, 2] (one firefly): median (2 + 3) / 2 = 2.5, threshold 5. The mean,
        // 26.5, would accept the 6 at the event frame. Frames before the window are ignored.
        let e = [1000.0, 3.0, 1.0, 100.0, 2.0, 6.0, 5.5, 5.0, 1.0];
        let opts = LagOptions {
            factor: 2.0,
            window: 4,
        };
        let l = lag(&e, 5, &opts).unwrap();
        assert_eq!(l.steady_state, 2.5);
        assert_eq!(l.threshold, 5.0);
        assert_eq!(l.frames, Some(2));
        // An odd window: [1, 100, 2] has median 2, threshold 4: frame 8 (k = 3).
        let opts = LagOptions {
            factor: 2.0,
            window: 3,
        };
        assert_eq!(lag(&e, 5, &opts).unwrap().frames, Some(3));
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let e = vec![0.1; 20];
        let d = LagOptions::default();
        assert_eq!(
            lag(&e, 20, &d),
            Err(TemporalError::EventOutOfRange {
                event: 20,
                frames: 20
            })
        );
        let err = lag(&e, 5, &d).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the steady state before the event needs at least 10 frames, got 5"
        );
        let mut bad = e.clone();
        bad[3] = f64::NAN;
        assert!(matches!(
            lag(&bad, 15, &d),
            Err(TemporalError::BadError { index: 3, .. })
        ));
        bad[3] = -1.0;
        assert!(matches!(
            lag(&bad, 15, &d),
            Err(TemporalError::BadError { index: 3, .. })
        ));
        for opts in [
            LagOptions { factor: 0.0, ..d },
            LagOptions {
                factor: f64::NAN,
                ..d
            },
            LagOptions { window: 0, ..d },
        ] {
            assert!(matches!(
                lag(&e, 15, &opts),
                Err(TemporalError::InvalidOption { .. })
            ));
        }
        assert!(matches!(
            lag(&[], 0, &d),
            Err(TemporalError::EventOutOfRange { .. })
        ));
    }
}
