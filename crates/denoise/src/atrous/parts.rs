//! What the À-Trous filter runs on: the frame cut into the parts filtered separately (the
//! whole colour, or a lighting split), each optionally demodulated by the albedo, and how a
//! filtered part goes back into the output; plus the image-relative scales of the default
//! phis.
//!
//! The output is always `colour + Σ_parts modulate(F(I) − I)`, with `I` a part's signal and `F`
//! the filter. Expanded for the irradiance path this is
//! `albedo ⊙ F(irradiance) + (colour − albedo ⊙ irradiance)`: the emission and the residual
//! (pixel means of products differ from products of means where one pixel's samples saw
//! different albedos) pass unfiltered; for a split it is `A' + B' + (colour − A − B)`, where the
//! residual is the emission. Writing it as a correction of the colour makes zero iterations
//! return the colour bit for bit.

use super::planes::Planes;
use rt_core::{Image, Rgb};

/// Albedo components at or below this are treated as black: dividing by them would turn noise
/// into huge irradiance values, so such components pass through unfiltered.
pub(crate) const ALBEDO_EPSILON: f32 = 1e-3;

/// How a part's filtered signal returns to colour units.
#[derive(Clone, Copy)]
pub(crate) enum Modulation<'a> {
    /// The signal is in colour units.
    None,
    /// The signal is irradiance: multiply by the albedo.
    Multiply(&'a Image<Rgb>),
    /// The signal was divided by the albedo where a component exceeds [`ALBEDO_EPSILON`]; the
    /// other components pass through unfiltered.
    Divide(&'a Image<Rgb>),
}

/// One separately filtered part.
pub(crate) struct Part<'a> {
    /// The signal to filter (demodulated if the modulation says so).
    pub(crate) signal: Image<Rgb>,
    pub(crate) modulation: Modulation<'a>,
    /// À-Trous levels for this part (0 leaves it as it is).
    pub(crate) iterations: usize,
}

impl<'a> Part<'a> {
    /// The part `raw` (colour units), divided by `albedo` if given.
    pub(crate) fn new(raw: Image<Rgb>, albedo: Option<&'a Image<Rgb>>, iterations: usize) -> Self {
        match albedo {
            None => Self {
                signal: raw,
                modulation: Modulation::None,
                iterations,
            },
            Some(a) => {
                let px = raw
                    .pixels()
                    .iter()
                    .zip(a.pixels())
                    .map(|(&c, &a)| Rgb::select(a.cmpgt(Rgb::splat(ALBEDO_EPSILON)), c / a, c))
                    .collect();
                Self {
                    signal: Image::new(raw.width(), raw.height(), px).unwrap_or_default(),
                    modulation: Modulation::Divide(a),
                    iterations,
                }
            }
        }
    }

    /// Adds `modulate(filtered − signal)` to `out`.
    pub(crate) fn add_correction(&self, filtered: &Planes, out: &mut Image<Rgb>) {
        let w = filtered.width;
        for (y, row) in self.signal.pixels().chunks(w.max(1)).enumerate() {
            let f = filtered.components(y);
            for (x, &s) in row.iter().enumerate() {
                let d = Rgb::new(f[0][x], f[1][x], f[2][x]) - s;
                let i = y * w + x;
                let d = match self.modulation {
                    Modulation::None => d,
                    Modulation::Multiply(a) => a.pixels()[i] * d,
                    Modulation::Divide(a) => {
                        let a = a.pixels()[i];
                        Rgb::select(a.cmpgt(Rgb::splat(ALBEDO_EPSILON)), a * d, Rgb::ZERO)
                    }
                };
                out.pixels_mut()[i] += d;
            }
        }
    }
}

/// `q`-quantile (nearest rank) of `values` (consumed), or `None` if empty.
fn quantile(mut values: Vec<f32>, q: f64) -> Option<f32> {
    if values.is_empty() {
        return None;
    }
    let k = ((values.len() - 1) as f64 * q).round() as usize;
    let (_, v, _) = values.select_nth_unstable_by(k, f32::total_cmp);
    Some(*v)
}

/// The colour scale `c_phi = 1` stands for: the 99th percentile of the signal's squared RGB
/// length `|c|²` (the quantity Listing 6.3 compares), a robust stand-in for the thesis' maximum
/// intensity that a few fireflies cannot inflate. Falls back to the maximum, then to 1 for a
/// black signal.
pub(crate) fn colour_scale(signal: &Planes) -> f32 {
    let w = signal.width;
    let mut sq = Vec::with_capacity(w * signal.height);
    for y in 0..signal.height {
        let [r, g, b] = signal.components(y);
        sq.extend((0..w).map(|x| r[x] * r[x] + g[x] * g[x] + b[x] * b[x]));
    }
    let max = sq.iter().copied().fold(0.0f32, f32::max);
    let p99 = quantile(sq, 0.99).unwrap_or(0.0);
    [p99, max, 1.0]
        .into_iter()
        .find(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(1.0)
}

/// The position scale `p_phi = 1` stands for: the squared diagonal of the bounding box of the
/// positions in the frame, so that the position weight is the same for a scene and a scaled copy
/// of it (seed 002 claim 17). 1 when all positions coincide.
pub(crate) fn position_scale(position: &Planes) -> f32 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for y in 0..position.height {
        for (k, run) in position.components(y).iter().enumerate() {
            for &v in *run {
                lo[k] = lo[k].min(v);
                hi[k] = hi[k].max(v);
            }
        }
    }
    let d2: f32 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum();
    if d2.is_finite() && d2 > 0.0 {
        d2
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_are_robust_and_never_zero() {
        let mut px = vec![Rgb::splat(1.0); 1000];
        px[0] = Rgb::splat(1e6);
        let img = Image::new(100, 10, px).unwrap();
        assert_eq!(colour_scale(&Planes::from_image(&img)), 3.0);
        let black = Image::filled(4, 4, Rgb::ZERO);
        assert_eq!(colour_scale(&Planes::from_image(&black)), 1.0);
        assert_eq!(position_scale(&Planes::from_image(&black)), 1.0);
        let pos = Image::from_fn(3, 1, |x, _| Rgb::new(x as f32 * 3.0, 0.0, x as f32 * 2.0));
        assert_eq!(position_scale(&Planes::from_image(&pos)), 36.0 + 16.0);
    }

    #[test]
    fn dark_albedo_passes_through() {
        let raw = Image::new(2, 1, vec![Rgb::new(1.0, 2.0, 3.0), Rgb::splat(0.5)]).unwrap();
        let a = Image::new(2, 1, vec![Rgb::new(0.5, 0.0, 1.0), Rgb::splat(0.25)]).unwrap();
        let part = Part::new(raw, Some(&a), 1);
        assert_eq!(
            part.signal.pixels(),
            &[Rgb::new(2.0, 2.0, 3.0), Rgb::splat(2.0)]
        );
        let filtered = Planes::from_image(&Image::filled(2, 1, Rgb::splat(4.0)));
        let mut out = Image::filled(2, 1, Rgb::ZERO);
        part.add_correction(&filtered, &mut out);
        assert_eq!(out.pixels(), &[Rgb::new(1.0, 0.0, 1.0), Rgb::splat(0.5)]);
    }
}
