//! A single-frame denoiser run on each frame alone: what temporal stability is measured against.

use crate::{TemporalDenoiser, TemporalError, TemporalFrame};
use rt_core::RgbImage;
use rt_denoise::Denoiser;
use rt_film::Channel;

/// `denoiser` applied to every frame, remembering nothing.
pub struct PerFrame(pub Box<dyn Denoiser>);

impl TemporalDenoiser for PerFrame {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn needs(&self) -> &[Channel] {
        self.0.needs()
    }

    fn needs_guides(&self) -> bool {
        false
    }

    fn filter(&mut self, frame: &TemporalFrame<'_>) -> Result<RgbImage, TemporalError> {
        Ok(self.0.denoise(frame.frame)?)
    }

    fn reset(&mut self) {}
}
