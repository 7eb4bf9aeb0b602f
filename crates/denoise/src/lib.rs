//! `rt-denoise`: denoisers, image-space filters that turn a noisy rendering into a cleaner one
//! (not pixel reconstruction filters, which weigh samples into pixels while rendering).
//!
//! The seam is the [`Denoiser`] trait: a pure function from a [`NoisyFrame`] (the beauty image
//! plus whatever the film recorded: variance, the two half-buffers, first-hit AOVs) to an
//! image. Filters never render; a frame can come straight from the film or be read back from
//! an EXR, so denoising experiments can be re-run without re-rendering. Later issues add the
//! edge-avoiding À-Trous filter (Dammertz), cross-bilateral and NL-means filters and the GREE
//! filter bank; for now there is [`BoxBlur`], a plain k×k mean that also serves as the
//! simplest member of a filter bank.
//!
//! Depends on `rt-core` and `rt-film`.
//!
//! ```
//! use rt_denoise::{BoxBlur, Denoiser, NoisyFrame};
//! use rt_core::Rgb;
//! let frame = NoisyFrame::from_beauty(3, 1, vec![Rgb::splat(0.0), Rgb::splat(3.0), Rgb::splat(0.0)]);
//! let out = BoxBlur::new(1).unwrap().apply(&frame);
//! assert_eq!(out[1], Rgb::splat(1.0));
//! ```
#![forbid(unsafe_code)]

mod box_blur;
mod frame;

pub use box_blur::BoxBlur;
pub use frame::NoisyFrame;

use rt_core::Rgb;

/// An invalid denoiser parameter.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum DenoiseError {
    /// A parameter outside its range.
    #[error("{name}: {message}")]
    Param {
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// An image-space denoiser. `apply` is pure and deterministic; parameters are validated when the
/// denoiser is constructed.
pub trait Denoiser: Send + Sync {
    /// Short name for reports and filter banks.
    fn name(&self) -> &str;

    /// Filters `frame.beauty`, returning an image of the same size (row-major).
    fn apply(&self, frame: &NoisyFrame) -> Vec<Rgb>;
}
