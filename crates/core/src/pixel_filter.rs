//! Pixel reconstruction filters, applied in one of two ways.
//!
//! - Filter importance sampling (the default): each camera sample's position in its pixel is
//!   drawn from the filter's profile instead of uniformly, and the sample counts with weight 1
//!   in that pixel alone (Ernst et al., "Filter importance sampling", RT 2006). Pixel noise
//!   stays independent (denoisers, per-pixel variances and every film buffer work as with the
//!   box).
//! - Splatting (`:splat`, what Mitsuba 3 does): the position is uniform in the pixel, and the
//!   film adds the sample to every pixel whose centre lies within the filter's radius, weighted
//!   by [`PixelFilter::eval`], each pixel divided by its sum of weights (`rt_film`'s filtered
//!   sums, after Mitsuba 3's `ImageBlock::put`). Each sample reaches several pixels, so a
//!   pixel averages more samples: for noise independent between samples its variance is the
//!   box's times `∫w²/(∫w)²` per axis (0.318 in two dimensions for the Gaussian of σ = ½),
//!   where filter importance sampling keeps the box's. The price: neighbouring pixels' noise
//!   is correlated.
//!
//! Both converge to an image filtered by the same profile, but not to the same image: the
//! importance-sampled pixel is `∫f(x)L(x)dx / ∫f` over its footprint, the splatted one a ratio
//! of two such sums, which equals it in expectation only where the radiance is constant over
//! the footprint (and at image borders, where Mitsuba's pixels lose the weights outside the
//! image, differs even then only in how the border is treated).
//!
//! Filters are separable, as Mitsuba's: `box` (radius ½, the plain jitter), `tent:radius=R`
//! (Mitsuba's default R = 1) and `gaussian:stddev=S` (Mitsuba's: `exp(−x²/2S²)` less its value
//! at the cut-off 4S, default S = 0.5). Deviation: the Gaussian's inverse distribution is a
//! table of [`TABLE_SIZE`] points, linear between them (the density is exact to about 1e-5
//! of its peak).

use glam::Vec2;

use crate::options::{Options, OptionsError};

/// Points of the tabulated inverse distribution of the Gaussian.
pub const TABLE_SIZE: usize = 2048;

/// A separable pixel filter.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum PixelFilter {
    /// Uniform over the pixel (radius ½): the renderer's default.
    #[default]
    Box,
    /// `max(0, 1 − |x|/radius)` per axis.
    Tent {
        /// Support radius in pixels.
        radius: f32,
        /// Applied by splatting rather than by importance sampling (see the module doc).
        splat: bool,
    },
    /// Mitsuba's truncated Gaussian per axis.
    Gaussian {
        /// Standard deviation in pixels; the support is 4 of them.
        stddev: f32,
        /// The inverse distribution: offsets at `TABLE_SIZE` evenly spaced probabilities.
        inverse: Vec<f32>,
        /// Applied by splatting rather than by importance sampling (see the module doc).
        splat: bool,
    },
}

impl PixelFilter {
    /// Mitsuba's tent (radius 1).
    pub fn tent(radius: f32) -> Self {
        Self::Tent {
            radius,
            splat: false,
        }
    }

    /// Mitsuba's Gaussian with standard deviation `stddev` pixels.
    pub fn gaussian(stddev: f32) -> Self {
        Self::Gaussian {
            stddev,
            inverse: gaussian_inverse(stddev as f64),
            splat: false,
        }
    }

    /// The same filter applied by splatting (the box has nothing to splat: it stays the box).
    pub fn splatted(mut self) -> Self {
        match &mut self {
            Self::Box => {}
            Self::Tent { splat, .. } | Self::Gaussian { splat, .. } => *splat = true,
        }
        self
    }

    /// True if the film splats samples with this filter's weights (see the module doc).
    #[inline]
    pub fn splats(&self) -> bool {
        match self {
            Self::Box => false,
            Self::Tent { splat, .. } | Self::Gaussian { splat, .. } => *splat,
        }
    }

    /// Parses `box`, `tent[:radius=R][:splat]` or `gaussian[:stddev=S][:splat]` (the option
    /// grammar).
    pub fn parse(text: &str) -> Result<Self, OptionsError> {
        let mut o = Options::parse(text)?;
        let positive = |v: &f32| v.is_finite() && *v > 0.0 && *v <= 16.0;
        let filter = match o.kind() {
            "box" => Self::Box,
            "tent" => Self::tent(
                o.value_in("radius", "a number of pixels in (0, 16]", positive)?
                    .unwrap_or(1.0),
            ),
            "gaussian" => Self::gaussian(
                o.value_in("stddev", "a number of pixels in (0, 4]", |v: &f32| {
                    v.is_finite() && *v > 0.0 && *v <= 4.0
                })?
                .unwrap_or(0.5),
            ),
            _ => {
                let kind = o.kind().to_string();
                return Err(o.bad("filter", &kind, "one of box, tent, gaussian"));
            }
        };
        let filter = if filter != Self::Box && o.flag("splat")? {
            filter.splatted()
        } else {
            filter
        };
        o.finish()?;
        Ok(filter)
    }

