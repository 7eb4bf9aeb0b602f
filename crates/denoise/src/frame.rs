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

    /// Everything the film recorded (its optional buffers that it did not keep stay empty).
    pub fn from_film(film: &Film) -> Self {
        let [even, odd] = [0, 1].map(|h| film.half_image(h).unwrap_or_default());
        Self {
            width: film.width() as usize,
            height: film.height() as usize,
            beauty: film.mean_image(),
            variance: film.variance_image().unwrap_or_default(),
            halves: [even, odd],
            albedo: film.albedo_image().unwrap_or_default(),
            normal: film.normal_image().unwrap_or_default(),
            depth: film.depth_image().unwrap_or_default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_film::{AovSet, FilmBuffers};

    #[test]
    fn channels_the_film_did_not_keep_are_empty() {
        let mut film = Film::new(2, 1, AovSet::default());
        film.add_sample(0, 0, 0, Rgb::ONE, None);
        let f = NoisyFrame::from_film(&film);
        assert_eq!(f.beauty, vec![Rgb::ONE, Rgb::ZERO]);
        assert!(f.variance.is_empty() && f.halves.iter().all(Vec::is_empty));
        assert!(f.albedo.is_empty() && f.normal.is_empty() && f.depth.is_empty());

        let aovs = AovSet {
            normal: true,
            ..Default::default()
        };
        let film = Film::new(2, 1, FilmBuffers::for_outputs(aovs).with_halves());
        let f = NoisyFrame::from_film(&film);
        assert_eq!(
            (f.halves[0].len(), f.halves[1].len(), f.normal.len()),
            (2, 2, 2)
        );
        assert!(f.variance.is_empty() && f.albedo.is_empty());
    }
}
