//! `rt-denoise`: denoisers, image-space filters that turn a noisy rendering into a cleaner one
//! (not pixel reconstruction filters, which weigh samples into pixels while rendering).
//!
//! The seam is the [`Denoiser`] trait: a pure, deterministic function from a [`NoisyFrame`]
//! (the pixel means plus whatever the film recorded: variance, half-buffers, first-hit
//! features with their variances, the lighting split) to an image. Denoisers never render; a
//! frame comes straight from the film or is read back from an EXR
//! ([`NoisyFrame::from_exr`]), so denoising experiments re-run without re-rendering.
//! Parameters are validated when a denoiser is built; a frame that lacks a channel the
//! denoiser needs is refused by [`Denoiser::denoise`] with one line naming the channel.
//!
//! [`DenoiserSpec`] is the one place denoisers are named, parsed from text such as
//! `gaussian:sigma=4` and built, so a program using this crate offers the same choice as
//! `render denoise --denoiser`.
//!
//! [`Sbmf`] (sample-based manifold filtering) filters per-sample records rather than a frame
//! and has its own entry point, [`Sbmf::filter_samples`].
//!
//! Depends on `rt-core`, `rt-film` and `rayon`.
//!
//! ```
//! use rt_denoise::{Denoiser, DenoiserSpec, NoisyFrame};
//! use rt_core::{Image, Rgb};
//! let frame = NoisyFrame::new(Image::new(3, 1, vec![Rgb::ZERO, Rgb::splat(3.0), Rgb::ZERO]).unwrap());
//! let denoiser = "box:radius=1".parse::<DenoiserSpec>().unwrap().build().unwrap();
//! let out = denoiser.denoise(&frame).unwrap();
//! assert_eq!(out.pixel(1, 0), Rgb::splat(1.0));
//! ```
#![forbid(unsafe_code)]

mod box_blur;
pub mod sbmf;
pub mod spec;

pub use box_blur::BoxBlur;
pub use rt_film::{Channel, FrameError, NoisyFrame};
pub use sbmf::{Sbmf, SbmfParams};
pub use spec::{DenoiserKind, DenoiserSpec, Options};

use rt_core::RgbImage;

/// Why a denoiser cannot be built or cannot run.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum DenoiseError {
    /// A parameter outside its range.
    #[error("{denoiser}: {name}: {message}")]
    Param {
        /// The denoiser.
        denoiser: &'static str,
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The frame lacks a channel or its channels differ in size.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// A denoiser spec that does not parse.
    #[error("{0}")]
    Spec(String),
}

/// An image-space denoiser: pure and deterministic (the same frame gives the same bits on any
/// thread count), with parameters validated when it is constructed.
pub trait Denoiser: Send + Sync {
    /// Short name for reports, errors and filter banks (with its options, e.g.
    /// `gaussian:sigma=4`).
    fn name(&self) -> &str;

    /// The channels the denoiser reads besides the colour image.
    fn needs(&self) -> &[Channel] {
        &[]
    }

    /// Filters a frame that has every channel of [`Denoiser::needs`] (callers go through
    /// [`Denoiser::denoise`], which checks). Returns an image of the frame's size.
    fn filter(&self, frame: &NoisyFrame) -> RgbImage;

    /// Checks the frame, filters it, and replaces any non-finite output pixel by zero so that
    /// no NaN or Inf reaches an output buffer.
    fn denoise(&self, frame: &NoisyFrame) -> Result<RgbImage, DenoiseError> {
        frame.require(self.name(), self.needs())?;
        let mut out = self.filter(frame);
        debug_assert_eq!(out.size(), frame.colour.size(), "{}", self.name());
        for p in out.pixels_mut() {
            if !p.is_finite() {
                *p = rt_core::Rgb::ZERO;
            }
        }
        Ok(out)
    }
}
