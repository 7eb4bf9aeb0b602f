//! `rt-filters`: image-space filters that turn a noisy rendering into a cleaner one.
//!
//! The seam is the [`Filter`] trait: a pure function from a [`NoisyFrame`] (the beauty image
//! plus whatever the film recorded: variance, the two half-buffers, first-hit AOVs) to an
//! image. Filters never render; a frame can come straight from the film or be read back from
//! an EXR, so denoising experiments can be re-run without re-rendering. Later issues add the
//! edge-avoiding À-Trous filter (Dammertz), cross-bilateral and NL-means filters and the GREE
//! filter bank; for now there is the [`BoxFilter`], a plain k×k mean that also serves as the
//! simplest member of a filter bank.
//!
//! Depends on `rt-core` and `rt-film`.
//!
//! ```
//! use rt_filters::{BoxFilter, Filter, NoisyFrame};
//! use rt_core::Rgb;
//! let frame = NoisyFrame::from_beauty(3, 1, vec![Rgb::splat(0.0), Rgb::splat(3.0), Rgb::splat(0.0)]);
//! let out = BoxFilter::new(1).unwrap().apply(&frame);
//! assert_eq!(out[1], Rgb::splat(1.0));
//! ```
#![forbid(unsafe_code)]

mod box_filter;
mod frame;

pub use box_filter::BoxFilter;
pub use frame::NoisyFrame;

use rt_core::Rgb;

/// An invalid filter parameter.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum FilterError {
    /// A parameter outside its range.
    #[error("{name}: {message}")]
    Param {
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// An image-space filter. `apply` is pure and deterministic; parameters are validated when the
/// filter is constructed.
pub trait Filter: Send + Sync {
    /// Short name for reports and filter banks.
    fn name(&self) -> &str;

    /// Filters `frame.beauty`, returning an image of the same size (row-major).
    fn apply(&self, frame: &NoisyFrame) -> Vec<Rgb>;
}
