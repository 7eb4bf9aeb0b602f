//! Frame-by-frame comparison of a test sequence with its reference, holding only the previous
//! pair of frames: what `render compare --frames` streams through.

use super::error::{positive, Result, TemporalError};
use super::frames::check_same_size;
use super::temporal_error::mean_luminance_change;
use super::temporal_relmse::{difference_relmse, Step};
use super::TemporalSeries;
use crate::error::Role;
use crate::image::RgbImage;
use crate::{compare, CompareOptions, Metrics};

/// The temporal metrics of one step, from the previous frame to this one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepMetrics {
    /// Mean absolute luminance change of the test frames ([`temporal_error`](super::temporal_error)).
    pub temporal_error_test: f64,
    /// The same of the reference frames.
    pub temporal_error_reference: f64,
    /// relMSE of the test's difference against the reference's
    /// ([`temporal_relmse`](super::temporal_relmse)).
    pub temporal_relmse: f64,
}

/// Metrics of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameMetrics {
    /// The frame against its reference frame ([`compare`]).
    pub metrics: Metrics,
    /// The step from the previous frame; `None` for the first frame.
    pub step: Option<StepMetrics>,
}

/// Everything [`SequenceComparison`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceMetrics {
    /// Per frame, in the order pushed.
    pub frames: Vec<FrameMetrics>,
    /// Temporal error of the test sequence (per step and mean).
    pub temporal_error_test: TemporalSeries,
    /// Temporal error of the reference sequence.
    pub temporal_error_reference: TemporalSeries,
    /// Temporal relMSE of the test sequence against the reference.
    pub temporal_relmse: TemporalSeries,
}

impl SequenceMetrics {
    /// The mean over frames of one per-frame metric, e.g. `|m| m.relmse`, summed in frame order.
    pub fn mean(&self, metric: impl Fn(&Metrics) -> f64) -> f64 {
        let sum: f64 = self.frames.iter().map(|f| metric(&f.metrics)).sum();
        sum / self.frames.len() as f64
    }

    /// One per-frame metric as a list, e.g. the per-frame relMSE for [`lag`](super::lag).
    pub fn per_frame(&self, metric: impl Fn(&Metrics) -> f64) -> Vec<f64> {
        self.frames.iter().map(|f| metric(&f.metrics)).collect()
    }
}

/// Compares a test sequence with its reference frame by frame as the frames arrive, so that a
/// long sequence never has to be in memory: [`push`](Self::push) each pair of frames in order,
/// then [`finish`](Self::finish). The results are the same bits as [`compare`] on each pair
/// and [`temporal_error`](super::temporal_error) and
/// [`temporal_relmse`](super::temporal_relmse) on the whole sequences.
#[derive(Debug)]
pub struct SequenceComparison {
    opts: CompareOptions,
    previous: Option<(RgbImage, RgbImage)>,
    frames: Vec<FrameMetrics>,
}

impl SequenceComparison {
    /// Starts a comparison; the options are checked here.
    pub fn new(opts: CompareOptions) -> Result<Self> {
        positive("epsilon", opts.epsilon)?;
        positive("peak", opts.peak)?;
        Ok(Self {
            opts,
            previous: None,
            frames: Vec::new(),
        })
    }

    /// Measures the next frame of the test sequence against the same frame of the reference.
    /// Errors name the frame by its index among those pushed: [`TemporalError::Frame`] for a
    /// frame the single-image checks refuse (empty, non-finite, or a size different from its
    /// reference frame), [`TemporalError::FrameSize`] for a size different from the previous
    /// frame's. After an error the comparison is unchanged.
    pub fn push(&mut self, test: RgbImage, reference: RgbImage) -> Result<FrameMetrics> {
        let index = self.frames.len();
        let metrics =
            compare(&test, &reference, &self.opts).map_err(|cause| TemporalError::Frame {
                frame: index,
                cause,
            })?;
        let step = match &self.previous {
            None => None,
            Some((t0, r0)) => {
                // `compare` has checked each image on its own; only the sizes are left.
                check_same_size(Role::Test, index, &test, t0)?;
                check_same_size(Role::Reference, index, &reference, r0)?;
                let step = Step {
                    test: [t0, &test],
                    reference: [r0, &reference],
                };
                Some(StepMetrics {
                    temporal_error_test: mean_luminance_change(t0, &test),
                    temporal_error_reference: mean_luminance_change(r0, &reference),
                    temporal_relmse: difference_relmse(&step, self.opts.epsilon),
                })
            }
        };
        let frame = FrameMetrics { metrics, step };
        self.frames.push(frame);
        self.previous = Some((test, reference));
        Ok(frame)
    }

