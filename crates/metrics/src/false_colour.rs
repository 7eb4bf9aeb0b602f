//! False-colour error images: where in the picture the error is.
//!
//! Each pixel shows its relative squared error, the per-pixel term of relMSE averaged over the
//! three channels, `e = mean_c (a − b)² / (b² + epsilon)` with `b` the reference, on a
//! logarithmic scale: `t = (log10 e − log10 min) / (log10 max − log10 min)`, clamped to [0, 1],
//! then mapped through viridis (dark blue at `min` and below, including zero error; yellow at
//! `max` and above). The scale is fixed rather than fitted to each image so that error images
//! of different renderings can be compared side by side.

use crate::error::{positive, MetricsError, Result};
use crate::error_metrics::{pixel_errors, DEFAULT_EPSILON};
use crate::image::{validate_pair, RgbImage};
use rayon::prelude::*;
use rt_core::color::srgb_to_linear;
use rt_core::Rgb;

/// How error values become colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FalseColourOptions {
    /// relMSE epsilon of the per-pixel error (default [`DEFAULT_EPSILON`]).
    pub epsilon: f64,
    /// Error shown as the bottom of the colour map (default 1e-4).
    pub min: f64,
    /// Error shown as the top of the colour map (default 10).
    pub max: f64,
}

impl Default for FalseColourOptions {
    fn default() -> Self {
        Self {
            epsilon: DEFAULT_EPSILON,
            min: 1e-4,
            max: 10.0,
        }
    }
}

/// Viridis (van der Walt and Smith, matplotlib's default colour map; CC0): 17 of its 256 sRGB
/// entries, at indices `round(k·255/16)`. Linear interpolation between them stays within a
/// few 8-bit steps of the full table, which is all an error picture needs.
const VIRIDIS: [[f32; 3]; 17] = [
    [0.267004, 0.004874, 0.329415],
    [0.282327, 0.094955, 0.417331],
    [0.278826, 0.175490, 0.483397],
    [0.258965, 0.251537, 0.524736],
    [0.229739, 0.322361, 0.545706],
    [0.199430, 0.387607, 0.554642],
    [0.172719, 0.448791, 0.557885],
    [0.149039, 0.508051, 0.557250],
    [0.127568, 0.566949, 0.550556],
    [0.120081, 0.622161, 0.534946],
    [0.153894, 0.680203, 0.504172],
    [0.239374, 0.735588, 0.455688],
    [0.360741, 0.785964, 0.387814],
    [0.506271, 0.828786, 0.300362],
    [0.668054, 0.861999, 0.196293],
    [0.835270, 0.886029, 0.102646],
    [0.993248, 0.906157, 0.143936],
];

/// Viridis at `t` in [0, 1] (clamped), as *linear* RGB so that it can go wherever rendered
/// pixels go: an EXR holds it as is, and the sRGB encoding of a PNG gives back the map's colours.
pub fn viridis(t: f64) -> Rgb {
    let s = t.clamp(0.0, 1.0) as f32 * (VIRIDIS.len() - 1) as f32;
    let i = (s as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f32;
    let srgb = Rgb::from_array(VIRIDIS[i]).lerp(Rgb::from_array(VIRIDIS[i + 1]), f);
    srgb.to_array().map(srgb_to_linear).into()
}

/// The false-colour image of the test image's per-pixel relative squared error (see the module
/// documentation), the same size as the inputs.
pub fn error_image(
    test: &RgbImage,
    reference: &RgbImage,
    opts: &FalseColourOptions,
) -> Result<RgbImage> {
    let epsilon = positive("epsilon", opts.epsilon)?;
    let lo = positive("min", opts.min)?.log10();
    let hi = positive("max", opts.max)?.log10();
    if hi <= lo {
        return Err(MetricsError::InvalidOption {
            name: "max",
            requirement: "greater than min",
            value: opts.max,
        });
    }
    validate_pair(test, reference)?;
    let pixels = test
        .pixels()
        .par_iter()
        .zip(reference.pixels())
        .map(|(&a, &b)| {
            let e = pixel_errors(a, b, epsilon).1 / 3.0;
            // log10(0) = -inf clamps to the bottom of the map.
            viridis((e.log10() - lo) / (hi - lo))
        })
        .collect();
    Ok(RgbImage::new(test.width(), test.height(), pixels)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::color::linear_to_srgb;

    fn srgb(c: Rgb) -> [f32; 3] {
        c.to_array().map(linear_to_srgb)
    }

    #[test]
    fn colour_map_ends_and_middle() {
        let close = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
        assert!(close(srgb(viridis(0.0)), VIRIDIS[0]));
        assert!(close(srgb(viridis(-3.0)), VIRIDIS[0]));
        assert!(close(srgb(viridis(f64::NEG_INFINITY)), VIRIDIS[0]));
        assert!(close(srgb(viridis(1.0)), VIRIDIS[16]));
        assert!(close(srgb(viridis(7.0)), VIRIDIS[16]));
        assert!(close(srgb(viridis(0.5)), VIRIDIS[8]));
    }

    #[test]
    fn colour_map_lightness_increases() {
        let mut last = -1.0;
        for i in 0..=100 {
            let y = rt_core::color::luminance(viridis(i as f64 / 100.0));
            assert!(y > last, "{i}");
            last = y;
        }
    }

    #[test]
    fn errors_map_on_a_log_scale() {
        // Reference 1 everywhere; per-pixel errors 0, 1e-4 (the bottom), 10^-1.5 (the middle of
        // the default range) and 10 (the top).
        let reference = RgbImage::from_fn(4, 1, |_, _| Rgb::ONE);
        let d = |e: f64| (e * 1.01).sqrt() as f32;
        let test = RgbImage::new(
            4,
            1,
            vec![
                Rgb::ONE,
                Rgb::splat(1.0 + d(1e-4)),
                Rgb::splat(1.0 + d(10f64.powf(-1.5))),
                Rgb::splat(1.0 + d(10.0)),
            ],
        )
        .unwrap();
        let img = error_image(&test, &reference, &FalseColourOptions::default()).unwrap();
        assert_eq!((img.width(), img.height()), (4, 1));
        let px = img.pixels();
        let near = |a: Rgb, b: Rgb| (a - b).abs().max_element() < 2e-3;
        assert_eq!(px[0], viridis(0.0));
        assert!(near(px[1], viridis(0.0)));
        assert!(near(px[2], viridis(0.5)));
        assert!(near(px[3], viridis(1.0)));
    }

    #[test]
    fn options_and_inputs_are_checked() {
        let a = RgbImage::from_fn(2, 2, |_, _| Rgb::ONE);
        let bad = FalseColourOptions {
            min: 1.0,
            max: 1.0,
            ..Default::default()
        };
        assert!(error_image(&a, &a, &bad).is_err());
        let bad = FalseColourOptions {
            epsilon: 0.0,
            ..Default::default()
        };
        assert!(error_image(&a, &a, &bad).is_err());
        let b = RgbImage::from_fn(1, 2, |_, _| Rgb::ONE);
        assert!(matches!(
            error_image(&a, &b, &FalseColourOptions::default()),
            Err(MetricsError::SizeMismatch { .. })
        ));
    }
}
