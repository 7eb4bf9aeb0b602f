//! Per-sample records: every camera sample kept apart instead of merged into its pixel, for
//! filters that work on samples (SBMF, Bauszat's thesis ch. 4, needs each sample's radiance,
//! first-hit guides and circle of confusion; seed-000 digest §5.1).
//!
//! [`SampleRecords`] is a struct of arrays: radiance, first-hit shading normal, world position
//! and albedo (12 bytes each), signed circle of confusion (4 bytes) and pixel index (4 bytes),
//! 56 bytes per sample, plus one 8-byte offset per pixel. Pixel `i`'s samples are the index
//! range `offsets[i]..offsets[i + 1]`, so the count may differ from pixel to pixel; within a
//! pixel they are in sample-index order, whatever the thread count.
//!
//! Conventions: a sample that hit nothing (the environment) has a zero normal (a hit's normal
//! is a unit vector, so [`SampleRecords::is_hit`] tests it), zero albedo and position, and the
//! circle of confusion of infinite depth ([`rt_core::Camera::coc_at_infinity`]: the largest
//! positive value). The circle of confusion is in pixels, positive behind the focal plane, and
//! zero for a pinhole camera; the render driver computes it with the scene's camera at rest
//! (a camera moving during the shutter is not followed). Samples the film drops (non-finite or negative radiance) are not
//! recorded either, so counts can be below the pass's samples per pixel.
//!
//! The render driver fills a pass ([`SampleRecords::pass`]: slots for `n` samples of every
//! pixel) in parallel bands of rows ([`SampleRecords::bands_mut`], disjoint slices, nothing
//! allocated per sample), then hands it to the film ([`crate::Film::add_sample_records`]),
//! which drops unfilled slots and appends it pixel by pixel to earlier passes.

use crate::FirstHit;
use rt_core::glam::Vec3;
use rt_core::Rgb;
use std::ops::Range;

/// Pixel index of a slot nothing was written to.
const EMPTY: u32 = u32::MAX;

/// One sample, as [`SampleRecords::sample`] returns it and [`SampleRecords::from_samples`]
/// takes it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Row-major pixel index (`y · width + x`).
    pub pixel: u32,
    /// Radiance of the camera sample.
    pub radiance: Rgb,
    /// First-hit shading normal facing the camera; zero for a miss.
    pub normal: Vec3,
    /// First-hit world position; zero for a miss.
    pub position: Vec3,
    /// First-hit albedo; zero for a miss.
    pub albedo: Rgb,
    /// Signed circle of confusion in pixels (positive behind the focal plane).
    pub coc: f32,
}

/// Why [`SampleRecords::from_samples`] refused its input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SampleRecordsError {
    /// A sample names a pixel outside the image.
    #[error("sample {index}: pixel {pixel} is outside the {width}x{height} image")]
    Pixel {
        /// Position of the sample in the input.
        index: usize,
        /// Its pixel index.
        pixel: u32,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// A sample holds a NaN or infinity.
    #[error("sample {index} holds a non-finite value")]
    NonFinite {
        /// Position of the sample in the input.
        index: usize,
    },
    /// The image has more pixels than a `u32` pixel index can name.
    #[error("a {width}x{height} image has too many pixels for sample records")]
    TooLarge {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
}

/// The samples of a `width × height` image, grouped by pixel (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleRecords {
    width: u32,
    height: u32,
    offsets: Vec<usize>,
    radiance: Vec<Rgb>,
    normal: Vec<Vec3>,
    position: Vec<Vec3>,
    albedo: Vec<Rgb>,
    coc: Vec<f32>,
    pixel: Vec<u32>,
}

/// Bytes per sample: radiance, normal, position, albedo, CoC and pixel index.
pub const SAMPLE_RECORD_BYTES: usize = 4 * 12 + 4 + 4;

