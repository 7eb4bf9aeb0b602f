//! `rt-temporal`: denoising a sequence of frames, where each frame's filter may use what the
//! frames before it saw.
//!
//! - [`svgf`]: spatiotemporal variance-guided filtering (Schied et al. 2017) with Voorhuis'
//!   (2018) extensions for temporally stable reflections: mirrors and sharp glossy surfaces
//!   reproject by where their reflection was, not where their surface was.
//! - [`PerFrame`]: any single-frame `rt_denoise::Denoiser` run on every frame alone, the
//!   baseline temporal stability is measured against.
//! - [`TemporalSpec`]: the one dispatch point, `svgf[:options]` or any single-frame spec.
//!
//! A frame is an `rt_film::NoisyFrame` (its lighting split: emission, direct, indirect) plus the
//! `rt_film::GuideBuffers` the integrators' guide pass writes (noise-free primary features,
//! motion vectors, reflected hits).
//!
//! Depends on `rt-core`, `rt-film` and `rt-denoise` (the option parser and the single-frame
//! denoisers).
//!
//! ```
//! use rt_temporal::{TemporalFrame, TemporalSpec};
//! use rt_film::{GuideBuffers, NoisyFrame, NO_ID};
//! use rt_core::{glam::{Vec2, Vec3}, Image, Rgb};
//! // A flat grey wall seen by a still camera, two frames of noisy light.
//! let (w, h) = (8, 6);
//! let guides = GuideBuffers {
//!     depth: Image::filled(w, h, 2.0),
//!     position: Image::filled(w, h, Vec3::ZERO),
//!     normal: Image::filled(w, h, Vec3::Z),
//!     albedo: Image::filled(w, h, Rgb::splat(0.5)),
//!     emission: Image::filled(w, h, Rgb::ZERO),
//!     motion: Image::filled(w, h, Vec2::ZERO),
//!     previous_depth: Image::filled(w, h, 2.0),
//!     object: Image::filled(w, h, 0),
//!     instance: Image::filled(w, h, NO_ID),
//!     roughness: Image::filled(w, h, 1.0),
//!     reflected: None,
//! };
//! let mut svgf = "svgf:iterations=3".parse::<TemporalSpec>()?.build()?;
//! for k in 0..2 {
//!     let mut frame = NoisyFrame::new(Image::from_fn(w, h, |x, y| Rgb::splat(((x + y + k) % 3) as f32 * 0.1)));
//!     frame.direct = Some(frame.colour.clone());
//!     frame.indirect = Some(Image::filled(w, h, Rgb::ZERO));
//!     frame.emission = Some(Image::filled(w, h, Rgb::ZERO));
//!     let out = svgf.push(&TemporalFrame { frame: &frame, guides: Some(&guides), extra: &[] })?;
//!     assert_eq!(out.size(), (w, h));
//! }
//! # Ok::<(), rt_temporal::TemporalError>(())
//! ```
// `deny`, not `forbid`: the only unsafe code is the À-Trous filter's AVX2 row code (module
// `svgf::atrous_avx2`), which allows itself.
#![deny(unsafe_code)]

mod per_frame;
mod spec;
pub mod svgf;

pub use per_frame::PerFrame;
pub use spec::TemporalSpec;
pub use svgf::{Reflections, Svgf, SvgfInput, SvgfParams};

use rt_core::{Rgb, RgbImage};
use rt_denoise::DenoiseError;
use rt_film::{Channel, FrameError, GuideBuffers, GuideError, NoisyFrame};

/// One frame of a sequence as a temporal denoiser reads it.
#[derive(Clone, Copy, Debug)]
pub struct TemporalFrame<'a> {
    /// The frame's light and whatever channels it has.
    pub frame: &'a NoisyFrame,
    /// Its guide buffers, if rendered.
    pub guides: Option<&'a GuideBuffers>,
    /// Samples 1, 2, ... of every pixel as one-sample frames, when `frame` holds only the
    /// guide ray's sample 0 (denoisers whose [`TemporalDenoiser::guide_samples`] is true);
    /// empty otherwise.
    pub extra: &'a [NoisyFrame],
}

/// The channels of each further sample a guide-sampling denoiser reads.
pub const EXTRA_SAMPLE_CHANNELS: [Channel; 6] = [
    Channel::Direct,
    Channel::Indirect,
    Channel::Emission,
    Channel::Albedo,
    Channel::Normal,
    Channel::Position,
];

/// Why a sequence cannot be denoised.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum TemporalError {
    /// The denoiser cannot be built or a single-frame denoiser failed.
    #[error(transparent)]
    Denoise(#[from] DenoiseError),
    /// A channel is missing or the frame's channels differ in size.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// The frame has no guide buffers but the denoiser needs them.
    #[error("{denoiser} needs the frame's guide buffers (motion vectors, depth, normals), and the frame has none")]
    MissingGuides {
        /// The denoiser.
        denoiser: String,
    },
    /// The guide buffers are malformed or of another size than the frame.
    #[error("{denoiser}: {message}")]
    Guides {
        /// The denoiser.
        denoiser: String,
        /// What is wrong.
        message: String,
    },
}

/// A denoiser of sequences: it sees the frames in order and may keep state between them.
pub trait TemporalDenoiser: Send {
    /// Name with options, for reports.
    fn name(&self) -> &str;

    /// Channels of the noisy frame it reads besides the colour.
    fn needs(&self) -> &[Channel];

    /// True if it reads the guide buffers.
    fn needs_guides(&self) -> bool;

    /// True if, at more than one sample per pixel, it wants the guide ray's sample 0 in the
    /// frame and every further sample apart in [`TemporalFrame::extra`] (supersampling with
    /// guide rays), each with the channels of [`EXTRA_SAMPLE_CHANNELS`].
    fn guide_samples(&self) -> bool {
        false
    }

    /// Filters a frame that has what [`TemporalDenoiser::needs`] (callers go through
    /// [`TemporalDenoiser::push`], which checks).
    fn filter(&mut self, frame: &TemporalFrame<'_>) -> Result<RgbImage, TemporalError>;

    /// Forgets every earlier frame (a cut, or a new sequence).
    fn reset(&mut self);

    /// Checks the frame, filters it, and replaces any non-finite output pixel by zero.
    fn push(&mut self, frame: &TemporalFrame<'_>) -> Result<RgbImage, TemporalError> {
        frame.frame.require(self.name(), self.needs())?;
        for (k, e) in frame.extra.iter().enumerate() {
            e.require(self.name(), &EXTRA_SAMPLE_CHANNELS)?;
            if e.colour.size() != frame.frame.colour.size() {
                return Err(TemporalError::Guides {
                    denoiser: self.name().to_string(),
                    message: format!("sample {} has another size than the frame", k + 1),
                });
            }
        }
        if self.needs_guides() {
            let g = frame.guides.ok_or_else(|| TemporalError::MissingGuides {
                denoiser: self.name().to_string(),
            })?;
            let bad = |message: String| TemporalError::Guides {
                denoiser: self.name().to_string(),
                message,
            };
            g.check().map_err(|e: GuideError| bad(e.to_string()))?;
            if g.size() != frame.frame.colour.size() {
                let (gs, fs) = (g.size(), frame.frame.colour.size());
                return Err(bad(format!(
                    "guide buffers are {}x{}, the frame is {}x{}",
                    gs.0, gs.1, fs.0, fs.1
                )));
            }
        }
        let mut out = self.filter(frame)?;
        for p in out.pixels_mut() {
            if !p.is_finite() {
                *p = Rgb::ZERO;
            }
        }
        Ok(out)
    }
}
