//! On-demand spectral rendering (Dammertz 2011, §6.6): paths are RGB until a dispersive event;
//! there one wavelength λ is sampled, the path's throughput is multiplied by the RGB weight of
//! λ, and λ stays fixed until the path ends.
//!
//! The thesis leaves the RGB→λ rule open. Ours:
//!
//! - **Colour of a wavelength.** The CIE 1931 2° matching functions, by the multi-lobe Gaussian
//!   fit of Wyman, Sloan and Shirley ("Simple Analytic Approximations to the CIE XYZ Color
//!   Matching Functions", JCGT 2(2), 2013, Table 1), turned into linear Rec. 709 RGB by the
//!   sRGB (D65) XYZ→RGB matrix (IEC 61966-2-1). The negative lobes (spectral colours lie
//!   outside the Rec. 709 gamut) are clamped to zero. Each channel is normalised so that its
//!   integral over [380, 780] nm is one: the **equal-energy spectrum is RGB (1, 1, 1)**, the
//!   white of this renderer. Clamping is the one deviation from colorimetry: a spectral colour
//!   comes out as the nearest in-gamut one, never with a negative channel.
//! - **Tabulation.** The normalised RGB `c(λ)` is tabulated at the centres of [`BINS`] bins of
//!   1 nm and held constant within a bin (so it is exactly normalised on the table, not only
//!   up to quadrature error).
//! - **Sampling.** λ is drawn from the fixed pdf `p(λ) = (c_r + c_g + c_b) / 3` (a bin by its
//!   CDF, then uniformly within it) and the throughput is multiplied by
//!   `w(λ) = c(λ) / p(λ) = 3 c(λ) / (c_r + c_g + c_b)`. The weight's channels always sum to 3,
//!   so no wavelength carries a large weight, and `E[w] = ∫ c(λ) dλ = (1, 1, 1)`: white stays
//!   white in expectation. Sampling in proportion to the path's throughput (the digest's
//!   suggestion) would lower the variance of strongly coloured paths; the fixed pdf keeps λ a
//!   function of one random number alone.
//!
//! Indices of refraction: Cauchy `n = A + B/λ² + C/λ⁴` and the three-term Sellmeier (Schott)
//! form `n² = 1 + Σ Bᵢ λ² / (λ² − Cᵢ)`, λ in µm, with presets from the Schott catalogue.

use crate::Rgb;
use std::sync::OnceLock;

/// Shortest wavelength sampled, nm.
pub const LAMBDA_MIN: f32 = 380.0;
/// Longest wavelength sampled, nm.
pub const LAMBDA_MAX: f32 = 780.0;
/// Number of 1 nm bins of the colour table.
pub const BINS: usize = 400;
/// The d line of helium, where glass catalogues give `n_d`, nm.
pub const LAMBDA_D: f32 = 587.56;

/// One lobe of the Wyman–Sloan–Shirley fit: `α · exp(−½ ((λ − μ) / σ)²)` with `σ = σ₁` below
/// the mean and `σ₂` above.
fn lobe(lambda: f64, alpha: f64, mu: f64, sigma1: f64, sigma2: f64) -> f64 {
    let s = if lambda < mu { sigma1 } else { sigma2 };
    let t = (lambda - mu) / s;
    alpha * (-0.5 * t * t).exp()
}

/// CIE 1931 2° `(x̄, ȳ, z̄)` at `lambda` nm (Wyman, Sloan and Shirley 2013, the multi-lobe fit).
pub fn cie_xyz(lambda: f64) -> [f64; 3] {
    let x = lobe(lambda, 1.056, 599.8, 37.9, 31.0) + lobe(lambda, 0.362, 442.0, 16.0, 26.7)
        - lobe(lambda, 0.065, 501.1, 20.4, 26.2);
    let y = lobe(lambda, 0.821, 568.8, 46.9, 40.5) + lobe(lambda, 0.286, 530.9, 16.3, 31.1);
    let z = lobe(lambda, 1.217, 437.0, 11.8, 36.0) + lobe(lambda, 0.681, 459.0, 26.0, 13.8);
    [x, y, z]
}