impl SampleRecords {
    /// No samples for a `width × height` image.
    pub fn empty(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            offsets: vec![0; width as usize * height as usize + 1],
            ..Default::default()
        }
    }

    /// Slots for `per_pixel` samples of every pixel, all unfilled: one render pass, filled by
    /// [`SampleRecords::bands_mut`]. Unfilled slots are dropped when the film takes the pass.
    pub fn pass(width: u32, height: u32, per_pixel: u32) -> Self {
        let pixels = width as usize * height as usize;
        let n = pixels * per_pixel as usize;
        Self {
            width,
            height,
            offsets: (0..=pixels).map(|i| i * per_pixel as usize).collect(),
            radiance: vec![Rgb::ZERO; n],
            normal: vec![Vec3::ZERO; n],
            position: vec![Vec3::ZERO; n],
            albedo: vec![Rgb::ZERO; n],
            coc: vec![0.0; n],
            pixel: vec![EMPTY; n],
        }
    }

    /// Records from samples in any pixel order; within a pixel their order is kept. Refuses
    /// pixel indices outside the image and non-finite values.
    pub fn from_samples(
        width: u32,
        height: u32,
        samples: &[Sample],
    ) -> Result<Self, SampleRecordsError> {
        let pixels = width as usize * height as usize;
        if pixels >= EMPTY as usize {
            return Err(SampleRecordsError::TooLarge { width, height });
        }
        let mut counts = vec![0usize; pixels + 1];
        for (index, s) in samples.iter().enumerate() {
            if s.pixel as usize >= pixels {
                return Err(SampleRecordsError::Pixel {
                    index,
                    pixel: s.pixel,
                    width,
                    height,
                });
            }
            let finite = s.radiance.is_finite()
                && s.normal.is_finite()
                && s.position.is_finite()
                && s.albedo.is_finite()
                && s.coc.is_finite();
            if !finite {
                return Err(SampleRecordsError::NonFinite { index });
            }
            counts[s.pixel as usize + 1] += 1;
        }
        for i in 0..pixels {
            counts[i + 1] += counts[i];
        }
        let mut r = Self::pass(width, height, 0);
        r.offsets = counts.clone();
        let n = samples.len();
        r.radiance = vec![Rgb::ZERO; n];
        r.normal = vec![Vec3::ZERO; n];
        r.position = vec![Vec3::ZERO; n];
        r.albedo = vec![Rgb::ZERO; n];
        r.coc = vec![0.0; n];
        r.pixel = vec![0; n];
        let mut next = counts;
        for s in samples {
            let j = next[s.pixel as usize];
            next[s.pixel as usize] += 1;
            r.set(j, s);
        }
        Ok(r)
    }

    fn set(&mut self, j: usize, s: &Sample) {
        self.radiance[j] = s.radiance;
        self.normal[j] = s.normal;
        self.position[j] = s.position;
        self.albedo[j] = s.albedo;
        self.coc[j] = s.coc;
        self.pixel[j] = s.pixel;
    }

    /// Image width.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.pixel.len()
    }

    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.pixel.is_empty()
    }

    /// Bytes held (samples and offsets).
    pub fn memory_bytes(&self) -> usize {
        self.len() * SAMPLE_RECORD_BYTES + std::mem::size_of_val(self.offsets.as_slice())
    }

    /// The indices of row-major pixel `i`'s samples (empty outside the image).
    pub fn pixel_range(&self, i: usize) -> Range<usize> {
        match (self.offsets.get(i), self.offsets.get(i + 1)) {
            (Some(&a), Some(&b)) => a..b,
            _ => 0..0,
        }
    }

    /// Number of samples of pixel `(x, y)`.
    pub fn count(&self, x: u32, y: u32) -> usize {
        self.pixel_range((y * self.width + x) as usize).len()
    }

    /// Per-pixel offsets (`width · height + 1` entries; pixel `i` owns `offsets[i]..offsets[i+1]`).
    pub fn offsets(&self) -> &[usize] {
        &self.offsets
    }

    /// Radiance of every sample.
    pub fn radiance(&self) -> &[Rgb] {
        &self.radiance
    }

    /// First-hit shading normals (zero for misses).
    pub fn normal(&self) -> &[Vec3] {
        &self.normal
    }

    /// First-hit world positions (zero for misses).
    pub fn position(&self) -> &[Vec3] {
        &self.position
    }

    /// First-hit albedos (zero for misses).
    pub fn albedo(&self) -> &[Rgb] {
        &self.albedo
    }

    /// Signed circles of confusion in pixels.
    pub fn coc(&self) -> &[f32] {
        &self.coc
    }

    /// Row-major pixel index of every sample.
    pub fn pixel(&self) -> &[u32] {
        &self.pixel
    }

    /// True if sample `j` hit a surface.
    pub fn is_hit(&self, j: usize) -> bool {
        self.normal[j] != Vec3::ZERO
    }

    /// Sample `j` as one value.
    pub fn sample(&self, j: usize) -> Sample {
        Sample {
            pixel: self.pixel[j],
            radiance: self.radiance[j],
            normal: self.normal[j],
            position: self.position[j],
            albedo: self.albedo[j],
            coc: self.coc[j],
        }
    }

    /// Bands of `rows` rows (the last may be shorter) with mutable slices of their samples, for
    /// filling in parallel.
    pub fn bands_mut(&mut self, rows: u32) -> Vec<SampleBand<'_>> {
        let w = self.width as usize;
        let rows = rows.max(1) as usize;
        let mut bands = Vec::new();
        let (mut radiance, mut normal, mut position, mut albedo, mut coc, mut pixel) = (
            self.radiance.as_mut_slice(),
            self.normal.as_mut_slice(),
            self.position.as_mut_slice(),
            self.albedo.as_mut_slice(),
            self.coc.as_mut_slice(),
            self.pixel.as_mut_slice(),
        );
        let mut y0 = 0;
        while y0 < self.height as usize {
            let y1 = (y0 + rows).min(self.height as usize);
            let offsets = &self.offsets[y0 * w..=y1 * w];
            let n = offsets[offsets.len() - 1] - offsets[0];
            let (r, rest_r) = std::mem::take(&mut radiance).split_at_mut(n);
            let (nn, rest_n) = std::mem::take(&mut normal).split_at_mut(n);
            let (p, rest_p) = std::mem::take(&mut position).split_at_mut(n);
            let (a, rest_a) = std::mem::take(&mut albedo).split_at_mut(n);
            let (c, rest_c) = std::mem::take(&mut coc).split_at_mut(n);
            let (px, rest_px) = std::mem::take(&mut pixel).split_at_mut(n);
            (radiance, normal, position, albedo, coc, pixel) =
                (rest_r, rest_n, rest_p, rest_a, rest_c, rest_px);
            bands.push(SampleBand {
                y0: y0 as u32,
                width: self.width,
                offsets,
                radiance: r,
                normal: nn,
                position: p,
                albedo: a,
                coc: c,
                pixel: px,
            });
            y0 = y1;
        }
        bands
    }

    /// Drops the slots nothing was written to.
    fn compact(&mut self) {
        if !self.pixel.contains(&EMPTY) {
            return;
        }
        let mut out = Self::empty(self.width, self.height);
        out.append_pixels(self, &Self::empty(self.width, self.height));
        *self = out;
    }

    /// `self` followed, pixel by pixel, by the filled slots of `other` (same size).
    pub(crate) fn append(&mut self, mut other: SampleRecords) {
        other.compact();
        if self.is_empty() {
            *self = other;
            return;
        }
        let mut out = Self::empty(self.width, self.height);
        out.append_pixels(self, &other);
        *self = out;
    }

    /// Fills the empty `self` with the filled samples of `a` then `b`, pixel by pixel.
    fn append_pixels(&mut self, a: &SampleRecords, b: &SampleRecords) {
        let n = a.len() + b.len();
        for v in [&mut self.radiance, &mut self.albedo] {
            v.reserve(n);
        }
        for v in [&mut self.normal, &mut self.position] {
            v.reserve(n);
        }
        self.coc.reserve(n);
        self.pixel.reserve(n);
        let pixels = self.width as usize * self.height as usize;
        for i in 0..pixels {
            for src in [a, b] {
                for j in src.pixel_range(i) {
                    if src.pixel[j] == EMPTY {
                        continue;
                    }
                    self.radiance.push(src.radiance[j]);
                    self.normal.push(src.normal[j]);
                    self.position.push(src.position[j]);
                    self.albedo.push(src.albedo[j]);
                    self.coc.push(src.coc[j]);
                    self.pixel.push(src.pixel[j]);
                }
            }
            self.offsets[i + 1] = self.pixel.len();
        }
    }
}

