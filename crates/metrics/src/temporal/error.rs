//! Why a sequence (or a list of per-frame errors) could not be measured.

use crate::error::{MetricsError, Role};

/// The name of a whole sequence in messages.
fn sequence(role: &Role) -> &'static str {
    match role {
        Role::Test => "test sequence",
        Role::Reference => "reference sequence",
    }
}

/// Errors of the temporal metrics. Frame indices count from 0 within the sequence given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TemporalError {
    /// A sequence with no frames.
    #[error("the {} has no frames", sequence(role))]
    EmptySequence {
        /// Which sequence.
        role: Role,
    },
    /// The test and reference sequences differ in length.
    #[error("the test sequence has {test} frames but the reference sequence has {reference}")]
    LengthMismatch {
        /// Frames of the test sequence.
        test: usize,
        /// Frames of the reference sequence.
        reference: usize,
    },
    /// Too few frames (or per-frame errors) for the metric asked for.
    #[error("{what} needs at least {needed} frames, got {got}")]
    TooFewFrames {
        /// What needs them, e.g. "the temporal error".
        what: &'static str,
        /// How many it needs.
        needed: usize,
        /// How many there were.
        got: usize,
    },
    /// A frame whose size differs from the frame before it in the same sequence.
    #[error(
        "frame {frame} of the {} is {}x{} but frame {} is {}x{}",
        sequence(role), size.0, size.1, frame - 1, previous.0, previous.1
    )]
    FrameSize {
        /// Which sequence.
        role: Role,
        /// The frame (at least 1).
        frame: usize,
        /// Its width and height.
        size: (usize, usize),
        /// Width and height of frame `frame - 1`.
        previous: (usize, usize),
    },
    /// A frame the single-image checks refuse: empty, non-finite, or (for a test frame against
    /// its reference frame) a different size. The cause is part of the message, not a
    /// separate `source`, so that a chain printer does not repeat it.
    #[error("frame {frame}: {cause}")]
    Frame {
        /// The frame.
        frame: usize,
        /// What is wrong with it.
        cause: MetricsError,
    },
    /// A region mask whose length is not the frames' pixel count.
    #[error("the mask has {mask} entries but the frames have {pixels} pixels")]
    MaskSize {
        /// Entries in the mask.
        mask: usize,
        /// Pixels per frame.
        pixels: usize,
    },
    /// [`lag`](super::lag)'s event frame is not one of the per-frame errors.
    #[error("the event frame {event} is outside the {frames} per-frame errors")]
    EventOutOfRange {
        /// The event frame.
        event: usize,
        /// How many per-frame errors there are.
        frames: usize,
    },
    /// A per-frame error given to [`lag`](super::lag) that is negative, NaN or infinite.
    #[error("per-frame error {index} is {value}; errors must be finite and >= 0")]
    BadError {
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// An option outside its domain.
    #[error("{name} must be {requirement}, got {value}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// What it was.
        value: f64,
    },
}

/// `Result` with [`TemporalError`].
pub type Result<T> = std::result::Result<T, TemporalError>;

/// Checks that `value` is finite and greater than zero.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    crate::error::positive(name, value).map_err(|_| TemporalError::InvalidOption {
        name,
        requirement: "positive and finite",
        value,
    })
}