/// XYZ → linear Rec. 709 RGB (D65), IEC 61966-2-1.
const XYZ_TO_RGB: [[f64; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266_0, 1.876_010_8, 0.041_556_0],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

struct Table {
    /// `w = c / p` per bin (channels sum to 3; zero where `p` is zero).
    weight: [[f32; 3]; BINS],
    /// Probability of each bin.
    prob: [f32; BINS],
    /// `cdf[k]` = probability of the bins before `k`; `cdf[BINS] = 1`.
    cdf: [f32; BINS + 1],
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut rgb = [[0.0f64; 3]; BINS];
        let mut sum = [0.0f64; 3];
        for (k, c) in rgb.iter_mut().enumerate() {
            let xyz = cie_xyz(f64::from(LAMBDA_MIN) + k as f64 + 0.5);
            for (ch, row) in XYZ_TO_RGB.iter().enumerate() {
                let v = row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2];
                c[ch] = v.max(0.0);
                sum[ch] += c[ch];
            }
        }
        let mut t = Table {
            weight: [[0.0; 3]; BINS],
            prob: [0.0; BINS],
            cdf: [0.0; BINS + 1],
        };
        let mut acc = 0.0f64;
        for (k, v) in rgb.iter().enumerate() {
            let c = [v[0] / sum[0], v[1] / sum[1], v[2] / sum[2]];
            let p = (c[0] + c[1] + c[2]) / 3.0;
            t.prob[k] = p as f32;
            if p > 0.0 {
                t.weight[k] = [(c[0] / p) as f32, (c[1] / p) as f32, (c[2] / p) as f32];
            }
            t.cdf[k] = acc as f32;
            acc += p;
        }
        t.cdf[BINS] = 1.0;
        t
    })
}

/// A sampled wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WavelengthSample {
    /// λ in nm, in [[`LAMBDA_MIN`], [`LAMBDA_MAX`]).
    pub lambda: f32,
    /// `c(λ) / p(λ)`: what the path throughput is multiplied by.
    pub weight: Rgb,
    /// `p(λ)` per nm.
    pub pdf: f32,
}

/// Samples λ from the fixed pdf `p(λ)` with one uniform number `u ∈ [0, 1)` (module docs).
#[inline]
pub fn sample_wavelength(u: f32) -> WavelengthSample {
    let t = table();
    // The bin whose CDF interval holds u; bins of zero probability have empty intervals and are
    // never chosen.
    let k = (t.cdf[1..].partition_point(|&c| c <= u)).min(BINS - 1);
    let width = t.cdf[k + 1] - t.cdf[k];
    let frac = if width > 0.0 {
        ((u - t.cdf[k]) / width).clamp(0.0, 0.999_999_94)
    } else {
        0.5
    };
    let w = t.weight[k];
    WavelengthSample {
        lambda: LAMBDA_MIN + k as f32 + frac,
        weight: Rgb::new(w[0], w[1], w[2]),
        pdf: t.prob[k],
    }
}

/// `c(λ)`: the normalised RGB of wavelength `lambda` nm (zero outside the sampled range).
pub fn wavelength_rgb(lambda: f32) -> Rgb {
    if !(LAMBDA_MIN..LAMBDA_MAX).contains(&lambda) {
        return Rgb::ZERO;
    }
    let t = table();
    let k = ((lambda - LAMBDA_MIN) as usize).min(BINS - 1);
    let w = t.weight[k];
    Rgb::new(w[0], w[1], w[2]) * t.prob[k]
}

/// A wavelength-dependent index of refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dispersion {
    /// Cauchy's `n = a + b/λ² + c/λ⁴`, λ in µm.
    Cauchy {
        /// Constant term.
        a: f32,
        /// µm².
        b: f32,
        /// µm⁴.
        c: f32,
    },
    /// Sellmeier's `n² = 1 + Σ bᵢ λ² / (λ² − cᵢ)`, λ in µm, `cᵢ` in µm² (Schott's form).
    Sellmeier {
        /// Oscillator strengths `B1..B3`.
        b: [f32; 3],
        /// Resonance wavelengths squared `C1..C3`, µm².
        c: [f32; 3],
    },
}

/// Named glasses: `(name, dispersion)`, with the catalogue's digits (f32 keeps about seven).
#[allow(clippy::excessive_precision)]
pub const PRESETS: [(&str, Dispersion); 3] = [
    // Schott N-BK7, borosilicate crown: n_d = 1.5168, V_d = 64.17.
    (
        "bk7",
        Dispersion::Sellmeier {
            b: [1.03961212, 0.231792344, 1.01046945],
            c: [0.00600069867, 0.0200179144, 103.560653],
        },
    ),
    // Schott N-SF11, dense flint: n_d = 1.78472, V_d = 25.68.
    (
        "sf11",
        Dispersion::Sellmeier {
            b: [1.73759695, 0.313747346, 1.89878101],
            c: [0.013188707, 0.0623068142, 155.23629],
        },
    ),
    // Fused silica (Malitson 1965, C = 0.0684043², 0.1162414², 9.896161² µm²): n_d = 1.4585.
    (
        "fused-silica",
        Dispersion::Sellmeier {
            b: [0.6961663, 0.4079426, 0.8974794],
            c: [0.004679148, 0.013512063, 97.934003],
        },
    ),
];