/// A band of rows of a [`SampleRecords`] pass, borrowed mutably so that bands fill in parallel.
pub struct SampleBand<'a> {
    y0: u32,
    width: u32,
    /// The band's pixel offsets (global sample indices), one more than its pixels.
    offsets: &'a [usize],
    radiance: &'a mut [Rgb],
    normal: &'a mut [Vec3],
    position: &'a mut [Vec3],
    albedo: &'a mut [Rgb],
    coc: &'a mut [f32],
    pixel: &'a mut [u32],
}

impl SampleBand<'_> {
    /// First row of the band.
    pub fn y0(&self) -> u32 {
        self.y0
    }

    /// Writes slot `slot` of pixel `(x, y)` (image coordinates inside the band). Returns false,
    /// writing nothing, for a slot the pixel does not have and for radiance the film would drop
    /// (non-finite or negative). A non-finite first hit is recorded as a miss, and a non-finite
    /// `coc` as zero.
    #[inline]
    pub fn record(
        &mut self,
        x: u32,
        y: u32,
        slot: u32,
        radiance: Rgb,
        hit: Option<&FirstHit>,
        coc: f32,
    ) -> bool {
        let i = ((y - self.y0) * self.width + x) as usize;
        let (Some(&start), Some(&end)) = (self.offsets.get(i), self.offsets.get(i + 1)) else {
            return false;
        };
        let j = start + slot as usize;
        if j >= end || !crate::accepts_sample(radiance) {
            return false;
        }
        let j = j - self.offsets[0];
        self.radiance[j] = radiance;
        let hit = hit.filter(|h| h.is_finite()).copied().unwrap_or_default();
        self.normal[j] = hit.normal;
        self.position[j] = hit.position;
        self.albedo[j] = hit.albedo;
        self.coc[j] = if coc.is_finite() { coc } else { 0.0 };
        self.pixel[j] = y * self.width + x;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(d: f32) -> FirstHit {
        FirstHit {
            albedo: Rgb::splat(0.5),
            normal: Vec3::Z,
            depth: d,
            position: Vec3::new(d, 0.0, 0.0),
        }
    }

    #[test]
    fn passes_fill_by_band_drop_unfilled_slots_and_append_per_pixel() {
        let mut first = SampleRecords::pass(3, 3, 2);
        for mut band in first.bands_mut(2) {
            let y0 = band.y0();
            for y in y0..(y0 + 2).min(3) {
                for x in 0..3 {
                    if (x, y) == (1, 1) {
                        continue; // a masked-out pixel
                    }
                    for k in 0..2 {
                        let v = (y * 3 + x) as f32 + k as f32 * 0.5;
                        assert!(band.record(x, y, k, Rgb::splat(v), Some(&hit(v)), v));
                    }
                    assert!(!band.record(x, y, 2, Rgb::ONE, None, 0.0), "no third slot");
                    assert!(!band.record(x, y, 0, Rgb::splat(-1.0), None, 0.0));
                }
            }
        }
        let mut rec = SampleRecords::empty(3, 3);
        rec.append(first);
        assert_eq!(rec.len(), 16);
        assert_eq!((rec.count(1, 1), rec.count(2, 2)), (0, 2));
        let mut second = SampleRecords::pass(3, 3, 1);
        for mut band in second.bands_mut(3) {
            assert!(band.record(1, 1, 0, Rgb::splat(7.0), None, f32::NAN));
            assert!(band.record(2, 2, 0, Rgb::splat(9.0), Some(&hit(9.0)), 3.0));
        }
        rec.append(second);
        assert_eq!(rec.len(), 18);
        assert_eq!((rec.count(1, 1), rec.count(2, 2)), (1, 3));
        let r = rec.pixel_range(8);
        assert_eq!(rec.radiance()[r.clone()], [8.0, 8.5, 9.0].map(Rgb::splat));
        assert!(rec.pixel()[r].iter().all(|&p| p == 8));
        let miss = rec.pixel_range(4).start;
        assert!(!rec.is_hit(miss) && rec.coc()[miss] == 0.0);
        assert!(rec.is_hit(0));
        assert_eq!(rec.offsets().len(), 10);
        assert_eq!(rec.memory_bytes(), 18 * 56 + 10 * 8);
    }

    #[test]
    fn a_film_keeps_records_only_when_asked_and_reports_their_memory() {
        let plain = crate::Film::new(2, 2, crate::AovSet::default());
        assert!(plain.sample_records().is_none() && plain.memory().samples.is_none());
        let buffers = crate::FilmBuffers::for_outputs(crate::AovSet::default()).with_samples();
        let mut film = crate::Film::new(2, 2, buffers);
        assert_eq!(film.memory().samples, Some(5 * 8));
        let mut pass = SampleRecords::pass(2, 2, 3);
        for mut band in pass.bands_mut(1) {
            let y = band.y0();
            assert!(band.record(1, y, 0, Rgb::ONE, Some(&hit(1.0)), 0.5));
        }
        film.add_sample_records(pass);
        assert_eq!(film.sample_records().unwrap().len(), 2);
        assert_eq!(film.memory().samples, Some(2 * SAMPLE_RECORD_BYTES + 5 * 8));
        film.add_sample_records(SampleRecords::pass(3, 2, 1));
        assert_eq!(
            film.sample_records().unwrap().len(),
            2,
            "wrong size: ignored"
        );
    }

    #[test]
    fn from_samples_groups_by_pixel_keeping_order_and_refuses_bad_input() {
        let s = |pixel: u32, v: f32| Sample {
            pixel,
            radiance: Rgb::splat(v),
            ..Default::default()
        };
        let rec = SampleRecords::from_samples(2, 1, &[s(1, 1.0), s(0, 2.0), s(1, 3.0)]).unwrap();
        assert_eq!(rec.offsets(), &[0, 1, 3]);
        assert_eq!(rec.radiance(), &[2.0, 1.0, 3.0].map(Rgb::splat));
        assert_eq!(rec.sample(2), s(1, 3.0));
        assert!(matches!(
            SampleRecords::from_samples(2, 1, &[s(2, 1.0)]),
            Err(SampleRecordsError::Pixel { pixel: 2, .. })
        ));
        assert!(SampleRecords::from_samples(2, 1, &[s(0, f32::NAN)]).is_err());
    }
}
