//! The crate's error type.

use std::convert::Infallible;

/// Why GREE could not run. Generic over the error of the [`CacheRenderer`](crate::CacheRenderer)
/// (`Infallible` where no renderer is involved, as in [`GreeParams::validate`](crate::GreeParams::validate)).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GreeError<E = Infallible> {
    /// A parameter outside its domain.
    #[error("{name} must be {requirement}, got {value}")]
    InvalidParam {
        /// The parameter's name (as in [`GreeParams`](crate::GreeParams)).
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// What it was.
        value: f64,
    },
    /// The filter bank has no images.
    #[error("the filter bank is empty")]
    EmptyBank,
    /// More filters than a `u16` label can name.
    #[error("{count} filters do not fit in u16 labels")]
    TooManyFilters {
        /// Number of filters given.
        count: usize,
    },
    /// The noisy image has no pixels.
    #[error("the noisy image is empty ({width}x{height})")]
    EmptyImage {
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// An input image differs in size from the noisy image.
    #[error("{what} is {}x{} but the noisy image is {}x{}", got.0, got.1, expected.0, expected.1)]
    SizeMismatch {
        /// Which input (`"variance_of_mean"`, `"bank[3]"`, ...).
        what: String,
        /// Size of the noisy image.
        expected: (usize, usize),
        /// Size of this input.
        got: (usize, usize),
    },
    /// A NaN or infinite value in an input (the first one in row-major order).
    #[error("{what} has a non-finite value at pixel ({x}, {y})")]
    NonFinite {
        /// Which input.
        what: String,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
    },
    /// A negative variance.
    #[error("variance_of_mean is negative at pixel ({x}, {y})")]
    NegativeVariance {
        /// Column.
        x: usize,
        /// Row.
        y: usize,
    },
    /// The renderer returned a different number of cache values than pixels asked for, or a
    /// non-finite one.
    #[error("the cache renderer returned {got} values for {expected} pixels")]
    CacheCount {
        /// Pixels asked for.
        expected: usize,
        /// Values returned.
        got: usize,
    },
    /// The renderer returned a NaN or infinite cache value.
    #[error("the cache renderer returned a non-finite value at pixel ({x}, {y})")]
    NonFiniteCache {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The cache triangulation failed (the placement makes distinct in-bounds pixels, so
    /// this is not expected).
    #[error("interpolating the cache errors failed")]
    Interpolation(#[source] crate::interpolate::InterpolateError),
    /// The renderer failed.
    #[error("rendering the filter caches failed")]
    Renderer(#[source] E),
}

impl GreeError<Infallible> {
    /// The same error with another renderer-error type (a renderer-free error can be any
    /// `GreeError<E>`).
    pub fn widen<E>(self) -> GreeError<E> {
        match self {
            GreeError::InvalidParam {
                name,
                requirement,
                value,
            } => GreeError::InvalidParam {
                name,
                requirement,
                value,
            },
            GreeError::EmptyBank => GreeError::EmptyBank,
            GreeError::TooManyFilters { count } => GreeError::TooManyFilters { count },
            GreeError::EmptyImage { width, height } => GreeError::EmptyImage { width, height },
            GreeError::SizeMismatch {
                what,
                expected,
                got,
            } => GreeError::SizeMismatch {
                what,
                expected,
                got,
            },
            GreeError::NonFinite { what, x, y } => GreeError::NonFinite { what, x, y },
            GreeError::NegativeVariance { x, y } => GreeError::NegativeVariance { x, y },
            GreeError::CacheCount { expected, got } => GreeError::CacheCount { expected, got },
            GreeError::NonFiniteCache { x, y } => GreeError::NonFiniteCache { x, y },
            GreeError::Interpolation(e) => GreeError::Interpolation(e),
            GreeError::Renderer(e) => match e {},
        }
    }
}
