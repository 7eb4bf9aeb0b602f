//! Pixel filters applied by splatting, as Mitsuba 3's `ImageBlock::put` applies them: each
//! camera sample, taken at a position uniform in its pixel, is added to every pixel whose
//! centre lies within the filter's radius, with the weight [`PixelFilter::eval`] gives its
//! offset along each axis (the product of the two); a pixel's value is its sum of weighted
//! samples over its sum of weights ([`Weighted::mean`]). Mitsuba's conventions, kept: pixel
//! `i`'s centre is at `i + ½`; the pixels reached along an axis from position `p` are
//! `ceil(p − ½ − r) ..= floor(p − ½ + r)`; pixels outside the image are dropped (Mitsuba's
//! border is developed away), so an edge pixel divides by the weights it received.
//!
//! Determinism: every weight and product is a function of the sample alone, and the sums are
//! exact integers ([`crate::fixed`]), so the order in which samples and bands arrive changes
//! nothing. A band of rows splats into its own rows and up to [`margin`] rows on either side,
//! which other bands own: each band collects its splats in a [`Window`] of its rows and the
//! margins, and the window is added into the film's sums when the band's stripe is dropped
//! (under a lock; integer addition, so the order bands finish in does not matter).
//!
//! Deviation from Mitsuba: the weights are evaluated exactly (Mitsuba's scalar variants look
//! them up in a table of 32 points per radius; its JIT variants, which the references use,
//! evaluate them exactly as here).

use crate::fixed::{real, Sum1, Sum3};
use rt_core::pixel_filter::PixelFilter;
use rt_core::Rgb;

/// Most pixels a filter reaches along one axis: [`PixelFilter::parse`] allows radii up to 16
/// pixels, which reach at most 33.
pub(crate) const MAX_TAPS: usize = 33;

/// One pixel's filter-weighted sums: Σ w·L and Σ w (64 bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Weighted {
    pub sum: Sum3,
    pub weight: Sum1,
}

impl Weighted {
    #[inline]
    fn add(&mut self, w: f32, l: Rgb) {
        self.sum.add(l * w);
        self.weight.add(w);
    }

    #[inline]
    pub fn merge(&mut self, o: &Weighted) {
        self.sum.merge(&o.sum);
        self.weight.merge(&o.weight);
    }

    #[inline]
    pub fn minus(&self, o: &Weighted) -> Weighted {
        Weighted {
            sum: self.sum.minus(&o.sum),
            weight: Sum1(self.weight.0 - o.weight.0),
        }
    }

    /// Σ w·L / Σ w; zero where no weight arrived (as Mitsuba develops such a pixel).
    #[inline]
    pub fn mean(&self) -> Rgb {
        let w = real(self.weight.0);
        if w <= 0.0 {
            return Rgb::ZERO;
        }
        Rgb::from_array(self.sum.0.map(|s| (real(s) / w) as f32))
    }
}

/// The filtered sums of a film: every sample's (`all`) and, with half-buffers, the even
/// sample indices' (`even`); empty until the first band adds its window.
#[derive(Clone, Debug, Default)]
pub(crate) struct FilterSums {
    pub all: Vec<Weighted>,
    pub even: Vec<Weighted>,
}

impl FilterSums {
    /// True once the film holds filtered sums.
    #[inline]
    pub fn is_some(&self) -> bool {
        !self.all.is_empty()
    }

    /// The sums to add into, allocated for `pixels` pixels if there were none.
    pub fn parts_mut(&mut self, pixels: usize, halves: bool) -> (&mut [Weighted], &mut [Weighted]) {
        if self.all.is_empty() {
            self.all = vec![Weighted::default(); pixels];
            if halves {
                self.even = vec![Weighted::default(); pixels];
            }
        }
        (&mut self.all, &mut self.even)
    }

