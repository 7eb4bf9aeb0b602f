//! `rt-gree`: GREE, "General and Robust Error Estimation and reconstruction" (Bauszat's
//! thesis, chapter 5; Bauszat, Eisemann, Eisemann and Magnor, CGF 2015).
//!
//! Given a noisy image N rendered at n spp, a bank of filtered versions F_1..F_m of N (any
//! black boxes that all take the same N), and a renderer that can trace extra, independent
//! samples at chosen pixels, GREE measures each filter's error where it rendered a *filter
//! cache* and picks a filter per pixel:
//!
//! 1. [`placement`]: caches at ≈ (1 − s) of the pixels, blue noise mixed with importance
//!    sampling of P_FN = P_F · P_N (thesis §5.1.2, Eq. 5.1);
//! 2. [`CacheRenderer`]: c spp at each cache, independent of N (§5.1.1);
//! 3. [`errors`]: `‖F_i(p) − C(p)‖²` at each cache (§5.1.3);
//! 4. [`interpolate`]: one Delaunay triangulation, piecewise-linear dense error maps (§5.1.3);
//! 5. [`graph_cut`]: α-expansion of the data + photomontage seam energy (§5.1.4, Eq. 5.2–5.4);
//! 6. [`fusion`]: a few Jacobi iterations of gradient-domain fusion (§5.1.4).
//!
//! [`composite`] runs them all. Each stage is a public module usable alone. The budget split
//! `c = (b − s·n)/(1 − s)` is [`Budget`].
//!
//! Deviations from the thesis, each detailed in its module: σ_r and λ are made
//! scale-free by the mean bank radiance ([`scale`]); the blue-noise set is generated per
//! image; importance draws are without replacement; the hull is padded with border
//! pseudo-caches; the max-flow is our own CPU Boykov–Kolmogorov; an optional relative error
//! metric ([`ErrorMetric::Relative`]).
//!
//! The crate does not render or filter: it depends on `rt-core` (images), `spade`
//! (Delaunay), `rayon` and `thiserror`. Parallel stages give the same bits for any thread
//! count.
//!
//! ```
//! use rt_core::{Rgb, RgbImage};
//! use rt_gree::{composite, CacheRenderer, GreeParams};
//!
//! // Truth is a ramp; filter 0 is exact on the left half, filter 1 on the right half.
//! let (w, h) = (48, 32);
//! let truth = RgbImage::from_fn(w, h, |x, _| Rgb::splat(0.2 + x as f32 / 64.0));
//! let off = |left: bool| RgbImage::from_fn(w, h, |x, y| {
//!     let wrong = (x < w / 2) != left;
//!     truth.pixel(x, y) + Rgb::splat(if wrong { 0.3 * ((x + y) % 2) as f32 } else { 0.0 })
//! });
//! let bank = vec![off(true), off(false)];
//! let variance = RgbImage::from_fn(w, h, |_, _| Rgb::splat(1e-3));
//!
//! struct Exact<'a>(&'a RgbImage);
//! impl CacheRenderer for Exact<'_> {
//!     type Error = std::convert::Infallible;
//!     fn render_caches(&mut self, px: &[(u32, u32)], _spp: u32) -> Result<Vec<Rgb>, Self::Error> {
//!         Ok(px.iter().map(|&(x, y)| self.0.pixel(x as usize, y as usize)).collect())
//!     }
//! }
//! let params = GreeParams { sparsity: 0.9, ..GreeParams::default() };
//! let out = composite(&truth, &variance, &bank, &mut Exact(&truth), &params)?;
//! assert_eq!(out.labels[5 * w + 2], 0);
//! assert_eq!(out.labels[5 * w + w - 3], 1);
//! # Ok::<(), rt_gree::GreeError>(())
//! ```
#![forbid(unsafe_code)]

mod error;
pub mod errors;
pub mod fusion;
pub mod graph_cut;
pub mod interpolate;
mod params;
mod pipeline;
pub mod placement;
mod renderer;
pub mod scale;

pub use error::GreeError;
pub use params::{Budget, ErrorMetric, GreeParams, RELATIVE_EPSILON};
pub use pipeline::{composite, Composite, StageTimes};
pub use renderer::CacheRenderer;
pub use rt_core::{Rgb, RgbImage};