    /// The film position of a sample of pixel `(x, y)` drawn with the uniform `jitter` in
    /// [0, 1)²; the box filter and every splatted filter give exactly `(x, y) + jitter`.
    #[inline]
    pub fn film_position(&self, x: u32, y: u32, jitter: Vec2) -> Vec2 {
        let corner = Vec2::new(x as f32, y as f32);
        if self.splats() {
            return corner + jitter;
        }
        match self {
            Self::Box => corner + jitter,
            Self::Tent { radius, .. } => {
                corner + Vec2::splat(0.5) + Vec2::new(tent(jitter.x), tent(jitter.y)) * *radius
            }
            Self::Gaussian { inverse, .. } => {
                corner
                    + Vec2::splat(0.5)
                    + Vec2::new(lookup(inverse, jitter.x), lookup(inverse, jitter.y))
            }
        }
    }

    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        match self {
            Self::Box => 0.5,
            Self::Tent { radius, .. } => *radius,
            Self::Gaussian { stddev, .. } => 4.0 * stddev,
        }
    }

    /// The filter's weight at offset `x` pixels from a pixel's centre along one axis, as
    /// Mitsuba 3 evaluates it in single precision: the tent `max(0, 1 − |x · (1/radius)|)`,
    /// the Gaussian `max(0, exp(α x²) − exp(α r²))` with `α = −1/(2σ²)` and `r = 4σ`, the box
    /// 1 inside `|x| ≤ ½` (and 0 outside).
    #[inline]
    pub fn eval(&self, x: f32) -> f32 {
        match self {
            Self::Box => f32::from(u8::from(x.abs() <= 0.5)),
            Self::Tent { radius, .. } => (1.0 - (x * (1.0 / radius)).abs()).max(0.0),
            Self::Gaussian { stddev, .. } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let r = 4.0 * stddev;
                ((alpha * x * x).exp() - (alpha * r * r).exp()).max(0.0)
            }
        }
    }
}

impl std::fmt::Display for PixelFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Box => write!(f, "box")?,
            Self::Tent { radius, .. } => write!(f, "tent:radius={radius}")?,
            Self::Gaussian { stddev, .. } => write!(f, "gaussian:stddev={stddev}")?,
        }
        if self.splats() {
            write!(f, ":splat")?;
        }
        Ok(())
    }
}

/// Inverse distribution of the unit tent `1 − |x|` on [−1, 1].
#[inline]
fn tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).max(0.0).sqrt()
    }
}

#[inline]
fn lookup(table: &[f32], u: f32) -> f32 {
    let t = u.clamp(0.0, 1.0) * (table.len() - 1) as f32;
    let i = (t as usize).min(table.len() - 2);
    let f = t - i as f32;
    table[i] * (1.0 - f) + table[i + 1] * f
}