    /// The estimate of pixel `i` from the even (`0`) or odd (`1`) sample indices.
    pub fn half_mean(&self, i: usize, half: usize) -> Rgb {
        let (Some(a), Some(e)) = (self.all.get(i), self.even.get(i)) else {
            return Rgb::ZERO;
        };
        if half == 0 {
            e.mean()
        } else {
            a.minus(e).mean()
        }
    }

    /// Bytes held, `None` before the first splat.
    pub fn bytes(&self) -> Option<usize> {
        self.is_some().then(|| {
            std::mem::size_of_val(self.all.as_slice()) + std::mem::size_of_val(self.even.as_slice())
        })
    }
}

/// The pixels one axis of a splat reaches and their weights.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Taps {
    /// First pixel reached.
    pub first: u32,
    /// Pixels reached (`first..first + count`); zero if none inside the image.
    pub count: u32,
    pub weights: [f32; MAX_TAPS],
}

/// The pixels of `0..len` along one axis that a sample at film coordinate `p` reaches through
/// `filter`, and their weights (Mitsuba's conventions: the module doc).
#[inline]
pub(crate) fn taps(filter: &PixelFilter, p: f32, len: u32) -> Taps {
    let r = filter.radius();
    let centre = p - 0.5;
    let lo = (centre - r).ceil().max(0.0);
    let hi = (centre + r).floor().min(len as f32 - 1.0);
    let mut t = Taps {
        first: lo as u32,
        count: 0,
        weights: [0.0; MAX_TAPS],
    };
    if lo > hi {
        return t;
    }
    t.count = ((hi - lo) as u32 + 1).min(MAX_TAPS as u32);
    for (k, w) in t.weights[..t.count as usize].iter_mut().enumerate() {
        *w = filter.eval((t.first + k as u32) as f32 - centre);
    }
    t
}

/// Rows beyond its own that a band's samples reach through `filter`: a sample in row `y` lies
/// in `[y, y + 1)`, so it reaches rows up to `floor(y + ½ + r)` and down to `ceil(y − ½ − r)`.
pub(crate) fn margin(filter: &PixelFilter) -> u32 {
    (filter.radius() + 0.5).ceil() as u32
}

/// A band's filtered splats: rows `y0..y0 + rows` of the image (its own and the margins).
#[derive(Debug)]
pub(crate) struct Window {
    pub y0: u32,
    pub rows: u32,
    pub sums: FilterSums,
}

impl Window {
    /// The window of the band of rows `band` in an image `width × height`, for `filter`.
    pub fn new(
        band: std::ops::Range<u32>,
        width: u32,
        height: u32,
        filter: &PixelFilter,
        halves: bool,
    ) -> Self {
        let m = margin(filter);
        let y0 = band.start.saturating_sub(m);
        let y1 = band.end.saturating_add(m).min(height);
        let rows = y1 - y0;
        let mut sums = FilterSums::default();
        sums.parts_mut(rows as usize * width as usize, halves);
        Window { y0, rows, sums }
    }

    /// Splats `l`, of sample index parity `even`, at film position `(px, py)` through
    /// `filter` (the caller checked that `l` is kept).
    #[inline]
    pub fn splat(
        &mut self,
        filter: &PixelFilter,
        (px, py): (f32, f32),
        (width, height): (u32, u32),
        even: bool,
        l: Rgb,
    ) {
        let tx = taps(filter, px, width);
        let ty = taps(filter, py, height);
        let halves = !self.sums.even.is_empty();
        for (j, &wy) in ty.weights[..ty.count as usize].iter().enumerate() {
            let y = ty.first + j as u32;
            // Rows outside the window cannot occur for the filter the window was made for.
            let Some(row) = y.checked_sub(self.y0).filter(|&r| r < self.rows) else {
                continue;
            };
            let base = (row * width + tx.first) as usize;
            for (k, &wx) in tx.weights[..tx.count as usize].iter().enumerate() {
                let w = wx * wy;
                if w == 0.0 {
                    continue;
                }
                self.sums.all[base + k].add(w, l);
                if even && halves {
                    self.sums.even[base + k].add(w, l);
                }
            }
        }
    }

