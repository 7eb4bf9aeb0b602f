//! A film's exact sums as bytes, for part files and checkpoints: [`Film::encode_sums`] writes
//! the sums of one rectangle of pixels, [`Film::add_encoded`] adds them into another film with
//! the same buffers. Because the sums are integers ([`crate::fixed`]), a film that adds the
//! parts of a render (sample ranges, regions, or the state before a checkpoint) holds the very
//! bits of the film that rendered everything itself.
//!
//! Layout (little-endian): a flags byte (bit 0: light-path splats present; bit 1: filtered
//! sums of a splatted pixel filter present), the discarded sample count (`u64`), with splats
//! the light paths and even-index light paths taken (two `u64`); then, for each buffer the
//! film keeps, in a fixed order, one element per pixel of the rectangle in row-major order,
//! the filtered sums last. Nothing in the bytes says how long anything is: the reader
//! computes every length from its own buffers and the rectangle, and checks the total first,
//! so a corrupt or hostile input can neither make it allocate nor read out of bounds.
//! Per-sample records ([`FilmBuffers::samples`]) are not encoded.

use crate::film::{EvenSums, Film};
use crate::filtered::Weighted;
use crate::fixed::{Squares3, Sum1, Sum3};
use crate::pixel::{FeatureSquares, SplitSums};
use crate::{FilmBuffers, LateSums};

/// A rectangle of pixels: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Rect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Rect {
    /// The whole `width × height` image.
    pub fn full(width: u32, height: u32) -> Rect {
        Rect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Width in pixels (zero if empty).
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    /// Height in pixels (zero if empty).
    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    /// Number of pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }

    /// True if the rectangle holds at least one pixel and lies inside a `width × height`
    /// image.
    pub fn is_inside(&self, width: u32, height: u32) -> bool {
        self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= width && self.y1 <= height
    }

    /// True if pixel `(x, y)` lies inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// True if the two rectangles share a pixel.
    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    /// Row-major indices, in a `width`-wide image, of the rectangle's pixels.
    fn indices(self, width: u32) -> impl Iterator<Item = usize> {
        (self.y0..self.y1)
            .flat_map(move |y| (self.x0..self.x1).map(move |x| (y * width + x) as usize))
    }
}

impl std::fmt::Display for Rect {
    /// As `--region` takes it: `x0,y0,x1,y1`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// Why [`Film::add_encoded`] refused its input.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RawError {
    /// The rectangle is empty or leaves the film.
    #[error("region {rect} is empty or outside the {width}x{height} image")]
    Rect {
        /// The rectangle.
        rect: Rect,
        /// Film width.
        width: u32,
        /// Film height.
        height: u32,
    },
    /// The byte count is not what the film's buffers and the rectangle need.
    #[error("{got} bytes of sums where the region and the film's buffers need {want}")]
    Length {
        /// Bytes given.
        got: usize,
        /// Bytes expected.
        want: u64,
    },
    /// A count would overflow (more than 2³² samples in a pixel).
    #[error("the sums overflow: more than 2^32 samples in a pixel")]
    Overflow,
}

/// One pixel's element of a buffer, as bytes.
trait Raw: Sized {
    const BYTES: usize;
    fn put(&self, out: &mut Vec<u8>);
    /// Reads from exactly [`Raw::BYTES`] bytes.
    fn get(b: &[u8]) -> Self;
    /// Adds `o` into `self`; `false` on overflow.
    fn merge(&mut self, o: &Self) -> bool;
}

fn i128_at(b: &[u8], k: usize) -> i128 {
    let mut a = [0u8; 16];
    a.copy_from_slice(&b[16 * k..16 * k + 16]);
    i128::from_le_bytes(a)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[at..at + 4]);
    u32::from_le_bytes(a)
}