/// Offsets at probabilities `k/(TABLE_SIZE−1)` of Mitsuba's Gaussian, by inverting its
/// distribution function integrated on a fine grid (Simpson per cell) with bisection-free
/// linear search; symmetric by construction, so the middle entry is exactly 0.
fn gaussian_inverse(stddev: f64) -> Vec<f32> {
    const CELLS: usize = 1 << 16;
    let r = 4.0 * stddev;
    let alpha = -1.0 / (2.0 * stddev * stddev);
    let bias = (alpha * r * r).exp();
    let f = |x: f64| ((alpha * x * x).exp() - bias).max(0.0);
    // Distribution function on [0, r] (the right half; the left is its mirror).
    let h = r / CELLS as f64;
    let mut cdf = Vec::with_capacity(CELLS + 1);
    cdf.push(0.0f64);
    for i in 0..CELLS {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        let area = h / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b));
        cdf.push(cdf[i] + area);
    }
    let half = cdf[CELLS];
    let mut table = vec![0.0f32; TABLE_SIZE];
    let mid = (TABLE_SIZE - 1) as f64 / 2.0;
    let mut j = 0;
    for k in (TABLE_SIZE / 2)..TABLE_SIZE {
        // Probability above the middle, as a fraction of the half's mass.
        let q = ((k as f64 - mid) / mid).min(1.0) * half;
        while j < CELLS && cdf[j + 1] < q {
            j += 1;
        }
        let (c0, c1) = (cdf[j], cdf[j + 1]);
        let frac = if c1 > c0 { (q - c0) / (c1 - c0) } else { 0.0 };
        let x = ((j as f64 + frac) * h).min(r) as f32;
        table[k] = x;
        table[TABLE_SIZE - 1 - k] = -x;
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Histogram of offsets drawn at evenly spaced probabilities against the filter's
    /// profile: the sampled density must be the normalised profile.
    fn check_density(filter: &PixelFilter, profile: impl Fn(f64) -> f64) {
        let n = 400_000;
        let bins = 40;
        let r = filter.radius() as f64;
        let mut hist = vec![0.0f64; bins];
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let x = (filter.film_position(0, 0, Vec2::new(u, 0.5)).x - 0.5) as f64;
            assert!(x.abs() <= r + 1e-5, "{x} outside the radius {r}");
            let b = (((x + r) / (2.0 * r)) * bins as f64)
                .floor()
                .clamp(0.0, bins as f64 - 1.0);
            hist[b as usize] += 1.0;
        }
        // Expected mass per bin by fine quadrature of the profile.
        let total: f64 = (0..100_000)
            .map(|i| profile(-r + (i as f64 + 0.5) * 2.0 * r / 100_000.0))
            .sum();
        for (b, &count) in hist.iter().enumerate() {
            let (a, c) = (
                -r + b as f64 * 2.0 * r / bins as f64,
                -r + (b + 1) as f64 * 2.0 * r / bins as f64,
            );
            // Both sums are midpoint rules with the same spacing (2r/100000 = (c−a)/2500).
            let mass: f64 = (0..2500)
                .map(|i| profile(a + (i as f64 + 0.5) * (c - a) / 2500.0))
                .sum::<f64>()
                / total;
            let got = count / n as f64;
            // Deterministic (stratified) draws: the only error is the binning of the
            // evenly spaced probabilities, one draw per bin edge.
            assert!(
                (got - mass).abs() < 2e-4 + 2.0 / n as f64,
                "bin {b}: {got} vs {mass}"
            );
        }
    }

    #[test]
    fn tent_and_gaussian_sample_their_profiles() {
        check_density(&PixelFilter::tent(1.0), |x| (1.0 - x.abs()).max(0.0));
        check_density(&PixelFilter::tent(1.5), |x| (1.0 - x.abs() / 1.5).max(0.0));
        let s = 0.5f64;
        let g = |x: f64| ((-x * x / (2.0 * s * s)).exp() - (-8.0f64).exp()).max(0.0);
        check_density(&PixelFilter::gaussian(0.5), g);
    }

    #[test]
    fn a_wrong_profile_is_seen() {
        // Control: a Gaussian twice as wide must fail the density check.
        let s = 1.0f64;
        let wide = |x: f64| ((-x * x / (2.0 * s * s)).exp()).max(0.0) * f64::from(x.abs() <= 2.0);
        let caught = std::panic::catch_unwind(|| check_density(&PixelFilter::gaussian(0.5), wide));
        assert!(caught.is_err());
    }

    #[test]
    fn box_is_the_plain_jitter_and_the_centre_stays_the_centre() {
        let j = Vec2::new(0.25, 0.75);
        assert_eq!(
            PixelFilter::Box.film_position(3, 4, j),
            Vec2::new(3.25, 4.75)
        );
        for f in [PixelFilter::tent(1.0), PixelFilter::gaussian(0.5)] {
            assert_eq!(
                f.film_position(3, 4, Vec2::splat(0.5)),
                Vec2::new(3.5, 4.5),
                "{f}"
            );
        }
    }

    #[test]
    fn specs_parse_print_and_refuse() {
        for text in [
            "box",
            "tent:radius=1.5",
            "gaussian:stddev=0.25",
            "tent:radius=1:splat",
            "gaussian:stddev=0.5:splat",
        ] {
            let f = PixelFilter::parse(text).unwrap();
            assert_eq!(f.to_string(), text);
            assert_eq!(PixelFilter::parse(&f.to_string()).unwrap(), f);
        }
        assert_eq!(PixelFilter::parse("tent").unwrap(), PixelFilter::tent(1.0));
        let e = |t: &str| PixelFilter::parse(t).unwrap_err().to_string();
        assert_eq!(
            e("mitchell"),
            "mitchell: filter: `mitchell` is not one of box, tent, gaussian"
        );
        assert_eq!(
            e("gaussian:stddev=0"),
            "gaussian: stddev: `0` is not a number of pixels in (0, 4]"
        );
        assert_eq!(e("box:radius=1"), "box: unknown option `radius`");
        assert_eq!(e("box:splat"), "box: unknown option `splat`");
        let g = PixelFilter::parse("gaussian:splat").unwrap();
        assert!(g.splats() && !PixelFilter::gaussian(0.5).splats());
        assert_ne!(
            g,
            PixelFilter::gaussian(0.5),
            "the method is part of the filter"
        );
        // Splatted filters place samples uniformly in the pixel, as the box does.
        let j = Vec2::new(0.25, 0.75);
        assert_eq!(g.film_position(3, 4, j), Vec2::new(3.25, 4.75));
    }
}
