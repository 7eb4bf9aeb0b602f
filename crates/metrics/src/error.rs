//! The crate's error type.

use std::fmt;

/// Which of the two images an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The image being measured (`A` in `render compare A B`).
    Test,
    /// The ground truth it is measured against (`B`); relMSE divides by it.
    Reference,
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Role::Test => "test image",
            Role::Reference => "reference image",
        })
    }
}

/// Why two images could not be compared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MetricsError {
    /// [`RgbImage::new`](crate::RgbImage::new) got a pixel vector of the wrong length.
    #[error(transparent)]
    PixelCount(#[from] rt_core::PixelCountError),
    /// An image has no pixels, so no mean exists.
    #[error("the {role} is empty ({width}x{height})")]
    Empty {
        /// Which image.
        role: Role,
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// The images differ in size.
    #[error(
        "the test image is {}x{} but the reference image is {}x{}",
        test.0, test.1, reference.0, reference.1
    )]
    SizeMismatch {
        /// Width and height of the test image.
        test: (usize, usize),
        /// Width and height of the reference image.
        reference: (usize, usize),
    },
    /// A NaN or infinite value, which would make every mean meaningless. The first one in
    /// row-major order (rows from the top) is reported.
    #[error("the {role} has a non-finite value ({value}) at pixel ({x}, {y}), channel {channel}")]
    NonFinite {
        /// Which image.
        role: Role,
        /// Column, from the left.
        x: usize,
        /// Row, from the top.
        y: usize,
        /// `R`, `G` or `B`.
        channel: char,
        /// The value (NaN, inf or -inf).
        value: f32,
    },
    /// An option outside its domain (e.g. a non-positive epsilon).
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

/// `Result` with [`MetricsError`].
pub type Result<T> = std::result::Result<T, MetricsError>;

/// Checks that `value` is finite and greater than zero.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MetricsError::InvalidOption {
            name,
            requirement: "positive and finite",
            value,
        })
    }
}