impl Raw for u32 {
    const BYTES: usize = 4;
    fn put(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn get(b: &[u8]) -> Self {
        u32_at(b, 0)
    }
    fn merge(&mut self, o: &Self) -> bool {
        match self.checked_add(*o) {
            Some(v) => {
                *self = v;
                true
            }
            None => false,
        }
    }
}

/// Sums of `N` grid values, read and written as `N` little-endian `i128`.
trait Sums: Sized {
    const N: usize;
    fn values(&self) -> impl Iterator<Item = i128>;
    fn from_values(v: impl FnMut(usize) -> i128) -> Self;
    fn add_values(&mut self, o: &Self);
}

impl<T: Sums> Raw for T {
    const BYTES: usize = 16 * T::N;
    fn put(&self, out: &mut Vec<u8>) {
        for v in self.values() {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    fn get(b: &[u8]) -> Self {
        T::from_values(|k| i128_at(b, k))
    }
    fn merge(&mut self, o: &Self) -> bool {
        self.add_values(o);
        true
    }
}

impl Sums for Sum1 {
    const N: usize = 1;
    fn values(&self) -> impl Iterator<Item = i128> {
        std::iter::once(self.0)
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        Sum1(v(0))
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

impl Sums for Sum3 {
    const N: usize = 3;
    fn values(&self) -> impl Iterator<Item = i128> {
        self.0.into_iter()
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        Sum3([v(0), v(1), v(2)])
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

impl Sums for Squares3 {
    const N: usize = 6;
    fn values(&self) -> impl Iterator<Item = i128> {
        self.fine.into_iter().chain(self.coarse)
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        Squares3 {
            fine: [v(0), v(1), v(2)],
            coarse: [v(3), v(4), v(5)],
        }
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

impl Sums for FeatureSquares {
    const N: usize = 10;
    fn values(&self) -> impl Iterator<Item = i128> {
        let d = [self.depth.0];
        self.albedo
            .0
            .into_iter()
            .chain(self.normal.0)
            .chain(d)
            .chain(self.position.0)
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        FeatureSquares {
            albedo: Sum3([v(0), v(1), v(2)]),
            normal: Sum3([v(3), v(4), v(5)]),
            depth: Sum1(v(6)),
            position: Sum3([v(7), v(8), v(9)]),
        }
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

impl Sums for SplitSums {
    const N: usize = 18;
    fn values(&self) -> impl Iterator<Item = i128> {
        self.parts().iter().flat_map(|s| s.0)
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        SplitSums::from_parts(std::array::from_fn(|p| {
            Sum3([v(3 * p), v(3 * p + 1), v(3 * p + 2)])
        }))
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

impl Sums for Weighted {
    const N: usize = 4;
    fn values(&self) -> impl Iterator<Item = i128> {
        self.sum.0.into_iter().chain([self.weight.0])
    }
    fn from_values(mut v: impl FnMut(usize) -> i128) -> Self {
        Weighted {
            sum: Sum3([v(0), v(1), v(2)]),
            weight: Sum1(v(3)),
        }
    }
    fn add_values(&mut self, o: &Self) {
        self.merge(o);
    }
}

/// Flag bits of the encoding's first byte.
const LIGHT_SPLATS: u8 = 1;
const FILTERED: u8 = 2;

impl Raw for EvenSums {
    const BYTES: usize = 16 * 3 + 4;
    fn put(&self, out: &mut Vec<u8>) {
        self.sum.put(out);
        self.n.put(out);
    }
    fn get(b: &[u8]) -> Self {
        EvenSums {
            sum: Sum3::get(&b[..48]),
            n: u32_at(b, 48),
        }
    }
    fn merge(&mut self, o: &Self) -> bool {
        self.sum.merge(&o.sum);
        self.n.merge(&o.n)
    }
}

fn put_all<T: Raw>(buf: &[T], rect: Rect, width: u32, out: &mut Vec<u8>) {
    if !buf.is_empty() {
        rect.indices(width).for_each(|i| buf[i].put(out));
    }
}

/// Bytes of one pixel's elements of every buffer `buffers` keeps (splats apart).
fn pixel_bytes(b: &FilmBuffers) -> usize {
    let a = b.aovs;
    let keep = |k: bool, n: usize| if k { n } else { 0 };
    u32::BYTES
        + Sum3::BYTES
        + keep(b.variance || a.variance, Squares3::BYTES)
        + keep(b.halves, EvenSums::BYTES)
        + keep(a.any_first_hit(), u32::BYTES)
        + keep(a.albedo, Sum3::BYTES)
        + keep(a.normal, Sum3::BYTES)
        + keep(a.depth, Sum1::BYTES)
        + keep(a.position, Sum3::BYTES)
        + keep(
            a.feature_variance && a.any_first_hit(),
            FeatureSquares::BYTES,
        )
        + keep(a.any_split(), SplitSums::BYTES)
}

/// Reads buffers of a rectangle in order, adding each into the film's.
struct Adder<'a> {
    bytes: &'a [u8],
    rect: Rect,
    width: u32,
    overflow: bool,
}

impl Adder<'_> {
    fn add<T: Raw>(&mut self, buf: &mut [T]) {
        if buf.is_empty() {
            return;
        }
        let (mine, rest) = self.bytes.split_at(self.rect.area() as usize * T::BYTES);
        self.bytes = rest;
        for (i, b) in self
            .rect
            .indices(self.width)
            .zip(mine.chunks_exact(T::BYTES))
        {
            self.overflow |= !buf[i].merge(&T::get(b));
        }
    }
}

impl Film {
    /// The exact sums of the pixels in `rect` (which must lie inside the film), with the
    /// light-path counts and the discarded-sample count, as bytes (layout: the crate doc).
    pub fn encode_sums(&self, rect: Rect) -> Vec<u8> {
        let w = self.width();
        let splats = self.splats.parts();
        let filtered = self.filtered.lock().unwrap_or_else(|e| e.into_inner());
        let flags = if splats.is_some() { LIGHT_SPLATS } else { 0 }
            | if filtered.is_some() { FILTERED } else { 0 };
        let mut out = Vec::with_capacity(self.encoded_len(rect, flags) as usize);
        out.push(flags);
        out.extend_from_slice(&self.discarded().to_le_bytes());
        if let Some((_, _, paths, even_paths)) = splats {
            out.extend_from_slice(&paths.to_le_bytes());
            out.extend_from_slice(&even_paths.to_le_bytes());
        }
        put_all(&self.counts, rect, w, &mut out);
        put_all(&self.sums, rect, w, &mut out);
        put_all(&self.squares, rect, w, &mut out);
        put_all(&self.even, rect, w, &mut out);
        let a = &self.aov;
        put_all(&a.hits, rect, w, &mut out);
        put_all(&a.albedo, rect, w, &mut out);
        put_all(&a.normal, rect, w, &mut out);
        put_all(&a.depth, rect, w, &mut out);
        put_all(&a.position, rect, w, &mut out);
        put_all(&a.squares, rect, w, &mut out);
        put_all(&a.split, rect, w, &mut out);
        if let Some((all, even, _, _)) = splats {
            put_all(all, rect, w, &mut out);
            put_all(even, rect, w, &mut out);
        }
        put_all(&filtered.all, rect, w, &mut out);
        put_all(&filtered.even, rect, w, &mut out);
        out
    }

    /// Bytes [`Film::encode_sums`] writes for `rect` with the given flags (with or without
    /// light-path splats and filtered sums).
    fn encoded_len(&self, rect: Rect, flags: u8) -> u64 {
        let mut n = 1 + 8 + rect.area() * pixel_bytes(&self.buffers()) as u64;
        let sets = 1 + u64::from(self.buffers().halves);
        if flags & LIGHT_SPLATS != 0 {
            n += 16 + rect.area() * sets * Sum3::BYTES as u64;
        }
        if flags & FILTERED != 0 {
            n += rect.area() * sets * Weighted::BYTES as u64;
        }
        n
    }

    /// The late sums ([`LateSums`]) that bytes [`Film::encode_sums`] wrote carry, read from
    /// their flags byte (unchecked: [`Film::add_encoded`] checks the rest).
    pub fn encoded_late_sums(bytes: &[u8]) -> LateSums {
        let flags = bytes.first().copied().unwrap_or(0);
        LateSums {
            light_splats: flags & LIGHT_SPLATS != 0,
            filtered: flags & FILTERED != 0,
        }
    }

    /// Adds sums that [`Film::encode_sums`] wrote for `rect` from a film with the same
    /// buffers. `add_light_paths`: whether the light paths the bytes were taken with count
    /// again: yes for a part of other sample indices or a checkpoint; no for a second region
    /// of a sample range whose light paths an earlier region already counted (every region
    /// traces all of them and keeps the splats that land inside it).
    pub fn add_encoded(
        &mut self,
        rect: Rect,
        bytes: &[u8],
        add_light_paths: bool,
    ) -> Result<(), RawError> {
        let (w, h) = (self.width(), self.height());
        if !rect.is_inside(w, h) {
            return Err(RawError::Rect {
                rect,
                width: w,
                height: h,
            });
        }
        let flags = bytes.first().copied().unwrap_or(0);
        let splats = flags & LIGHT_SPLATS != 0;
        let want = self.encoded_len(rect, flags);
        if bytes.len() as u64 != want || flags > (LIGHT_SPLATS | FILTERED) {
            return Err(RawError::Length {
                got: bytes.len(),
                want,
            });
        }
        let u64_at = |at: usize| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&bytes[at..at + 8]);
            u64::from_le_bytes(a)
        };
        let discarded = u64_at(1);
        let mut at = 9;
        let paths = splats.then(|| {
            at += 16;
            (u64_at(9), u64_at(17))
        });
        let mut r = Adder {
            bytes: &bytes[at..],
            rect,
            width: w,
            overflow: false,
        };
        r.add(&mut self.counts);
        r.add(&mut self.sums);
        r.add(&mut self.squares);
        r.add(&mut self.even);
        let a = &mut self.aov;
        r.add(&mut a.hits);
        r.add(&mut a.albedo);
        r.add(&mut a.normal);
        r.add(&mut a.depth);
        r.add(&mut a.position);
        r.add(&mut a.squares);
        r.add(&mut a.split);
        if let Some((paths, even_paths)) = paths {
            let halves = self.buffers().halves;
            let (all, even) = self.splats.parts_mut((w * h) as usize, halves);
            r.add(all);
            r.add(even);
            if add_light_paths {
                self.splats.add_paths(paths, even_paths);
            }
        }
        if flags & FILTERED != 0 {
            let halves = self.buffers().halves;
            let filtered = self.filtered.get_mut().unwrap_or_else(|e| e.into_inner());
            let (all, even) = filtered.parts_mut((w * h) as usize, halves);
            r.add(all);
            r.add(even);
        }
        self.add_discarded(discarded);
        if r.overflow {
            return Err(RawError::Overflow);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AovSet, FirstHit, LightSplit, Splat};
    use rt_core::glam::Vec3;
    use rt_core::Rgb;

    fn buffers() -> FilmBuffers {
        FilmBuffers::for_outputs(AovSet::parse_list(crate::AOV_NAMES).unwrap()).with_halves()
    }

    /// Sample `i` of pixel `p`: some deterministic, varied value.
    fn sample(p: u32, i: u32) -> (Rgb, FirstHit, LightSplit) {
        let h = rt_core::sampler::hash_u32(p * 7919 + i * 104_729);
        let v = (h >> 8) as f32 / (1 << 24) as f32;
        let l = Rgb::new(v * 30.0, v * v, 1.0 - v);
        let hit = FirstHit {
            albedo: Rgb::splat(v),
            normal: Vec3::new(v, -v, 0.5),
            depth: 1.0 + 100.0 * v,
            position: Vec3::new(-3.0 * v, 2.0, v),
        };
        let split = LightSplit {
            emission: l * 0.25,
            direct: l * 0.5,
            irradiance: l * 2.0,
            ..Default::default()
        };
        (l, hit, split)
    }

    /// Renders samples `range` of the pixels in `rect` and the splats of those indices.
    fn render(rect: Rect, range: std::ops::Range<u32>) -> Film {
        let mut film = Film::new(5, 4, buffers());
        for i in range {
            for y in rect.y0..rect.y1 {
                for x in rect.x0..rect.x1 {
                    let (l, hit, split) = sample(y * 5 + x, i);
                    let mut s = film.stripes_mut(4).pop().unwrap();
                    s.add_sample_split(x, y, i, l, Some(&hit), Some(&split));
                }
            }
            let splats: Vec<Splat> = (0..20)
                .map(|p| Splat {
                    pixel: (p * 3 + i) % 20,
                    value: sample(p, i).0 * 0.1,
                })
                .filter(|s| rect.contains(s.pixel % 5, s.pixel / 5))
                .collect();
            film.add_splats(i, 20, &splats);
        }
        film
    }

    fn bits(film: &Film) -> Vec<u8> {
        film.encode_sums(Rect::full(film.width(), film.height()))
    }

    #[test]
    fn parts_of_samples_and_regions_add_up_to_the_whole_bit_for_bit() {
        let full = Rect::full(5, 4);
        let whole = render(full, 0..9);
        // Sample ranges.
        let mut merged = Film::new(5, 4, buffers());
        for range in [0..2, 2..7, 7..9] {
            let part = render(full, range);
            merged
                .add_encoded(full, &part.encode_sums(full), true)
                .unwrap();
        }
        assert_eq!(bits(&merged), bits(&whole));
        assert_eq!(merged.mean_image(), whole.mean_image());
        assert_eq!(merged.half_image(1), whole.half_image(1));
        assert_eq!(merged.variance_image(), whole.variance_image());
        assert_eq!(merged.split_images(), whole.split_images());
        assert_eq!(
            merged.feature_variance_images(),
            whole.feature_variance_images()
        );
        // Regions, each of all sample indices (light paths counted once).
        let tiles = [
            Rect {
                x0: 0,
                y0: 0,
                x1: 3,
                y1: 4,
            },
            Rect {
                x0: 3,
                y0: 0,
                x1: 5,
                y1: 1,
            },
            Rect {
                x0: 3,
                y0: 1,
                x1: 5,
                y1: 4,
            },
        ];
        let mut merged = Film::new(5, 4, buffers());
        for (k, t) in tiles.iter().enumerate() {
            let part = render(*t, 0..9);
            merged
                .add_encoded(*t, &part.encode_sums(*t), k == 0)
                .unwrap();
        }
        assert_eq!(merged.mean_image(), whole.mean_image());
        assert_eq!(bits(&merged), bits(&whole));
    }

    #[test]
    fn bad_bytes_are_refused_without_panicking() {
        let full = Rect::full(5, 4);
        let part = render(full, 0..2);
        let bytes = part.encode_sums(full);
        let mut film = Film::new(5, 4, buffers());
        for cut in [0, 1, 9, 100, bytes.len() - 1] {
            let e = film.add_encoded(full, &bytes[..cut], true).unwrap_err();
            assert!(matches!(e, RawError::Length { .. }), "{e}");
        }
        let mut flags = bytes.clone();
        flags[0] = 7;
        assert!(film.add_encoded(full, &flags, true).is_err());
        let outside = Rect {
            x0: 4,
            y0: 0,
            x1: 6,
            y1: 1,
        };
        assert!(matches!(
            film.add_encoded(outside, &bytes, true),
            Err(RawError::Rect { .. })
        ));
        // Another film's buffers need other lengths.
        let lean = Film::new(5, 4, AovSet::default());
        assert!(lean.add_encoded_check(full, &bytes));
        // Counts that overflow are caught.
        let mut big = bytes.clone();
        let at = if big[0] == 1 { 25 } else { 9 };
        big[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let mut film = Film::new(5, 4, buffers());
        film.add_encoded(full, &big, true).unwrap();
        assert_eq!(film.add_encoded(full, &big, true), Err(RawError::Overflow));
    }

    impl Film {
        /// True if `add_encoded` on a copy refuses the bytes.
        fn add_encoded_check(&self, rect: Rect, bytes: &[u8]) -> bool {
            let mut f = Film::new(self.width(), self.height(), self.buffers());
            f.add_encoded(rect, bytes, true).is_err()
        }
    }
}
