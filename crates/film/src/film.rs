//! The film: a grid of pixel statistics plus optional first-hit AOVs.

use crate::pixel::{AovPixel, FirstHit, PixelStats};
use rt_core::Rgb;
use std::sync::atomic::{AtomicU64, Ordering};

/// Which first-hit AOVs to keep. The integrator computes them only if one of them is wanted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    /// Albedo of the first visible surface.
    pub albedo: bool,
    /// Shading normal.
    pub normal: bool,
    /// Distance from the camera.
    pub depth: bool,
    /// World position.
    pub position: bool,
    /// Per-pixel variance of the mean (from the statistics; costs nothing extra to keep).
    pub variance: bool,
}

impl AovSet {
    /// True if any first-hit quantity is wanted (variance is not a first-hit quantity).
    pub fn any_first_hit(&self) -> bool {
        self.albedo || self.normal || self.depth || self.position
    }

    /// Parses a comma-separated list such as `albedo,normal,variance`.
    pub fn parse_list<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<Self, String> {
        let mut s = Self::default();
        for n in names {
            match n.trim() {
                "albedo" => s.albedo = true,
                "normal" => s.normal = true,
                "depth" => s.depth = true,
                "position" => s.position = true,
                "variance" => s.variance = true,
                "" => {}
                other => {
                    return Err(format!(
                        "unknown AOV '{other}' (expected albedo, normal, depth, position, variance)"
                    ))
                }
            }
        }
        Ok(s)
    }
}

/// Per-pixel accumulation for a `width × height` image, row 0 at the top.
#[derive(Debug)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<PixelStats>,
    aov: Vec<AovPixel>,
    aovs: AovSet,
    discarded: AtomicU64,
}

/// A band of consecutive rows of a film, borrowed mutably so that bands can be rendered in
/// parallel without locks.
pub struct FilmStripe<'a> {
    /// First row of the band.
    pub y0: u32,
    /// Image width.
    pub width: u32,
    pixels: &'a mut [PixelStats],
    aov: &'a mut [AovPixel],
    discarded: &'a AtomicU64,
}

impl FilmStripe<'_> {
    /// Number of rows in this band.
    pub fn rows(&self) -> u32 {
        (self.pixels.len() / self.width as usize) as u32
    }

    /// Adds a radiance sample (sample number `index`) to pixel `(x, y)` (image coordinates).
    /// Non-finite or negative samples are dropped and counted; returns whether it was kept.
    #[inline]
    pub fn add_sample(
        &mut self,
        x: u32,
        y: u32,
        index: u32,
        radiance: Rgb,
        hit: Option<&FirstHit>,
    ) -> bool {
        let i = ((y - self.y0) * self.width + x) as usize;
        if !radiance.is_finite() || radiance.min_element() < 0.0 {
            self.discarded.fetch_add(1, Ordering::Relaxed);
            return false;
        }
        self.pixels[i].add(radiance, index);
        if let (Some(a), Some(h)) = (self.aov.get_mut(i), hit) {
            if h.albedo.is_finite()
                && h.normal.is_finite()
                && h.depth.is_finite()
                && h.position.is_finite()
            {
                a.add(h);
            }
        }
        true
    }
}

impl Film {
    /// An empty film keeping the given AOVs.
    pub fn new(width: u32, height: u32, aovs: AovSet) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            pixels: vec![PixelStats::default(); n],
            aov: if aovs.any_first_hit() {
                vec![AovPixel::default(); n]
            } else {
                Vec::new()
            },
            aovs,
            discarded: AtomicU64::new(0),
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The AOVs this film keeps.
    pub fn aovs(&self) -> AovSet {
        self.aovs
    }

    /// Samples dropped because they were NaN, infinite or negative.
    pub fn discarded(&self) -> u64 {
        self.discarded.load(Ordering::Relaxed)
    }

    /// Statistics of pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> &PixelStats {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// Mutable statistics of pixel `(x, y)`.
    pub fn pixel_mut(&mut self, x: u32, y: u32) -> &mut PixelStats {
        &mut self.pixels[(y * self.width + x) as usize]
    }

    /// All pixels, row-major.
    pub fn pixels(&self) -> &[PixelStats] {
        &self.pixels
    }

    /// Averaged first-hit AOVs, row-major (empty if none were kept).
    pub fn aov_averages(&self) -> Vec<FirstHit> {
        self.aov.iter().map(AovPixel::average).collect()
    }

    /// Splits the film into bands of `rows` rows for parallel rendering.
    pub fn stripes_mut(&mut self, rows: u32) -> Vec<FilmStripe<'_>> {
        let w = self.width;
        let chunk = (rows.max(1) * w).max(1) as usize;
        let aov_chunks: Vec<&mut [AovPixel]> = if self.aov.is_empty() {
            Vec::new()
        } else {
            self.aov.chunks_mut(chunk).collect()
        };
        let mut aov_iter = aov_chunks.into_iter();
        let discarded = &self.discarded;
        self.pixels
            .chunks_mut(chunk)
            .enumerate()
            .map(|(i, p)| FilmStripe {
                y0: i as u32 * rows.max(1),
                width: w,
                pixels: p,
                aov: aov_iter.next().unwrap_or_default(),
                discarded,
            })
            .collect()
    }

    /// The pixel estimates, row-major.
    pub fn mean_image(&self) -> Vec<Rgb> {
        self.pixels.iter().map(PixelStats::mean).collect()
    }

    /// Variance of each pixel estimate, row-major.
    pub fn variance_image(&self) -> Vec<Rgb> {
        self.pixels
            .iter()
            .map(PixelStats::variance_of_mean)
            .collect()
    }

    /// Mean of the even (`0`) or odd (`1`) samples, row-major.
    pub fn half_image(&self, half: usize) -> Vec<Rgb> {
        self.pixels.iter().map(|p| p.half_mean(half)).collect()
    }

    /// Total samples accumulated.
    pub fn total_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.count() as u64).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stripes_cover_the_film_and_reject_bad_samples() {
        let mut film = Film::new(
            3,
            5,
            AovSet {
                depth: true,
                ..Default::default()
            },
        );
        {
            let stripes = film.stripes_mut(2);
            assert_eq!(stripes.len(), 3);
            for mut s in stripes {
                for y in s.y0..s.y0 + s.rows() {
                    for x in 0..3 {
                        let hit = FirstHit {
                            depth: 2.0,
                            ..Default::default()
                        };
                        assert!(s.add_sample(x, y, 0, Rgb::splat(y as f32), Some(&hit)));
                        assert!(!s.add_sample(x, y, 1, Rgb::new(f32::NAN, 0.0, 0.0), None));
                        assert!(!s.add_sample(x, y, 1, Rgb::splat(f32::INFINITY), None));
                    }
                }
            }
        }
        assert_eq!(film.discarded(), 30);
        assert_eq!(film.pixel(2, 4).mean(), Rgb::splat(4.0));
        assert_eq!(film.total_samples(), 15);
        assert_eq!(film.aov_averages()[7].depth, 2.0);
    }

    #[test]
    fn aovs_are_not_allocated_unless_asked() {
        let film = Film::new(
            4,
            4,
            AovSet {
                variance: true,
                ..Default::default()
            },
        );
        assert!(film.aov_averages().is_empty());
        assert!(AovSet::parse_list(["albedo", "bogus"]).is_err());
    }
}