    /// Adds the window into `film`'s sums of an image `width` wide with `pixels` pixels.
    pub fn add_into(&self, film: &mut FilterSums, width: u32, pixels: usize) {
        let halves = !self.sums.even.is_empty();
        let (all, even) = film.parts_mut(pixels, halves);
        let at = self.y0 as usize * width as usize;
        let n = self.sums.all.len();
        for (d, s) in all[at..at + n].iter_mut().zip(&self.sums.all) {
            d.merge(s);
        }
        if halves {
            for (d, s) in even[at..at + n].iter_mut().zip(&self.sums.even) {
                d.merge(s);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AovSet, Film, FilmBuffers, Rect};
    use rt_core::glam::Vec2;

    /// Mitsuba's filters written out in `f64`, independently of [`PixelFilter::eval`].
    fn profile(filter: &PixelFilter, x: f64) -> f64 {
        match filter {
            PixelFilter::Tent { radius, .. } => (1.0 - x.abs() / f64::from(*radius)).max(0.0),
            PixelFilter::Gaussian { stddev, .. } => {
                let s = f64::from(*stddev);
                let g = |x: f64| (-x * x / (2.0 * s * s)).exp();
                (g(x) - g(4.0 * s)).max(0.0)
            }
            PixelFilter::Box => f64::from(u8::from(x.abs() <= 0.5)),
        }
    }

    /// Samples spread over a `w × h` image (edges and corners included): pixel, index,
    /// position in the pixel, radiance.
    fn samples(w: u32, h: u32) -> Vec<((u32, u32), u32, Vec2, Rgb)> {
        let mut out = Vec::new();
        let mut state = 0x9e37_79b9u32;
        let mut next = || {
            state = rt_core::sampler::hash_u32(state);
            (state >> 8) as f32 / (1 << 24) as f32
        };
        for y in 0..h {
            for x in 0..w {
                for i in 0..3 {
                    let pos = Vec2::new(x as f32 + next(), y as f32 + next());
                    let l = Rgb::new(next() * 4.0, next(), 0.25);
                    out.push(((x, y), i, pos, l));
                }
            }
        }
        out
    }

    /// A film of `w × h` splatting `samples` through `filter` in bands of `rows` rows, the
    /// bands taken in reverse order (the order must not matter).
    fn splat(filter: &PixelFilter, w: u32, h: u32, rows: u32, halves: bool) -> Film {
        let s = samples(w, h);
        let buffers = if halves {
            FilmBuffers::from(AovSet::default()).with_halves()
        } else {
            FilmBuffers::from(AovSet::default())
        };
        let mut film = Film::new(w, h, buffers);
        for mut stripe in film.stripes_mut(rows).into_iter().rev() {
            let band = stripe.y0..stripe.y0 + stripe.rows();
            for &(xy, i, pos, l) in s.iter().filter(|s| band.contains(&s.0 .1)) {
                assert!(stripe.add_filtered(filter, pos, xy, i, l));
            }
        }
        film
    }

    /// Every pixel's filtered value against the weighted mean computed directly from the
    /// samples and the filter's formula, over the whole image (no notion of bands, margins or
    /// taps): Mitsuba's pixel centres at `i + ½`, weights the product of the axes', each pixel
    /// its weighted sum over its sum of weights. Also the even samples' half.
    #[test]
    fn weights_are_the_filters_at_the_pixel_centres() {
        let (w, h) = (9, 7);
        for filter in [
            PixelFilter::gaussian(0.5).splatted(),
            PixelFilter::tent(1.0).splatted(),
            PixelFilter::tent(1.7).splatted(),
        ] {
            let s = samples(w, h);
            for rows in [1, 2, 3, h] {
                let film = splat(&filter, w, h, rows, true);
                let image = film.mean_image();
                let even = film.half_image(0).unwrap();
                for py in 0..h {
                    for px in 0..w {
                        let (mut num, mut den) = ([0.0f64; 3], 0.0f64);
                        let (mut enum_, mut eden) = ([0.0f64; 3], 0.0f64);
                        for &(_, i, pos, l) in &s {
                            let wx = profile(&filter, f64::from(px) + 0.5 - f64::from(pos.x));
                            let wy = profile(&filter, f64::from(py) + 0.5 - f64::from(pos.y));
                            let wt = wx * wy;
                            for c in 0..3 {
                                num[c] += wt * f64::from(l[c]);
                                if i % 2 == 0 {
                                    enum_[c] += wt * f64::from(l[c]);
                                }
                            }
                            den += wt;
                            if i % 2 == 0 {
                                eden += wt;
                            }
                        }
                        let k = (py * w + px) as usize;
                        for c in 0..3 {
                            for (got, want) in
                                [(image[k][c], num[c] / den), (even[k][c], enum_[c] / eden)]
                            {
                                let got = f64::from(got);
                                assert!(
                                    (got - want).abs() <= 1e-5 * want.abs() + 1e-6,
                                    "{filter} rows {rows}: pixel ({px}, {py}) channel {c}: \
                                     {got} vs {want}"
                                );
                            }
                        }
                    }
                }
                assert_eq!(film.total_samples(), u64::from(w * h * 3));
                assert_eq!(film.pixel(4, 3).count(), 3);
                assert!(film.variance_image().is_none() && film.has_filtered());
            }
        }
    }

    /// The bits do not depend on the bands, and the sums of two sample ranges, carried as bytes
    /// ([`Film::encode_sums`]), add up to the film of both.
    #[test]
    fn bands_and_parts_give_the_same_bits() {
        let (w, h) = (11, 8);
        let filter = PixelFilter::gaussian(0.5).splatted();
        let bits = |f: &Film| {
            let mut v: Vec<u32> = f
                .mean_image()
                .iter()
                .flat_map(|p| p.to_array().map(f32::to_bits))
                .collect();
            v.extend(
                f.half_image(1)
                    .unwrap()
                    .iter()
                    .flat_map(|p| p.to_array().map(f32::to_bits)),
            );
            v
        };
        let whole = splat(&filter, w, h, h, true);
        for rows in [1, 2, 5] {
            assert_eq!(
                bits(&splat(&filter, w, h, rows, true)),
                bits(&whole),
                "rows {rows}"
            );
        }
        // Two parts: the even-numbered pixels' samples and the others, in bands of 2 rows.
        let s = samples(w, h);
        let buffers = FilmBuffers::from(AovSet::default()).with_halves();
        let part = |odd: bool| {
            let mut film = Film::new(w, h, buffers);
            for mut stripe in film.stripes_mut(2) {
                let band = stripe.y0..stripe.y0 + stripe.rows();
                for &(xy, i, pos, l) in &s {
                    if band.contains(&xy.1) && ((xy.0 + xy.1) % 2 == 1) == odd {
                        stripe.add_filtered(&filter, pos, xy, i, l);
                    }
                }
            }
            film.encode_sums(Rect::full(w, h))
        };
        let mut merged = Film::new(w, h, buffers);
        merged
            .add_encoded(Rect::full(w, h), &part(false), true)
            .unwrap();
        merged
            .add_encoded(Rect::full(w, h), &part(true), true)
            .unwrap();
        assert_eq!(bits(&merged), bits(&whole));
        assert_eq!(
            merged.encode_sums(Rect::full(w, h)),
            whole.encode_sums(Rect::full(w, h))
        );
        // A film without filtered sums reads them from the bytes and keeps the flag's length
        // check: a truncated part is refused.
        let bytes = whole.encode_sums(Rect::full(w, h));
        let mut short = Film::new(w, h, buffers);
        assert!(short
            .add_encoded(Rect::full(w, h), &bytes[..bytes.len() - 1], true)
            .is_err());
    }
}