/// Index range accepted over the visible range: above one (a dielectric denser than vacuum, as
/// the layered model's Fresnel and `1/η²` assume) and at most that of the densest optical
/// glasses and crystals (diamond 2.42, rutile 2.9).
pub const MAX_INDEX: f32 = 4.0;

impl Dispersion {
    /// The preset called `name` (case-insensitive).
    pub fn preset(name: &str) -> Option<Self> {
        PRESETS
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|&(_, d)| d)
    }

    /// Index of refraction at `lambda` nm.
    #[inline]
    pub fn ior(&self, lambda: f32) -> f32 {
        let l = f64::from(lambda) * 1e-3;
        let l2 = l * l;
        match *self {
            Dispersion::Cauchy { a, b, c } => {
                (f64::from(a) + f64::from(b) / l2 + f64::from(c) / (l2 * l2)) as f32
            }
            Dispersion::Sellmeier { b, c } => {
                let mut n2 = 1.0;
                for i in 0..3 {
                    n2 += f64::from(b[i]) * l2 / (l2 - f64::from(c[i]));
                }
                n2.sqrt() as f32
            }
        }
    }

    /// Checks the coefficients: finite; Sellmeier's `Bᵢ, Cᵢ ≥ 0` with no resonance `√Cᵢ` inside
    /// [380, 780] nm; and an index in (1, [`MAX_INDEX`]] at every nm of the sampled range.
    pub fn validate(&self) -> Result<(), String> {
        match *self {
            Dispersion::Cauchy { a, b, c } => {
                if ![a, b, c].iter().all(|v| v.is_finite()) {
                    return Err(format!(
                        "Cauchy coefficients must be finite, got [{a}, {b}, {c}]"
                    ));
                }
            }
            Dispersion::Sellmeier { b, c } => {
                if !b.iter().chain(&c).all(|v| v.is_finite() && *v >= 0.0) {
                    return Err(format!(
                        "Sellmeier coefficients must be finite and non-negative, got b = {b:?}, c = {c:?}"
                    ));
                }
                let (lo, hi) = (LAMBDA_MIN * 1e-3, LAMBDA_MAX * 1e-3);
                if let Some(ci) = c.iter().find(|&&ci| (lo * lo..=hi * hi).contains(&ci)) {
                    return Err(format!(
                        "Sellmeier c = {ci} µm² puts a resonance at {:.0} nm, inside the visible range \
                         [380, 780] nm (c is in µm², not nm²)",
                        ci.sqrt() * 1e3
                    ));
                }
            }
        }
        for k in 0..=(LAMBDA_MAX - LAMBDA_MIN) as u32 {
            let lambda = LAMBDA_MIN + k as f32;
            let n = self.ior(lambda);
            if !(n.is_finite() && n > 1.0 && n <= MAX_INDEX) {
                return Err(format!(
                    "index of refraction must be in (1, {MAX_INDEX}] over [380, 780] nm, but it is {n} at {lambda} nm"
                ));
            }
        }
        Ok(())
    }
}

