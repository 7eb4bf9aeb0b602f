//! The film: a grid of pixel statistics plus the optional buffers a caller asked for
//! ([`FilmBuffers`]): variance, half-buffers, first-hit AOVs, the lighting split, samples.

use crate::filtered::{FilterSums, Window};
use crate::fixed::{sample_variance, sample_variance3, Squares3, Sum1, Sum3};
use crate::pixel::{FeatureSquares, FirstHit, HalfSums, LightSplit, PixelStats, SplitSums};
use crate::samples::SampleRecords;
use crate::splat::{Splat, SplatSums};
use crate::{AovSet, FilmBuffers, FilmMemory};
use rt_core::glam::{Vec2, Vec3};
use rt_core::pixel_filter::PixelFilter;
use rt_core::Rgb;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The variance of each pixel's mean feature ([`Film::feature_variance_images`]); `None` for a
/// feature the film does not keep. Albedo is RGB, stored like the normal and position as three
/// components.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FeatureVariances {
    /// Albedo.
    pub albedo: Option<Vec<Vec3>>,
    /// Shading normal.
    pub normal: Option<Vec<Vec3>>,
    /// Depth.
    pub depth: Option<Vec<f32>>,
    /// Position.
    pub position: Option<Vec<Vec3>>,
}

/// Sums of the first-hit AOVs, one buffer per quantity; each is empty unless asked for.
#[derive(Debug, Default)]
pub(crate) struct AovBuffers {
    /// Samples whose first hit was recorded (the divisor of every AOV average).
    pub(crate) hits: Vec<u32>,
    pub(crate) albedo: Vec<Sum3>,
    pub(crate) normal: Vec<Sum3>,
    pub(crate) depth: Vec<Sum1>,
    pub(crate) position: Vec<Sum3>,
    /// Sums of squares of the features (all four in one buffer).
    pub(crate) squares: Vec<FeatureSquares>,
    /// Sums of the lighting split, divided by the pixel's sample count (every kept sample
    /// carries a split when one is kept). One buffer for all parts: 288 bytes per pixel, the
    /// price of a simple accumulation loop; only written parts reach the output.
    pub(crate) split: Vec<SplitSums>,
}

/// A band of [`AovBuffers`].
struct AovSlices<'a> {
    hits: &'a mut [u32],
    albedo: &'a mut [Sum3],
    normal: &'a mut [Sum3],
    depth: &'a mut [Sum1],
    position: &'a mut [Sum3],
    squares: &'a mut [FeatureSquares],
    split: &'a mut [SplitSums],
}

/// The even-numbered samples' sum and count of one pixel (the odd ones are the rest).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct EvenSums {
    pub sum: Sum3,
    pub n: u32,
}

/// Per-pixel accumulation for a `width × height` image, row 0 at the top. Only the buffers
/// named by its [`FilmBuffers`] exist; the others have length zero. Every statistic is an
/// exact integer sum (see the crate doc), so the order samples arrive in never changes a bit.
///
/// A film whose camera splats its pixel filter ([`FilmStripe::add_filtered`]) keeps the
/// filter-weighted sums instead (`crates/film/src/filtered.rs`), allocated with the first splat: its
/// image and half-images are the filtered ones; it keeps no per-pixel variance (a pixel's
/// samples are shared with its neighbours), and its sample counts are those taken in each
/// pixel.
#[derive(Debug)]
pub struct Film {
    width: u32,
    height: u32,
    buffers: FilmBuffers,
    pub(crate) counts: Vec<u32>,
    pub(crate) sums: Vec<Sum3>,
    pub(crate) squares: Vec<Squares3>,
    pub(crate) even: Vec<EvenSums>,
    pub(crate) aov: AovBuffers,
    pub(crate) splats: SplatSums,
    /// Filter-weighted sums; behind a lock only for the stripes that add their windows.
    pub(crate) filtered: Mutex<FilterSums>,
    samples: Option<SampleRecords>,
    discarded: AtomicU64,
}