    /// The per-frame and temporal metrics; at least two frames must have been pushed.
    pub fn finish(self) -> Result<SequenceMetrics> {
        if self.frames.len() < 2 {
            return Err(TemporalError::TooFewFrames {
                what: "the temporal metrics",
                needed: 2,
                got: self.frames.len(),
            });
        }
        let steps: Vec<StepMetrics> = self.frames.iter().filter_map(|f| f.step).collect();
        let series =
            |f: fn(&StepMetrics) -> f64| TemporalSeries::from_pairs(steps.iter().map(f).collect());
        Ok(SequenceMetrics {
            temporal_error_test: series(|s| s.temporal_error_test),
            temporal_error_reference: series(|s| s.temporal_error_reference),
            temporal_relmse: series(|s| s.temporal_relmse),
            frames: self.frames,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::temporal::{temporal_error, temporal_relmse};
    use rt_core::Rgb;
    use rt_testkit::Rng;

    fn noisy(rng: &mut Rng, level: f32) -> RgbImage {
        RgbImage::from_fn(13, 11, |x, y| {
            let base = Rgb::new(x as f32 / 13.0, y as f32 / 11.0, 0.4);
            base + Rgb::new(rng.f32(), rng.f32(), rng.f32()) * level
        })
    }

    #[test]
    fn streaming_equals_the_sequence_functions() {
        let mut rng = Rng::new(7);
        let test: Vec<RgbImage> = (0..5).map(|_| noisy(&mut rng, 0.3)).collect();
        let reference: Vec<RgbImage> = (0..5).map(|_| noisy(&mut rng, 0.01)).collect();
        let opts = CompareOptions {
            epsilon: 0.02,
            ..Default::default()
        };
        let mut s = SequenceComparison::new(opts).unwrap();
        for (t, r) in test.iter().zip(&reference) {
            s.push(t.clone(), r.clone()).unwrap();
        }
        let m = s.finish().unwrap();
        assert_eq!(m.frames.len(), 5);
        assert_eq!(m.frames[0].step, None);
        for (f, (t, r)) in m.frames.iter().zip(test.iter().zip(&reference)) {
            assert_eq!(f.metrics, compare(t, r, &opts).unwrap());
        }
        assert_eq!(m.temporal_error_test, temporal_error(&test).unwrap());
        assert_eq!(
            m.temporal_error_reference,
            temporal_error(&reference).unwrap()
        );
        assert_eq!(
            m.temporal_relmse,
            temporal_relmse(&test, &reference, 0.02).unwrap()
        );
        assert!(m.temporal_error_test.mean > 10.0 * m.temporal_error_reference.mean);
        let relmse = m.per_frame(|m| m.relmse);
        assert_eq!(relmse.len(), 5);
        assert_eq!(m.mean(|m| m.relmse), relmse.iter().sum::<f64>() / 5.0);
    }

    #[test]
    fn errors_name_the_frame_and_leave_the_comparison_usable() {
        let grey = |w, h| RgbImage::from_fn(w, h, |_, _| Rgb::splat(0.5));
        let mut s = SequenceComparison::new(CompareOptions::default()).unwrap();
        s.push(grey(4, 4), grey(4, 4)).unwrap();
        let e = s.push(grey(4, 4), grey(4, 3)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "frame 1: the test image is 4x4 but the reference image is 4x3"
        );
        let e = s.push(grey(3, 4), grey(3, 4)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "frame 1 of the test sequence is 3x4 but frame 0 is 4x4"
        );
        assert!(matches!(
            SequenceComparison::new(CompareOptions::default())
                .unwrap()
                .finish(),
            Err(TemporalError::TooFewFrames { got: 0, .. })
        ));
        s.push(grey(4, 4), grey(4, 4)).unwrap();
        let m = s.finish().unwrap();
        assert_eq!(m.frames.len(), 2);
        assert_eq!(m.temporal_relmse.mean, 0.0);
        assert!(matches!(
            SequenceComparison::new(CompareOptions {
                peak: -1.0,
                ..Default::default()
            }),
            Err(TemporalError::InvalidOption { name: "peak", .. })
        ));
    }
}