impl crate::content_hash::ContentHash for Dispersion {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        match self {
            Dispersion::Cauchy { a, b, c } => {
                0u32.content_hash(out);
                a.content_hash(out);
                b.content_hash(out);
                c.content_hash(out);
            }
            Dispersion::Sellmeier { b, c } => {
                1u32.content_hash(out);
                for v in b.iter().chain(c) {
                    v.content_hash(out);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A SplitMix64 stream: independent of the sampler under test.
    fn uniforms(seed: u64, n: usize) -> impl Iterator<Item = f32> {
        let mut s = seed;
        (0..n).map(move |_| {
            s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            (z >> 40) as f32 / (1u64 << 24) as f32
        })
    }

    /// White stays white: the mean weight over many λ is (1, 1, 1) within 4 standard errors
    /// (the standard error from the weights' own sample variance).
    #[test]
    fn mean_weight_is_white() {
        let n = 200_000;
        let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
        for u in uniforms(7, n) {
            let s = sample_wavelength(u);
            assert!((LAMBDA_MIN..LAMBDA_MAX).contains(&s.lambda));
            let w = s.weight.to_array();
            assert!(
                (w[0] + w[1] + w[2] - 3.0).abs() < 1e-4,
                "channels sum to 3: {w:?}"
            );
            for ch in 0..3 {
                sum[ch] += f64::from(w[ch]);
                sum2[ch] += f64::from(w[ch]).powi(2);
            }
        }
        for ch in 0..3 {
            let mean = sum[ch] / n as f64;
            let var = sum2[ch] / n as f64 - mean * mean;
            let se = (var / n as f64).sqrt();
            assert!(
                (mean - 1.0).abs() < 4.0 * se,
                "channel {ch}: mean weight {mean} (standard error {se})"
            );
        }
    }

    /// The table's own expectation is exactly white, and the pdf is a pdf.
    #[test]
    fn table_is_normalised() {
        let t = table();
        let mut e = [0.0f64; 3];
        for k in 0..BINS {
            for (ch, e) in e.iter_mut().enumerate() {
                *e += f64::from(t.prob[k]) * f64::from(t.weight[k][ch]);
            }
        }
        for (ch, e) in e.iter().enumerate() {
            assert!((e - 1.0).abs() < 1e-5, "channel {ch}: {e}");
        }
        assert!((t.cdf[BINS - 1] + t.prob[BINS - 1] - 1.0).abs() < 1e-5);
        // Long wavelengths are red, short ones blue, 530 nm green.
        let (r, g, b) = (
            wavelength_rgb(650.0),
            wavelength_rgb(530.0),
            wavelength_rgb(450.0),
        );
        assert!(r.x > r.y && r.x > r.z, "{r:?}");
        assert!(g.y > g.x && g.y > g.z, "{g:?}");
        assert!(b.z > b.x && b.z > b.y, "{b:?}");
    }

    #[test]
    fn sampled_wavelengths_follow_the_pdf() {
        // Fraction of samples in [380, 480) nm against the table's probability of those bins.
        let n = 100_000;
        let hits = uniforms(11, n)
            .filter(|&u| sample_wavelength(u).lambda < 480.0)
            .count() as f64;
        let p: f64 = table().prob[..100].iter().map(|&p| f64::from(p)).sum();
        let se = (p * (1.0 - p) / n as f64).sqrt();
        assert!(
            (hits / n as f64 - p).abs() < 4.0 * se,
            "{} vs {p}",
            hits / n as f64
        );
    }

    #[test]
    fn indices_match_the_catalogue() {
        let bk7 = Dispersion::preset("BK7").unwrap();
        assert!((bk7.ior(587.6) - 1.5168).abs() < 1e-4, "{}", bk7.ior(587.6));
        // Schott N-BK7 at the F (486.1 nm) and C (656.3 nm) lines: 1.52238, 1.51432.
        assert!((bk7.ior(486.13) - 1.52238).abs() < 1e-4);
        assert!((bk7.ior(656.27) - 1.51432).abs() < 1e-4);
        let sf11 = Dispersion::preset("sf11").unwrap();
        assert!(
            (sf11.ior(LAMBDA_D) - 1.78472).abs() < 1e-4,
            "{}",
            sf11.ior(LAMBDA_D)
        );
        let silica = Dispersion::preset("fused-silica").unwrap();
        assert!((silica.ior(LAMBDA_D) - 1.4585).abs() < 1e-4);
        // Cauchy's fit of BK7 (A = 1.5046, B = 0.00420 µm²) at the d line.
        let cauchy = Dispersion::Cauchy {
            a: 1.5046,
            b: 0.0042,
            c: 0.0,
        };
        assert!((cauchy.ior(587.6) - 1.5168).abs() < 1e-4);
        // Normal dispersion: blue bends more.
        assert!(bk7.ior(400.0) > bk7.ior(700.0));
        for (_, d) in PRESETS {
            assert_eq!(d.validate(), Ok(()));
        }
    }

    #[test]
    fn bad_coefficients_are_rejected() {
        let s = |b: [f32; 3], c: [f32; 3]| Dispersion::Sellmeier { b, c }.validate();
        let e = s([1.0, 0.2, 1.0], [0.006, 0.25, 100.0]).unwrap_err();
        assert!(e.contains("resonance at 500 nm"), "{e}");
        // C in nm² instead of µm²: the index drops below one.
        let e = s([1.04, 0.23, 1.01], [6000.0, 20000.0, 1.0e8]).unwrap_err();
        assert!(e.contains("must be in (1, 4]"), "{e}");
        assert!(s([-1.0, 0.0, 0.0], [0.0; 3])
            .unwrap_err()
            .contains("non-negative"));
        let c = |a: f32, b: f32| Dispersion::Cauchy { a, b, c: 0.0 }.validate();
        assert!(c(0.9, 0.001).unwrap_err().contains("(1, 4]"));
        assert!(c(f32::NAN, 0.0).unwrap_err().contains("finite"));
        assert!(c(5.0, 0.0).is_err());
        assert_eq!(c(1.5, 0.004), Ok(()));
    }
}