/// A band of consecutive rows of a film, borrowed mutably so that bands can be rendered in
/// parallel without locks.
pub struct FilmStripe<'a> {
    /// First row of the band.
    pub y0: u32,
    /// Image width.
    pub width: u32,
    counts: &'a mut [u32],
    sums: &'a mut [Sum3],
    squares: &'a mut [Squares3],
    even: &'a mut [EvenSums],
    aov: AovSlices<'a>,
    discarded: &'a AtomicU64,
    height: u32,
    /// This band's filtered splats, made at its first one and added to `filtered` on drop.
    window: Option<Window>,
    filtered: &'a Mutex<FilterSums>,
}

impl Drop for FilmStripe<'_> {
    fn drop(&mut self) {
        if let Some(w) = self.window.take() {
            let pixels = self.width as usize * self.height as usize;
            w.add_into(&mut lock(self.filtered), self.width, pixels);
        }
    }
}

/// The filtered sums, whether or not a panicking thread poisoned the lock (the sums of a
/// finished window are whole: it is added in one call).
fn lock(m: &Mutex<FilterSums>) -> MutexGuard<'_, FilterSums> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl FilmStripe<'_> {
    /// Adds radiance sample `index` of pixel `(x, y)`, taken at film position `pos` (uniform in
    /// the pixel), splatted through `filter` into every pixel within its radius
    /// (`crates/film/src/filtered.rs`); counted as a sample of `(x, y)`. Non-finite or negative samples
    /// are dropped and counted; returns whether it was kept. First-hit AOVs, the lighting
    /// split and the variance are not kept for splatted samples (callers refuse them).
    #[inline]
    pub fn add_filtered(
        &mut self,
        filter: &PixelFilter,
        pos: Vec2,
        (x, y): (u32, u32),
        index: u32,
        radiance: Rgb,
    ) -> bool {
        let Some(i) = self.count(x, y, radiance) else {
            return false;
        };
        let even = index.is_multiple_of(2);
        if let (Some(e), true) = (self.even.get_mut(i), even) {
            e.n += 1;
        }
        let (w, h, y0, rows) = (self.width, self.height, self.y0, self.rows());
        let halves = !self.even.is_empty();
        self.window
            .get_or_insert_with(|| Window::new(y0..y0 + rows, w, h, filter, halves))
            .splat(filter, (pos.x, pos.y), (w, h), even, radiance);
        true
    }

    /// Counts a sample of pixel `(x, y)` (image coordinates) and returns the pixel's index in
    /// this band, or drops and counts it as discarded when it is non-finite or negative.
    #[inline]
    fn count(&mut self, x: u32, y: u32, radiance: Rgb) -> Option<usize> {
        if !crate::accepts_sample(radiance) {
            self.discarded.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        let i = ((y - self.y0) * self.width + x) as usize;
        self.counts[i] += 1;
        Some(i)
    }

    /// Number of rows in this band.
    pub fn rows(&self) -> u32 {
        (self.counts.len() / self.width as usize) as u32
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
        self.add_sample_split(x, y, index, radiance, hit, None)
    }

    /// [`FilmStripe::add_sample`] with the sample's lighting split, which a film keeping one
    /// needs from every sample (a non-finite split is left out of the sums).
    #[inline]
    pub fn add_sample_split(
        &mut self,
        x: u32,
        y: u32,
        index: u32,
        radiance: Rgb,
        hit: Option<&FirstHit>,
        split: Option<&LightSplit>,
    ) -> bool {
        let Some(i) = self.count(x, y, radiance) else {
            return false;
        };
        // Optional buffers are empty slices when not kept, so `get_mut` is the "is it kept"
        // test: one predictable branch per buffer, no per-sample flags to consult.
        self.sums[i].add(radiance);
        if let Some(q) = self.squares.get_mut(i) {
            q.add(radiance);
        }
        if let (Some(e), true) = (self.even.get_mut(i), index.is_multiple_of(2)) {
            e.sum.add(radiance);
            e.n += 1;
        }
        if let (Some(sum), Some(sp)) = (self.aov.split.get_mut(i), split) {
            if sp.is_finite() {
                sum.add(sp);
            }
        }
        let a = &mut self.aov;
        if let (Some(n), Some(h)) = (a.hits.get_mut(i), hit) {
            if h.is_finite() {
                *n += 1;
                if let Some(v) = a.albedo.get_mut(i) {
                    v.add(h.albedo);
                }
                if let Some(v) = a.normal.get_mut(i) {
                    v.add(h.normal);
                }
                if let Some(v) = a.depth.get_mut(i) {
                    v.add(h.depth);
                }
                if let Some(v) = a.position.get_mut(i) {
                    v.add(h.position);
                }
                if let Some(q) = a.squares.get_mut(i) {
                    q.albedo.add_squares(h.albedo);
                    q.normal.add_squares(h.normal);
                    q.depth.add_square(h.depth);
                    q.position.add_squares(h.position);
                }
            }
        }
        true
    }
}

/// `v` allocated with `n` default elements if `keep`, else empty (no allocation).
fn buffer<T: Clone + Default>(keep: bool, n: usize) -> Vec<T> {
    if keep {
        vec![T::default(); n]
    } else {
        Vec::new()
    }
}

/// Bytes held by `v`, or `None` if it was not allocated.
fn bytes<T>(v: &[T]) -> Option<usize> {
    (!v.is_empty()).then(|| std::mem::size_of_val(v))
}

/// Chunks of `v`, followed by empty slices forever, so that an unallocated buffer hands every
/// stripe an empty slice.
fn chunks<T>(v: &mut [T], chunk: usize) -> impl Iterator<Item = &mut [T]> {
    v.chunks_mut(chunk)
        .chain(std::iter::repeat_with(Default::default))
}

/// Per-pixel averages of one AOV's sums (zero where no sample hit a surface), or `None` if the
/// film does not keep it.
fn averages(sums: &[Sum3], hits: &[u32]) -> Option<Vec<Vec3>> {
    (!sums.is_empty()).then(|| {
        sums.iter()
            .zip(hits)
            .map(|(s, &n)| s.mean(n.into()))
            .collect()
    })
}

impl Film {
    /// An empty film keeping the given buffers. Passing an [`AovSet`] keeps what writing those
    /// outputs needs ([`FilmBuffers::for_outputs`]).
    pub fn new(width: u32, height: u32, buffers: impl Into<FilmBuffers>) -> Self {
        let mut buffers = buffers.into();
        buffers.variance |= buffers.aovs.variance;
        let n = width as usize * height as usize;
        let a = buffers.aovs;
        Self {
            width,
            height,
            buffers,
            counts: vec![0; n],
            sums: vec![Sum3::default(); n],
            squares: buffer(buffers.variance, n),
            even: buffer(buffers.halves, n),
            aov: AovBuffers {
                hits: buffer(a.any_first_hit(), n),
                albedo: buffer(a.albedo, n),
                normal: buffer(a.normal, n),
                depth: buffer(a.depth, n),
                position: buffer(a.position, n),
                squares: buffer(a.feature_variance && a.any_first_hit(), n),
                split: buffer(a.any_split(), n),
            },
            splats: SplatSums::default(),
            filtered: Mutex::default(),
            samples: buffers.samples.then(|| SampleRecords::empty(width, height)),
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
        self.buffers.aovs
    }

    /// The buffers this film keeps.
    pub fn buffers(&self) -> FilmBuffers {
        self.buffers
    }

    /// Bytes held by each buffer.
    pub fn memory(&self) -> FilmMemory {
        FilmMemory {
            mean: std::mem::size_of_val(self.counts.as_slice())
                + std::mem::size_of_val(self.sums.as_slice()),
            variance: bytes(&self.squares),
            halves: bytes(&self.even),
            first_hits: bytes(&self.aov.hits),
            albedo: bytes(&self.aov.albedo),
            normal: bytes(&self.aov.normal),
            depth: bytes(&self.aov.depth),
            position: bytes(&self.aov.position),
            feature_variance: bytes(&self.aov.squares),
            split: bytes(&self.aov.split),
            splats: self.splats.bytes(),
            filtered: lock(&self.filtered).bytes(),
            samples: self.samples.as_ref().map(SampleRecords::memory_bytes),
        }
    }

    /// Bytes held by all buffers together.
    pub fn memory_bytes(&self) -> usize {
        self.memory().total()
    }

    /// Counts samples another film dropped (when its sums are added to this one).
    pub(crate) fn add_discarded(&self, n: u64) {
        self.discarded.fetch_add(n, Ordering::Relaxed);
    }

    /// Samples dropped because they were NaN, infinite or negative.
    pub fn discarded(&self) -> u64 {
        self.discarded.load(Ordering::Relaxed)
    }

    fn stats_at(&self, i: usize) -> PixelStats {
        let (sum, n) = (&self.sums[i], self.counts[i]);
        let f = lock(&self.filtered);
        if f.is_some() {
            let halves = self.even.get(i).map(|e| {
                HalfSums::from_means([f.half_mean(i, 0), f.half_mean(i, 1)], [e.n, n - e.n])
            });
            return PixelStats::filtered(f.all[i].mean(), n, halves);
        }
        let halves = self
            .even
            .get(i)
            .map(|e| HalfSums::from_sums(&e.sum, &sum.minus(&e.sum), [e.n, n - e.n]));
        PixelStats::new(sum, n, self.squares.get(i), halves)
    }

    /// Statistics of pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> PixelStats {
        self.stats_at((y * self.width + x) as usize)
    }

    /// Statistics of all pixels, row-major.
    pub fn pixels(&self) -> impl ExactSizeIterator<Item = PixelStats> + '_ {
        (0..self.counts.len()).map(|i| self.stats_at(i))
    }

    /// Adds a sample to pixel `(x, y)`, as [`FilmStripe::add_sample`] does, for callers that
    /// fill the film from one thread.
    pub fn add_sample(
        &mut self,
        x: u32,
        y: u32,
        index: u32,
        radiance: Rgb,
        hit: Option<&FirstHit>,
    ) -> bool {
        let rows = self.height;
        self.bands(rows)
            .next()
            .is_some_and(|mut s| s.add_sample(x, y, index, radiance, hit))
    }

    /// Bands of `rows` rows (the last may be shorter), lazily, so that [`Film::add_sample`]
    /// can borrow the whole film as one band without allocating.
    fn bands(&mut self, rows: u32) -> impl Iterator<Item = FilmStripe<'_>> {
        let w = self.width;
        let rows = rows.max(1);
        let chunk = (rows as usize * w as usize).max(1);
        let discarded = &self.discarded;
        let filtered = &self.filtered;
        let height = self.height;
        let mut sums = chunks(&mut self.sums, chunk);
        let mut squares = chunks(&mut self.squares, chunk);
        let mut even = chunks(&mut self.even, chunk);
        let mut hits = chunks(&mut self.aov.hits, chunk);
        let mut albedo = chunks(&mut self.aov.albedo, chunk);
        let mut normal = chunks(&mut self.aov.normal, chunk);
        let mut depth = chunks(&mut self.aov.depth, chunk);
        let mut position = chunks(&mut self.aov.position, chunk);
        let mut feature_squares = chunks(&mut self.aov.squares, chunk);
        let mut split = chunks(&mut self.aov.split, chunk);
        self.counts
            .chunks_mut(chunk)
            .enumerate()
            .map(move |(i, counts)| FilmStripe {
                y0: i as u32 * rows,
                width: w,
                counts,
                sums: sums.next().unwrap_or_default(),
                squares: squares.next().unwrap_or_default(),
                even: even.next().unwrap_or_default(),
                aov: AovSlices {
                    hits: hits.next().unwrap_or_default(),
                    albedo: albedo.next().unwrap_or_default(),
                    normal: normal.next().unwrap_or_default(),
                    depth: depth.next().unwrap_or_default(),
                    position: position.next().unwrap_or_default(),
                    squares: feature_squares.next().unwrap_or_default(),
                    split: split.next().unwrap_or_default(),
                },
                discarded,
                height,
                window: None,
                filtered,
            })
    }

    /// Splits the film into bands of `rows` rows for parallel rendering.
    pub fn stripes_mut(&mut self, rows: u32) -> Vec<FilmStripe<'_>> {
        self.bands(rows).collect()
    }

    /// Adds `paths` light paths of sample index `index` (light-path techniques take one set of
    /// light paths per sample index) and their splats, summed in the order given: callers that
    /// render in parallel hand them over in a fixed order, so the sums do not depend on the
    /// thread count. Non-finite, negative or out-of-image splats are dropped and counted.
    pub fn add_splats(&mut self, index: u32, paths: u64, splats: &[Splat]) {
        let n = self.counts.len();
        let dropped = self
            .splats
            .add(n, self.buffers.halves, index, paths, splats);
        self.discarded.fetch_add(dropped, Ordering::Relaxed);
    }

    /// Appends a render pass's sample records (same size as the film; its unfilled slots are
    /// dropped) after the samples already kept, pixel by pixel; ignored unless the film keeps
    /// samples ([`FilmBuffers::samples`]).
    pub fn add_sample_records(&mut self, pass: SampleRecords) {
        if let Some(r) = &mut self.samples {
            if (pass.width(), pass.height()) == (self.width, self.height) {
                r.append(pass);
            }
        }
    }

    /// Every camera sample's record, grouped by pixel; `None` unless the film keeps them.
    pub fn sample_records(&self) -> Option<&SampleRecords> {
        self.samples.as_ref()
    }

    /// Moves the sample records out (leaving none), to filter them without a copy.
    pub fn take_sample_records(&mut self) -> Option<SampleRecords> {
        let (w, h) = (self.width, self.height);
        self.samples
            .as_mut()
            .map(|r| std::mem::replace(r, SampleRecords::empty(w, h)))
    }

    /// Light paths taken so far (the splats' divisor).
    pub fn light_paths(&self) -> u64 {
        self.splats.paths()
    }

    /// True if the film holds light-path splats, whose per-pixel variance it does not know.
    pub fn has_splats(&self) -> bool {
        self.splats.paths() > 0
    }

    /// True if the film holds samples splatted through a pixel filter
    /// ([`FilmStripe::add_filtered`]), whose per-pixel variance it does not know.
    pub fn has_filtered(&self) -> bool {
        lock(&self.filtered).is_some()
    }

    /// The pixel estimates, row-major: the mean of the camera samples plus the light paths'
    /// splats over the number of light paths; for a film of filtered samples, each pixel's
    /// weighted sum over its sum of weights.
    pub fn mean_image(&self) -> Vec<Rgb> {
        let f = lock(&self.filtered);
        if f.is_some() {
            return f.all.iter().map(|p| p.mean()).collect();
        }
        self.sums
            .iter()
            .zip(&self.counts)
            .enumerate()
            .map(|(i, (s, &n))| s.mean(n.into()) + self.splats.mean(i))
            .collect()
    }

    /// Variance of each pixel estimate, row-major; `None` without a variance buffer.
    pub fn variance_image(&self) -> Option<Vec<Rgb>> {
        if self.squares.is_empty() || self.has_filtered() {
            return None;
        }
        Some(
            self.pixels()
                .map(|p| p.variance_of_mean().unwrap_or_default())
                .collect(),
        )
    }

    /// Mean of the even (`0`) or odd (`1`) samples, row-major; `None` without half-buffers.
    pub fn half_image(&self, half: usize) -> Option<Vec<Rgb>> {
        if self.even.is_empty() {
            return None;
        }
        let f = lock(&self.filtered);
        if f.is_some() {
            return Some((0..self.even.len()).map(|i| f.half_mean(i, half)).collect());
        }
        Some(
            self.even
                .iter()
                .zip(self.sums.iter().zip(&self.counts))
                .enumerate()
                .map(|(i, (e, (sum, &n)))| {
                    let camera = if half == 0 {
                        e.sum.mean(e.n.into())
                    } else {
                        sum.minus(&e.sum).mean((n - e.n).into())
                    };
                    camera + self.splats.half_mean(i, half)
                })
                .collect(),
        )
    }

    /// Average first-hit albedo, row-major (zero where no sample hit); `None` unless kept.
    pub fn albedo_image(&self) -> Option<Vec<Rgb>> {
        averages(&self.aov.albedo, &self.aov.hits)
    }

    /// Average first-hit shading normal (not renormalised); `None` unless kept.
    pub fn normal_image(&self) -> Option<Vec<Vec3>> {
        averages(&self.aov.normal, &self.aov.hits)
    }

    /// Average first-hit distance from the camera; `None` unless kept.
    pub fn depth_image(&self) -> Option<Vec<f32>> {
        let d = &self.aov.depth;
        (!d.is_empty()).then(|| {
            d.iter()
                .zip(&self.aov.hits)
                .map(|(s, &n)| s.mean(n.into()))
                .collect()
        })
    }

    /// Average first-hit world position; `None` unless kept.
    pub fn position_image(&self) -> Option<Vec<Vec3>> {
        averages(&self.aov.position, &self.aov.hits)
    }

    /// Variance of each pixel's mean first-hit feature, for the features kept, when the film
    /// keeps feature variances; `None` otherwise.
    pub fn feature_variance_images(&self) -> Option<FeatureVariances> {
        let (q, a, n) = (&self.aov.squares, &self.aov, &self.aov.hits);
        if q.is_empty() {
            return None;
        }
        let of_mean = |v: f32, n: u32| if n < 2 { 0.0 } else { v / n as f32 };
        let pick = |sums: &[Sum3], sq: fn(&FeatureSquares) -> &Sum3| {
            (!sums.is_empty()).then(|| {
                sums.iter()
                    .zip(q)
                    .zip(n)
                    .map(|((s, f), &n)| sample_variance3(n.into(), s, sq(f)).map(|v| of_mean(v, n)))
                    .collect()
            })
        };
        Some(FeatureVariances {
            albedo: pick(&a.albedo, |f| &f.albedo),
            normal: pick(&a.normal, |f| &f.normal),
            depth: (!a.depth.is_empty()).then(|| {
                a.depth
                    .iter()
                    .zip(q)
                    .zip(n)
                    .map(|((s, f), &n)| of_mean(sample_variance(n.into(), s.0, f.depth.0), n))
                    .collect()
            }),
            position: pick(&a.position, |f| &f.position),
        })
    }

    /// The per-pixel means of the lighting split (sums over the pixel's kept samples); `None`
    /// unless some part of it is kept.
    pub fn split_images(&self) -> Option<Vec<LightSplit>> {
        if self.aov.split.is_empty() {
            return None;
        }
        Some(
            self.aov
                .split
                .iter()
                .zip(&self.counts)
                .map(|(s, &n)| s.mean(n))
                .collect(),
        )
    }

    /// Total samples accumulated.
    pub fn total_samples(&self) -> u64 {
        self.counts.iter().map(|&n| u64::from(n)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LateSums, AOV_NAMES};

    /// A technique whose paths start at the lights.
    const LIGHT: LateSums = LateSums {
        light_splats: true,
        filtered: false,
    };

    #[test]
    fn the_estimate_is_what_a_film_allocates() {
        // Every output combination `render --aov` can ask for, one at a time and all together.
        let mut sets: Vec<AovSet> = AOV_NAMES
            .iter()
            .map(|n| AovSet::parse_list([*n]).unwrap())
            .collect();
        sets.push(AovSet::parse_list(AOV_NAMES).unwrap());
        sets.push(AovSet::default());
        for aovs in sets {
            for buffers in [
                FilmBuffers::for_outputs(aovs),
                FilmBuffers::for_outputs(aovs).with_halves().with_variance(),
            ] {
                let film = Film::new(7, 5, buffers);
                assert_eq!(
                    FilmMemory::estimate(7, 5, buffers, 0, LateSums::default()),
                    film.memory(),
                    "{buffers:?}"
                );
            }
        }
        // Splats appear with the first light path; records grow with the samples.
        let mut film = Film::new(7, 5, FilmBuffers::default());
        film.add_splats(
            0,
            1,
            &[Splat {
                pixel: 3,
                value: Rgb::ONE,
            }],
        );
        let e = FilmMemory::estimate(7, 5, FilmBuffers::default(), 0, LIGHT);
        assert_eq!(e.splats, film.memory().splats);
        let halves = FilmBuffers::default().with_halves();
        let mut film = Film::new(7, 5, halves);
        film.add_splats(
            0,
            1,
            &[Splat {
                pixel: 3,
                value: Rgb::ONE,
            }],
        );
        let e = FilmMemory::estimate(7, 5, halves, 0, LIGHT);
        assert_eq!(e.splats, film.memory().splats);
        // Filtered sums appear with the first splatted camera sample, doubled by half-buffers.
        let filter = PixelFilter::parse("gaussian:splat").unwrap();
        for buffers in [FilmBuffers::default(), halves] {
            let mut film = Film::new(7, 5, buffers);
            for mut stripe in film.stripes_mut(2) {
                let y = stripe.y0;
                stripe.add_filtered(&filter, Vec2::new(0.5, y as f32 + 0.5), (0, y), 0, Rgb::ONE);
            }
            let late = LateSums {
                filtered: true,
                ..LateSums::default()
            };
            let e = FilmMemory::estimate(7, 5, buffers, 0, late);
            assert_eq!(e, film.memory(), "{buffers:?}");
        }
        let records = FilmBuffers {
            samples: true,
            ..FilmBuffers::default()
        };
        let e = FilmMemory::estimate(7, 5, records, 16, LateSums::default());
        assert_eq!(e.samples, Some(35 * 16 * 56 + 36 * 8));
        // A 16384² film with every sample kept at 1024 spp: about 15 TB, without overflow.
        let huge = FilmMemory::estimate(16384, 16384, records, 1024, LateSums::default());
        assert!(huge.total() > 15_000_000_000_000, "{huge:?}");
    }

    fn all_buffers() -> FilmBuffers {
        FilmBuffers::for_outputs(AovSet {
            albedo: true,
            normal: true,
            depth: true,
            position: true,
            variance: true,
            ..Default::default()
        })
        .with_halves()
    }

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
            assert_eq!(stripes.iter().map(FilmStripe::rows).sum::<u32>(), 5);
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
                        assert!(!s.add_sample(x, y, 1, Rgb::splat(-1.0), None));
                    }
                }
            }
        }
        assert_eq!(film.discarded(), 45);
        assert_eq!(film.pixel(2, 4).mean(), Rgb::splat(4.0));
        assert_eq!(film.total_samples(), 15);
        assert_eq!(film.depth_image().unwrap()[7], 2.0);
        assert!(film.albedo_image().is_none());
    }

    #[test]
    fn only_requested_buffers_are_allocated() {
        let film = Film::new(4, 4, AovSet::default());
        let m = film.memory();
        assert_eq!(m.mean, 16 * 52, "sums (48 B) and count (4 B) per pixel");
        assert_eq!(
            (m.variance, m.halves, m.first_hits),
            (None, None, None),
            "{m:?}"
        );
        assert_eq!(
            (m.albedo, m.normal, m.depth, m.position),
            (None, None, None, None)
        );
        assert_eq!(film.memory_bytes(), 16 * 52);
        assert!(film.variance_image().is_none() && film.half_image(0).is_none());
        assert!(film.pixel(1, 1).variance_of_mean().is_none());

        // The variance output brings its buffer and nothing else.
        let film = Film::new(
            4,
            4,
            AovSet {
                variance: true,
                ..Default::default()
            },
        );
        let m = film.memory();
        assert_eq!(m.variance, Some(16 * 96));
        assert_eq!((m.halves, m.first_hits, m.albedo), (None, None, None));
        assert!(film.buffers().variance && !film.buffers().halves);
        assert_eq!(film.variance_image().unwrap().len(), 16);

        // One first-hit AOV: its sums plus the shared hit count.
        let film = Film::new(
            4,
            4,
            AovSet {
                albedo: true,
                ..Default::default()
            },
        );
        let m = film.memory();
        assert_eq!((m.first_hits, m.albedo), (Some(16 * 4), Some(16 * 48)));
        assert_eq!(
            (m.normal, m.depth, m.position, m.variance),
            (None, None, None, None)
        );

        let film = Film::new(4, 4, all_buffers());
        let per_pixel = film.memory_bytes() / 16;
        assert_eq!(per_pixel, 52 + 96 + 64 + 4 + 48 + 48 + 16 + 48);
        assert!(film.half_image(1).is_some());
        assert!(AovSet::parse_list(["albedo", "bogus"]).is_err());
        let all = AovSet::parse_list(AOV_NAMES).unwrap();
        assert_eq!(AovSet::parse_list(all.names()), Ok(all));
        assert_eq!(all.names().len(), AOV_NAMES.len() - 1, "all but `denoise`");
    }

    /// The mean's bits do not depend on which optional buffers are kept, and the statistics
    /// agree with a two-pass computation in `f64`.
    #[test]
    fn statistics_are_exact_and_the_same_with_and_without_optional_buffers() {
        let mut lean = Film::new(2, 2, AovSet::default());
        let mut full = Film::new(2, 2, all_buffers());
        // Each pixel's samples in f64, for the reference statistics.
        let mut kept: Vec<Vec<[f64; 3]>> = vec![Vec::new(); 4];
        // A spread of magnitudes, so that rounding differences would show.
        let mut state = 0x1234_5678u32;
        for i in 0..1000u32 {
            state = rt_core::sampler::hash_u32(state.wrapping_add(i));
            let v = (state >> 8) as f32 / (1 << 24) as f32;
            let x = Rgb::new(v * 1e3, v * v, (1.0 - v) * 7.0);
            let p = (state & 3) as usize;
            let (px, py) = (p as u32 % 2, p as u32 / 2);
            assert!(lean.add_sample(px, py, i, x, None));
            assert!(full.add_sample(px, py, i, x, Some(&FirstHit::default())));
            kept[p].push(x.to_array().map(f64::from));
        }
        let bits = |img: &[Rgb]| -> Vec<[u32; 3]> {
            img.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
        };
        assert_eq!(bits(&lean.mean_image()), bits(&full.mean_image()));
        for (p, xs) in full.pixels().zip(&kept) {
            let n = xs.len() as f64;
            for c in 0..3 {
                let mean = xs.iter().map(|x| x[c]).sum::<f64>() / n;
                let var = xs.iter().map(|x| (x[c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
                // The mean within an f32 rounding; the variance within the f64 subtraction's
                // cancellation (relative to the squares' size) and an f32 rounding.
                assert!((f64::from(p.mean()[c]) - mean).abs() <= 1e-7 * mean, "{c}");
                let squares = xs.iter().map(|x| x[c] * x[c]).sum::<f64>() / n;
                let got = f64::from(p.variance_of_mean().unwrap()[c]);
                assert!((got - var / n).abs() <= 1e-7 * var / n + 1e-15 * squares);
            }
        }
        assert_eq!(lean.pixels().len(), 4);
        assert_eq!(full.total_samples(), 1000);
    }

    #[test]
    fn aov_averages_skip_non_finite_hits_and_empty_pixels() {
        let mut film = Film::new(2, 1, all_buffers());
        let hit = |d: f32| FirstHit {
            albedo: Rgb::splat(0.5),
            normal: Vec3::Z,
            depth: d,
            position: Vec3::new(1.0, 2.0, 3.0),
        };
        film.add_sample(0, 0, 0, Rgb::ONE, Some(&hit(2.0)));
        film.add_sample(0, 0, 1, Rgb::ONE, Some(&hit(4.0)));
        film.add_sample(0, 0, 2, Rgb::ONE, Some(&hit(f32::NAN)));
        film.add_sample(1, 0, 0, Rgb::ONE, None);
        assert_eq!(film.depth_image().unwrap(), vec![3.0, 0.0]);
        assert_eq!(film.albedo_image().unwrap()[0], Rgb::splat(0.5));
        assert_eq!(film.normal_image().unwrap()[1], Vec3::ZERO);
        assert_eq!(film.position_image().unwrap()[0], Vec3::new(1.0, 2.0, 3.0));
        let h = *film.pixel(0, 0).halves().unwrap();
        assert_eq!((h.count(0), h.count(1)), (2, 1));
    }
}
