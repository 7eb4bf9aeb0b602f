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
//! The filter bank of Bauszat's GREE (thesis ch. 5): [`Gaussian`] (`gaussian`),
//! [`JointBilateral`] (`bilateral`, guided by normal, position and albedo), [`Nlm`] (`nlm`,
//! Rousselle et al.'s variance-normalised non-local means) and [`GuidedFilter`] (`guided`),
//! built on the shared [`blocks`] (separable Gaussian, summed-area-table box mean, per-offset
//! patch distances), plus the [`BoxBlur`] baseline; [`Bank`] runs several on one frame.
//!
//! [`Sbmf`] (sample-based manifold filtering, Bauszat ch. 4) filters per-sample records rather
//! than pixels; it reads them from a frame that carries them ([`Channel::Samples`]).
//!
//! Depends on `rt-core`, `rt-film` and rayon (rows in parallel, same bits on any pool). The
//! optional feature `oidn` adds `Oidn`, Intel Open Image Denoise loaded at run time
//! (`libloading`); the default build needs nothing native.
//!
//! ```
//! use rt_denoise::{Denoiser, DenoiserSpec, NoisyFrame};
//! use rt_core::{Image, Rgb};
//! let frame = NoisyFrame::new(Image::new(3, 1, vec![Rgb::ZERO, Rgb::splat(3.0), Rgb::ZERO]).unwrap());
//! let denoiser = "box:radius=1".parse::<DenoiserSpec>().unwrap().build().unwrap();
//! let out = denoiser.denoise(&frame).unwrap();
//! assert_eq!(out.pixel(1, 0), Rgb::splat(1.0));
//! ```
// `deny`, not `forbid`: the only unsafe code is the À-Trous filter's AVX2 dispatch (one call)
// and, with the `oidn` feature, the OIDN FFI (module `oidn::ffi`); each allows itself.
#![deny(unsafe_code)]

mod atrous;
mod bank;
mod bilateral;
pub mod blocks;
mod box_blur;
mod gaussian;
mod guided;
mod nlm;
#[cfg(feature = "oidn")]
mod oidn;
pub mod sbmf;
pub mod spec;

pub use atrous::{Atrous, Demodulate, Halve, Split};
pub use bank::{Bank, BankOutput, DEFAULT_BANK};
pub use bilateral::{JointBilateral, VarianceUse};
pub use box_blur::BoxBlur;
pub use gaussian::Gaussian;
pub use guided::{Guide, GuidedFilter};
pub use nlm::Nlm;
#[cfg(feature = "oidn")]
pub use oidn::{Oidn, OidnParams, OidnQuality, OIDN_LIB_DEFAULTS, OIDN_LIB_ENV};
pub use rt_film::{Channel, FrameError, NoisyFrame};
pub use sbmf::{Sbmf, SbmfParams};
pub use spec::{DenoiserKind, DenoiserOptions, DenoiserSpec, Options};

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

    /// A native library the denoiser calls is missing or failed (e.g. Open Image Denoise).
    #[error("{denoiser}: {message}")]
    Native {
        /// The denoiser.
        denoiser: &'static str,
        /// What was tried and what went wrong.
        message: String,
    },
}

/// An option that breaks the option grammar, or that nothing reads, is a spec error (values
/// out of range are [`DenoiseError::Param`]s, from [`DenoiserOptions`]).
impl From<rt_core::options::OptionsError> for DenoiseError {
    fn from(e: rt_core::options::OptionsError) -> Self {
        DenoiseError::Spec(e.to_string())
    }
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
