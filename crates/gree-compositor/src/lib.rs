//! `gree-compositor`: general and robust error estimation and reconstruction (GREE, Bauszat).
//!
//! Planned shape (a later issue fills it in): run a bank of `rt_denoise::Denoiser`s over a
//! `NoisyFrame`; estimate each filter's error at sparse "filter caches" from the two
//! half-buffers; interpolate the error over the image on a Delaunay triangulation (spade); pick
//! or blend the best filter per pixel. It depends on `rt-core` and `rt-denoise` only and never
//! renders, so it can be re-run on saved EXR frames.
//!
//! This crate is intentionally empty for now: the seam (`rt_denoise::Denoiser`, `NoisyFrame`)
//! exists so that the compositor can be written against it.
#![forbid(unsafe_code)]
