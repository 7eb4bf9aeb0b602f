//! `rt-film`: where samples land, and how images leave the renderer.
//!
//! [`Film`] keeps per-pixel running statistics (Welford mean and variance, sample count) plus
//! the two half-buffers of even- and odd-numbered samples that the thesis' stopping criterion
//! (Dammertz §6.2) and the error estimators of the denoisers compare. First-hit AOVs (albedo,
//! shading normal, depth, world position) are kept only when asked for. Nothing non-finite ever
//! enters a buffer: such samples are counted and dropped.
//!
//! [`output`] writes EXR (linear float, AOVs as extra channel groups) and PNG (tone mapped
//! sRGB), always atomically: a temporary file in the target directory renamed into place.
//!
//! Depends on `rt-core` (for `Rgb`), `exr` and `image`.
//!
//! ```
//! use rt_film::{Film, AovSet};
//! use rt_core::glam::Vec3;
//! let mut film = Film::new(2, 1, AovSet::default());
//! for (i, v) in [1.0, 3.0].into_iter().enumerate() {
//!     film.pixel_mut(0, 0).add(Vec3::splat(v), i as u32);
//! }
//! assert_eq!(film.pixel(0, 0).mean(), Vec3::splat(2.0));
//! assert_eq!(film.pixel(0, 0).variance_of_mean(), Vec3::splat(1.0));
//! ```
#![forbid(unsafe_code)]

mod film;
pub mod output;
mod pixel;

pub use film::{AovSet, Film, FilmStripe};
pub use output::{read_exr, write_image, write_rgb, FilmError, OutputOptions};
pub use pixel::{AovPixel, FirstHit, PixelStats};
