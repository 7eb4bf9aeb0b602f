//! `rt-film`: where samples land, and how images leave the renderer.
//!
//! [`Film`] keeps per-pixel statistics in separate buffers, and only those a consumer asked
//! for in its [`FilmBuffers`]: the sum and sample count always (52 bytes per pixel); the sums
//! of squares for the variance of the mean (96 bytes); the even-numbered samples' sums, from
//! which the two half-images that the thesis' stopping criterion (Dammertz §6.2) and the
//! error estimators of the denoisers compare follow (64 bytes); each first-hit AOV (albedo,
//! shading normal, depth, world position), their sums of squares and their shared hit count;
//! and, for sample-space filters, every sample kept apart ([`SampleRecords`], 56 bytes per
//! sample). [`Film::memory`] reports what is held. Nothing non-finite ever enters a buffer:
//! such samples are counted and dropped.
//!
//! Every sum is exact: each sample's value is rounded once to a grid of 2⁻³² and added as a
//! 128-bit integer (the `fixed` module says why, and what it costs). So the order samples
//! arrive in never changes a bit: [`Film::encode_sums`] and [`Film::add_encoded`] carry the
//! sums of a rectangle ([`Rect`]) between machines, and the film that adds up the parts of a
//! render (sample ranges, regions, a checkpoint and what came after it) is the film of the
//! whole render, bit for bit (`rt-parts` builds part files and plans on this). The encoding
//! is a flags byte (bit 0: splats present; bit 1: filtered sums present), the discarded-sample count (`u64`), with splats
//! the light paths and even-index light paths taken (two `u64`), then each kept buffer in a
//! fixed order, one element per pixel of the rectangle, row-major, little-endian; the reader
//! derives every length from its own buffers and the rectangle and checks the total first.
//!
//! Light paths land on any pixel: their [`Splat`]s are summed apart (exactly, allocated at the
//! first splat) and divided by the number of light paths taken; the image is the camera
//! samples' mean plus that ([`Film::mean_image`]).
//!
//! A camera whose pixel filter splats (`rt_core::pixel_filter`, Mitsuba's way) adds each sample
//! to every pixel under the filter ([`FilmStripe::add_filtered`]): the film then keeps
//! filter-weighted sums and sums of weights (exact, allocated with the first such sample; each
//! band of rows collects what crosses its border and adds it when the band ends), and its image
//! and half-images are their ratios.
//!
//! [`input`] reads any image (EXR, PNG, JPEG) as a linear [`rt_core::RgbImage`]. [`output`]
//! writes EXR (linear float, AOVs as extra channel groups) and PNG (tone mapped
//! sRGB), always atomically: a temporary file in the target directory renamed into place.
//!
//! Depends on `rt-core` (for `Rgb`), `exr` and `image`.
//!
//! ```
//! use rt_film::{AovSet, Film, FilmBuffers};
//! use rt_core::glam::Vec3;
//! // A consumer that reads the variance asks for it; the half-buffers are left out.
//! let mut film = Film::new(2, 1, FilmBuffers::for_outputs(AovSet::default()).with_variance());
//! for (i, v) in [1.0, 3.0].into_iter().enumerate() {
//!     film.add_sample(0, 0, i as u32, Vec3::splat(v), None);
//! }
//! assert_eq!(film.pixel(0, 0).mean(), Vec3::splat(2.0));
//! assert_eq!(film.pixel(0, 0).variance_of_mean(), Some(Vec3::splat(1.0)));
//! assert!(film.half_image(0).is_none());
//! assert_eq!(film.memory_bytes(), 2 * (52 + 96));
//! ```
#![forbid(unsafe_code)]

mod aov_set;
mod buffers;
mod film;
mod filtered;
mod fixed;
mod guides;
pub mod input;
mod noisy_frame;
pub mod output;
mod pixel;
mod raw;
pub mod samples;
mod splat;
pub mod stopping;

pub use aov_set::{AovFlag, AovSet, UnknownAov, AOV_FLAGS, AOV_NAMES};
pub use buffers::{FilmBuffers, FilmMemory, LateSums};
pub use film::{FeatureVariances, Film, FilmStripe};
pub use guides::{GuideBuffers, GuideError, ReflectedGuides, NO_ID};
pub use input::{decode_raw, decode_srgb, read_rgb};
pub use noisy_frame::{Channel, FrameError, NoisyFrame};
pub use output::{
    copy_atomic, read_exr, srgb8, write_bytes_atomic, write_image, write_image_with, write_rgb,
    ExrImage, FilmError, OutputOptions,
};
pub use pixel::{accepts_sample, FirstHit, HalfSums, LightSplit, PixelStats};
pub use raw::{RawError, Rect};
pub use samples::{Sample, SampleBand, SampleRecords, SampleRecordsError};
pub use splat::Splat;
