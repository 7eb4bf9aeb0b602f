//! The input of every filter.

use rt_core::Rgb;
use rt_film::Film;

/// A noisy rendering with its side channels, all row-major and `width × height`. Optional
/// channels are empty when the film did not keep them.
#[derive(Clone, Debug, Default)]
pub struct NoisyFrame {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Pixel means.
    pub beauty: Vec<Rgb>,
    /// Variance of each pixel mean.
    pub variance: Vec<Rgb>,
    /// Means of the even and odd samples.
    pub halves: [Vec<Rgb>; 2],
    /// First-hit albedo.
    pub albedo: Vec<Rgb>,
    /// First-hit shading normal.
    pub normal: Vec<Rgb>,
    /// First-hit depth.
    pub depth: Vec<f32>,
}

impl NoisyFrame {
    /// A frame with only the beauty image.
    pub fn from_beauty(width: usize, height: usize, beauty: Vec<Rgb>) -> Self {
        Self {
            width,
            height,
            beauty,
            ..Default::default()
        }
    }

    /// Everything the film recorded.
    pub fn from_film(film: &Film) -> Self {
        let aovs = film.aovs();
        let first = film.aov_averages();
        let pick = |on: bool, f: &dyn Fn(&rt_film::FirstHit) -> Rgb| -> Vec<Rgb> {
            if on {
                first.iter().map(f).collect()
            } else {
                Vec::new()
            }
        };
        Self {
            width: film.width() as usize,
            height: film.height() as usize,
            beauty: film.mean_image(),
            variance: film.variance_image(),
            halves: [film.half_image(0), film.half_image(1)],
            albedo: pick(aovs.albedo, &|h| h.albedo),
            normal: pick(aovs.normal, &|h| h.normal),
            depth: if aovs.depth {
                first.iter().map(|h| h.depth).collect()
            } else {
                Vec::new()
            },
        }
    }
}
