//! The one thing GREE needs from the renderer: extra, independent samples at chosen pixels
//! (the "filter caches" of thesis §5.1.1).
//!
//! Independence is the caller's promise, and it matters: a cache that reuses the samples of
//! the noisy image `N` correlates with every filter output and most with the identity-like
//! ones, so selection is biased toward the weakest filters (not in the thesis; the crate's
//! `tests/independence.rs` shows it). Render caches from a different sample stream.

use rt_core::Rgb;

/// Renders extra samples at chosen pixels, independent of N's samples (the caller guarantees
/// independence; e.g. a different sample stream).
pub trait CacheRenderer {
    /// What can go wrong while rendering.
    type Error: std::error::Error + Send + Sync + 'static;
    /// Mean radiance of `spp` new samples at each pixel (x, y), in order.
    fn render_caches(&mut self, pixels: &[(u32, u32)], spp: u32) -> Result<Vec<Rgb>, Self::Error>;
}
