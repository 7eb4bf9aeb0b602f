//! The Preetham analytic daylight sky with a sun, as an environment map.
//!
//! A. J. Preetham, P. Shirley, B. Smits, "A Practical Analytic Model for Daylight",
//! SIGGRAPH 99. The sky's luminance `Y` and chromaticities `x`, `y` each follow the Perez
//! all-weather distribution
//!
//! ```text
//! F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ)
//! value(θ, γ) = value_zenith · F(θ, γ) / F(0, θ_s)
//! ```
//!
//! (θ: zenith angle of the view direction, γ: its angle to the sun, θ_s: the sun's zenith
//! angle) with coefficients linear in the turbidity `T` (Appendix A.2), the zenith luminance
//! `Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192` kcd/m² with
//! `χ = (4/9 − T/120)(π − 2θ_s)`, and the zenith chromaticities from the appendix's
//! polynomials in `T` and `θ_s`. `xyY` becomes CIE XYZ and then linear Rec. 709 / sRGB (D65),
//! the renderer's colour space. The sun is [`super::sun`]'s model.
//!
//! **Units.** Radiance is in kcd/m² of luminance (the paper's unit for `Y_z`) times the
//! caller's `scale`: the luminance of an RGB value (`rt_core::color::luminance`) is the sky's
//! luminance in kcd/m². A clear sky at the zenith is a few units, the sun about 10⁶.
//!
//! **How it reaches the renderer.** [`Sky::to_env_map`] tabulates the sky into an
//! equirectangular [`EnvMap`] (each texel holds the radiance at its centre) and adds the sun
//! as a [`SunDisc`], so importance sampling is exact for what `Environment::radiance`
//! returns and nothing downstream knows it is a sky.
//!
//! Deviations from the paper:
//! - The sky is tabulated, piecewise constant over texels (512 × 256 by default), like every
//!   environment map here; the paper evaluates it per direction. The sun disc is not
//!   tabulated: at 512 × 256 it covers 0.45–0.9 of a texel below 60° elevation, and a disc
//!   drawn with ~50 texels would need about 4,500 × 2,300 texels at 45° (120 MB), so it is a
//!   separate cone, sampled on its own (see [`crate::environment`]).
//! - The sky is converted from xyY straight to RGB; the paper goes through spectra (the CIE
//!   daylight basis functions) for a spectral renderer. An RGB renderer only sees the
//!   tristimulus values, which the two routes share. Out-of-gamut components (negative RGB)
//!   are clamped to zero.
//! - Below the horizon the environment is black (no ground model): scenes put a ground
//!   plane there.
//! - The sun must be at or above the horizon (the fit covers θ_s ∈ [0, π/2]); within its
//!   radius of the horizon the disc reaches slightly below it.
//! - Turbidity is limited to [1.7, 10]: below about 1.65 the luminance distribution's
//!   gradient term `1 + A e^(B / cos θ)` is negative at the zenith (a negative sky), and 10 is
//!   the haziest of the clear skies the model describes.

use super::sun::{self, SolarTime, SUN_ANGULAR_RADIUS_DEG};
use super::{uv_to_dir, EnvMap, SunDisc};
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

/// Turbidities the model accepts.
pub const TURBIDITY_RANGE: std::ops::RangeInclusive<f32> = 1.7..=10.0;
/// Default size of the tabulated sky, width × height (2:1, lat-long).
pub const DEFAULT_RESOLUTION: (u32, u32) = (512, 256);
/// Largest width or height of the tabulated sky.
pub const MAX_RESOLUTION: u32 = 8192;

/// Why a sky could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SkyError {
    /// Turbidity outside [`TURBIDITY_RANGE`] or not finite.
    #[error(
        "sky turbidity must be in [1.7, 10] (the range the Preetham model is fitted for), got {0}"
    )]
    Turbidity(f32),
    /// A sun direction that is zero or not finite.
    #[error("sky sun_direction must be finite and non-zero, got {0:?}")]
    SunDirection([f32; 3]),
    /// The sun is below the horizon.
    #[error("the sun is {0:.2} degrees below the horizon; the Preetham sky needs it at or above the horizon")]
    SunBelowHorizon(f32),
    /// A latitude outside [−90, 90] degrees.
    #[error("sky latitude must be in [-90, 90] degrees, got {0}")]
    Latitude(f64),
    /// A longitude outside [−180, 180] degrees.
    #[error("sky longitude must be in [-180, 180] degrees (east positive), got {0}")]
    Longitude(f64),
    /// A standard meridian outside [−180, 180] degrees.
    #[error("sky standard_meridian must be in [-180, 180] degrees (east positive), got {0}")]
    StandardMeridian(f64),
    /// A day of the year outside [1, 366].
    #[error("sky day must be a day of the year in [1, 366], got {0}")]
    Day(u32),
    /// An hour outside [0, 24].
    #[error("sky time of day must be in [0, 24] hours, got {0}")]
    Hour(f64),
    /// A negative or non-finite scale.
    #[error("sky scale must be finite and >= 0, got {0}")]
    Scale(f32),
    /// A table size outside [2, MAX_RESOLUTION].
    #[error("sky resolution {0}x{1}: width and height must be in [2, 8192]")]
    Resolution(u32, u32),
}

/// Perez coefficients A–E for one quantity.
type Perez = [f64; 5];

/// The Perez function F(θ, γ) from cos θ and γ.
fn perez(c: &Perez, cos_theta: f64, gamma: f64) -> f64 {
    let [a, b, cc, d, e] = *c;
    let cos_g = gamma.cos();
    (1.0 + a * (b / cos_theta).exp()) * (1.0 + cc * (d * gamma).exp() + e * cos_g * cos_g)
}

/// Linear RGB (Rec. 709 primaries, D65 white) of CIE XYZ (IEC 61966-2-1).
pub fn xyz_to_rgb(xyz: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = xyz;
    [
        3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
        -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
        0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
    ]
}

/// CIE XYZ of chromaticity (x, y) and luminance Y.
pub fn xyy_to_xyz(x: f64, y: f64, lum: f64) -> [f64; 3] {
    if y <= 0.0 {
        return [0.0; 3];
    }
    [x * lum / y, lum, (1.0 - x - y) * lum / y]
}

/// RGB as the renderer stores it: components clamped to [0, ∞) (out-of-gamut colours) and
/// non-finite values to zero.
fn to_rgb(c: [f64; 3]) -> Rgb {
    let f = |v: f64| {
        if v.is_finite() {
            v.max(0.0) as f32
        } else {
            0.0
        }
    };
    Rgb::new(f(c[0]), f(c[1]), f(c[2]))
}

/// A Preetham sky for one sun position and turbidity. All evaluation is in f64; the map it
/// tabulates into is f32.
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    turbidity: f64,
    /// Unit direction towards the sun (f64 copy for γ).
    sun: [f64; 3],
    /// Sun zenith angle θ_s.
    theta_s: f64,
    /// Perez coefficients for Y, x, y.
    coeffs: [Perez; 3],
    /// Zenith values Y (kcd/m²), x, y.
    zenith: [f64; 3],
}

impl Sky {
    /// A sky lit by a sun in direction `sun_direction` (towards the sun, +y up; normalised
    /// here) with atmospheric turbidity `turbidity`.
    pub fn new(sun_direction: Vec3, turbidity: f32) -> Result<Self, SkyError> {
        if !(turbidity.is_finite() && TURBIDITY_RANGE.contains(&turbidity)) {
            return Err(SkyError::Turbidity(turbidity));
        }
        if !sun_direction.is_finite() || sun_direction.length_squared() == 0.0 {
            return Err(SkyError::SunDirection(sun_direction.to_array()));
        }
        let d = sun_direction.as_dvec3().normalize();
        if d.y < 0.0 {
            return Err(SkyError::SunBelowHorizon(-(d.y.asin().to_degrees() as f32)));
        }
        let t = turbidity as f64;
        let theta_s = d.y.clamp(-1.0, 1.0).acos();
        Ok(Self {
            turbidity: t,
            sun: d.to_array(),
            theta_s,
            coeffs: perez_coefficients(t),
            zenith: zenith_values(t, theta_s),
        })
    }

    /// The sky for the sun's position at a date, time and place (the appendix's formula).
    pub fn at(time: &SolarTime, turbidity: f32) -> Result<Self, SkyError> {
        check_time(time)?;
        Self::new(time.sun_direction(), turbidity)
    }

    /// Unit direction towards the sun.
    pub fn sun_direction(&self) -> Vec3 {
        Vec3::from_array(self.sun.map(|v| v as f32))
    }

    /// The sun's zenith angle θ_s in radians.
    pub fn sun_zenith_angle(&self) -> f64 {
        self.theta_s
    }

    /// Zenith luminance (kcd/m²) and chromaticity: `[Y, x, y]`.
    pub fn zenith(&self) -> [f64; 3] {
        self.zenith
    }

    /// Luminance (kcd/m²) and chromaticity `[Y, x, y]` of the sky seen along direction `d`
    /// (+y up), or `None` below the horizon.
    pub fn yxy(&self, d: Vec3) -> Option<[f64; 3]> {
        let d = d.as_dvec3().normalize();
        if d.y.is_nan() || d.y <= 0.0 {
            return None;
        }
        let cos_gamma = d.dot(glam::DVec3::from_array(self.sun)).clamp(-1.0, 1.0);
        let gamma = cos_gamma.acos();
        Some(std::array::from_fn(|i| {
            let c = &self.coeffs[i];
            self.zenith[i] * perez(c, d.y, gamma) / perez(c, 1.0, self.theta_s)
        }))
    }

    /// Linear RGB radiance of the sky (without the sun) along `d`, in kcd/m² of luminance;
    /// black below the horizon.
    pub fn radiance(&self, d: Vec3) -> Rgb {
        match self.yxy(d) {
            Some([lum, x, y]) => to_rgb(xyz_to_rgb(xyy_to_xyz(x, y, lum))),
            None => Rgb::ZERO,
        }
    }

    /// Linear RGB radiance of the sun disc, in kcd/m² of luminance.
    pub fn sun_radiance(&self) -> Rgb {
        let xyz = sun::spectrum_to_xyz(&sun::spectral_radiance(self.turbidity, self.theta_s));
        // cd/m² to kcd/m².
        to_rgb(xyz_to_rgb(xyz.map(|v| v / 1000.0)))
    }

    /// Tabulates the sky into a `width × height` lat-long map (texel = radiance at its centre)
    /// times `scale`, with the sun as a disc of [`SUN_ANGULAR_RADIUS_DEG`] on top.
    pub fn to_env_map(&self, scale: f32, width: u32, height: u32) -> Result<EnvMap, SkyError> {
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(SkyError::Scale(scale));
        }
        if !((2..=MAX_RESOLUTION).contains(&width) && (2..=MAX_RESOLUTION).contains(&height)) {
            return Err(SkyError::Resolution(width, height));
        }
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let uv = Vec2::new(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                );
                texels.push(self.radiance(uv_to_dir(uv)) * scale);
            }
        }
        let sun = SunDisc::new(
            self.sun_direction(),
            SUN_ANGULAR_RADIUS_DEG.to_radians() as f32,
            self.sun_radiance() * scale,
        );
        Ok(EnvMap::new(width, height, texels).with_sun(sun))
    }
}

/// Checks the ranges of a date, time and place.
pub fn check_time(t: &SolarTime) -> Result<(), SkyError> {
    if !(t.latitude.is_finite() && (-90.0..=90.0).contains(&t.latitude)) {
        return Err(SkyError::Latitude(t.latitude));
    }
    if !(1..=366).contains(&t.day) {
        return Err(SkyError::Day(t.day));
    }
    let hour = match t.time {
        sun::TimeOfDay::Solar(h) => h,
        sun::TimeOfDay::Standard {
            hour,
            longitude,
            standard_meridian,
        } => {
            if !(longitude.is_finite() && (-180.0..=180.0).contains(&longitude)) {
                return Err(SkyError::Longitude(longitude));
            }
            if !(standard_meridian.is_finite() && (-180.0..=180.0).contains(&standard_meridian)) {
                return Err(SkyError::StandardMeridian(standard_meridian));
            }
            hour
        }
    };
    if !(hour.is_finite() && (0.0..=24.0).contains(&hour)) {
        return Err(SkyError::Hour(hour));
    }
    Ok(())
}

/// Perez coefficients A–E for Y, x and y at turbidity `t` (Appendix A.2).
fn perez_coefficients(t: f64) -> [Perez; 3] {
    [
        [
            0.1787 * t - 1.4630,
            -0.3554 * t + 0.4275,
            -0.0227 * t + 5.3251,
            0.1206 * t - 2.5771,
            -0.0670 * t + 0.3703,
        ],
        [
            -0.0193 * t - 0.2592,
            -0.0665 * t + 0.0008,
            -0.0004 * t + 0.2125,
            -0.0641 * t - 0.8989,
            -0.0033 * t + 0.0452,
        ],
        [
            -0.0167 * t - 0.2608,
            -0.0950 * t + 0.0092,
            -0.0079 * t + 0.2102,
            -0.0441 * t - 1.6537,
            -0.0109 * t + 0.0529,
        ],
    ]
}

/// Zenith luminance (kcd/m²) and chromaticities `[Y, x, y]` at turbidity `t` and sun zenith
/// angle `theta_s` (Appendix A.2).
fn zenith_values(t: f64, theta_s: f64) -> [f64; 3] {
    let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
    let lum = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    const X: [[f64; 4]; 3] = [
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ];
    const Y: [[f64; 4]; 3] = [
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ];
    let tv = [t * t, t, 1.0];
    let th = [theta_s.powi(3), theta_s * theta_s, theta_s, 1.0];
    let poly = |m: &[[f64; 4]; 3]| -> f64 {
        (0..3)
            .map(|i| tv[i] * (0..4).map(|j| m[i][j] * th[j]).sum::<f64>())
            .sum()
    };
    [lum, poly(&X), poly(&Y)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::luminance;
    use crate::environment::Environment;

    /// Unit direction at elevation `el` and azimuth `az` (degrees; azimuth 0 is −z, 90 is +x).
    fn dir(el: f64, az: f64) -> Vec3 {
        let (el, az) = (el.to_radians(), az.to_radians());
        Vec3::new(
            (el.cos() * az.sin()) as f32,
            el.sin() as f32,
            (-el.cos() * az.cos()) as f32,
        )
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn zenith_values_match_the_appendix_formulas() {
        // Reference values from the appendix's formulas evaluated independently in double
        // precision (Python): [Y kcd/m², x, y].
        for (t, el, expected) in [
            (
                3.0,
                30.0,
                [5.139156036248174, 0.24492859354203797, 0.2525731242208065],
            ),
            (
                2.0,
                60.0,
                [5.886743249307964, 0.25142146237013935, 0.2559238381535146],
            ),
            (
                10.0,
                5.0,
                [2.5034464076941707, 0.3106830209077872, 0.33743639360678035],
            ),
            (5.0, 90.0, [49.72596450745196, 0.27856, 0.29268]),
        ] {
            let z = zenith_values(t, (90.0f64 - el).to_radians());
            for i in 0..3 {
                assert!(close(z[i], expected[i], 1e-9), "T {t}, el {el}: {z:?}");
            }
        }
    }

    #[test]
    fn sky_values_match_an_independent_evaluation() {
        // Sun at azimuth 0; a view at zenith angle θ and azimuth offset φ has γ = |θ − θ_s|
        // for φ = 0 and a known γ otherwise. References as above: [Y, x, y].
        let sky = Sky::new(dir(30.0, 0.0), 3.0).unwrap();
        let toward = sky.yxy(dir(45.0, 0.0)).unwrap(); // γ = 15°
        let expected = [16.53209903441524, 0.27874341170703343, 0.2867220802648994];
        for i in 0..3 {
            assert!(close(toward[i], expected[i], 1e-5), "{toward:?}");
        }
        // The zenith gives the zenith values (up to rounding of z · F / F).
        let (at_zenith, zenith) = (sky.yxy(Vec3::Y).unwrap(), sky.zenith());
        for i in 0..3 {
            assert!(
                close(at_zenith[i], zenith[i], 1e-12),
                "{at_zenith:?} {zenith:?}"
            );
        }
        let sky = Sky::new(dir(50.0, 0.0), 6.0).unwrap();
        // θ = 80°, γ = 60°: the view's azimuth φ from cos γ = cos θ cos θ_s + sin θ sin θ_s cos φ.
        let (th, ts, g) = (80f64.to_radians(), 40f64.to_radians(), 60f64.to_radians());
        let phi = ((g.cos() - th.cos() * ts.cos()) / (th.sin() * ts.sin())).acos();
        let v = sky.yxy(dir(10.0, phi.to_degrees())).unwrap();
        let expected = [13.226092346770749, 0.32406998719431085, 0.335771175412436];
        for i in 0..3 {
            assert!(close(v[i], expected[i], 1e-5), "{v:?}");
        }
        // Its RGB, through XYZ and the sRGB matrix: [14.355, 12.996, 12.178].
        let rgb = sky.radiance(dir(10.0, phi.to_degrees()));
        for (c, e) in rgb
            .to_array()
            .iter()
            .zip([14.35486226, 12.99624254, 12.17751191])
        {
            assert!(close(*c as f64, e, 1e-4), "{rgb}");
        }
        assert!(close(luminance(rgb) as f64, expected[0], 1e-4), "{rgb}");
    }

    #[test]
    fn sky_is_brighter_towards_the_sun_and_blue_overhead() {
        for t in [1.7, 2.0, 3.0, 6.0, 10.0] {
            for sun_el in [5.0, 20.0, 45.0, 70.0] {
                let sky = Sky::new(dir(sun_el, 30.0), t).unwrap();
                for el in [10.0, 30.0, 60.0] {
                    let toward = sky.yxy(dir(el, 30.0)).unwrap()[0];
                    let away = sky.yxy(dir(el, 210.0)).unwrap()[0];
                    let side = sky.yxy(dir(el, 120.0)).unwrap()[0];
                    assert!(
                        toward > away && toward > side,
                        "T {t}, sun {sun_el}°, view {el}°: {toward} {side} {away}"
                    );
                }
            }
            // A clear sky (low turbidity) is blue at the zenith; haze makes it greyer.
            let sky = Sky::new(dir(40.0, 0.0), t).unwrap();
            let z = sky.radiance(Vec3::Y);
            if t <= 3.0 {
                assert!(z.z > 1.3 * z.x, "T {t}: {z}");
            }
        }
        let blueness = |t: f32| {
            let z = Sky::new(dir(40.0, 0.0), t).unwrap().radiance(Vec3::Y);
            z.z / z.x
        };
        assert!(blueness(2.0) > blueness(5.0) && blueness(5.0) > blueness(10.0));
    }

    #[test]
    fn the_sun_is_white_at_noon_and_red_at_sunset_and_dominates_the_sky() {
        let high = Sky::new(dir(60.0, 0.0), 2.5).unwrap();
        let low = Sky::new(dir(3.0, 0.0), 2.5).unwrap();
        let (h, l) = (high.sun_radiance(), low.sun_radiance());
        assert!(h.z > 0.7 * h.x && h.z < h.x, "{h}");
        assert!(l.z < 0.3 * l.x, "{l}");
        // Disc luminance about 1.3e6 kcd/m², a million times the sky's.
        assert!((1.0e6..1.6e6).contains(&luminance(h)), "{h}");
        assert!(luminance(h) > 1e5 * luminance(high.radiance(Vec3::Y)));
    }

    #[test]
    fn tabulated_sky_is_finite_non_negative_and_black_below_the_horizon() {
        for t in [1.7, 3.0, 10.0] {
            for el in [0.0, 0.5, 15.0, 45.0, 90.0] {
                let map = Sky::new(dir(el, 123.0), t)
                    .unwrap()
                    .to_env_map(1.0, 64, 32)
                    .unwrap();
                let env = Environment::Map(map);
                for y in 0..32 {
                    for x in 0..64 {
                        let d =
                            uv_to_dir(Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0));
                        let r = env.radiance(d);
                        assert!(
                            r.is_finite() && r.min_element() >= 0.0,
                            "T {t} el {el}: {r}"
                        );
                        if y >= 16 {
                            assert_eq!(r, Rgb::ZERO, "below the horizon");
                        } else {
                            assert!(luminance(r) > 0.0, "T {t} el {el} ({x}, {y})");
                        }
                    }
                }
                let sun = env.map().unwrap().sun().unwrap();
                assert!(sun.radiance().is_finite() && sun.radiance().min_element() >= 0.0);
                assert!(!env.is_black());
            }
        }
    }

    #[test]
    fn bad_parameters_are_typed_errors() {
        for t in [1.69, 10.01, f32::NAN, -3.0] {
            assert!(
                matches!(Sky::new(Vec3::Y, t), Err(SkyError::Turbidity(_))),
                "{t}"
            );
        }
        assert!(Sky::new(Vec3::Y, 1.7).is_ok() && Sky::new(Vec3::Y, 10.0).is_ok());
        assert!(matches!(
            Sky::new(Vec3::ZERO, 3.0),
            Err(SkyError::SunDirection(_))
        ));
        assert!(matches!(
            Sky::new(Vec3::new(f32::INFINITY, 1.0, 0.0), 3.0),
            Err(SkyError::SunDirection(_))
        ));
        let e = Sky::new(dir(-5.0, 0.0), 3.0).unwrap_err();
        assert_eq!(e, SkyError::SunBelowHorizon(5.0));
        assert!(
            e.to_string().contains("5.00 degrees below the horizon"),
            "{e}"
        );
        assert!(Sky::new(Vec3::X, 3.0).is_ok(), "on the horizon");
        let sky = Sky::new(Vec3::Y, 3.0).unwrap();
        assert!(matches!(
            sky.to_env_map(-1.0, 8, 4),
            Err(SkyError::Scale(_))
        ));
        assert!(matches!(
            sky.to_env_map(f32::NAN, 8, 4),
            Err(SkyError::Scale(_))
        ));
        assert!(matches!(
            sky.to_env_map(1.0, 1, 4),
            Err(SkyError::Resolution(1, 4))
        ));
        assert!(matches!(
            sky.to_env_map(1.0, 8, 8193),
            Err(SkyError::Resolution(..))
        ));
        let at = |latitude: f64, day: u32, time: sun::TimeOfDay| {
            Sky::at(
                &SolarTime {
                    latitude,
                    day,
                    time,
                },
                3.0,
            )
        };
        let solar = sun::TimeOfDay::Solar(12.0);
        assert!(matches!(at(91.0, 100, solar), Err(SkyError::Latitude(_))));
        assert!(matches!(
            at(f64::NAN, 100, solar),
            Err(SkyError::Latitude(_))
        ));
        assert!(matches!(at(40.0, 0, solar), Err(SkyError::Day(0))));
        assert!(matches!(at(40.0, 367, solar), Err(SkyError::Day(367))));
        assert!(matches!(
            at(40.0, 100, sun::TimeOfDay::Solar(24.5)),
            Err(SkyError::Hour(_))
        ));
        let standard = |hour, longitude, standard_meridian| sun::TimeOfDay::Standard {
            hour,
            longitude,
            standard_meridian,
        };
        assert!(matches!(
            at(40.0, 100, standard(12.0, 181.0, 0.0)),
            Err(SkyError::Longitude(_))
        ));
        assert!(matches!(
            at(40.0, 100, standard(12.0, 0.0, -200.0)),
            Err(SkyError::StandardMeridian(_))
        ));
        assert!(matches!(
            at(40.0, 100, standard(-1.0, 0.0, 0.0)),
            Err(SkyError::Hour(_))
        ));
        // Midnight in June at 40° N: the sun is 26.6° below the horizon.
        let e = at(40.0, 172, sun::TimeOfDay::Solar(0.0)).unwrap_err();
        assert!(
            matches!(e, SkyError::SunBelowHorizon(el) if (el - 26.56).abs() < 0.1),
            "{e}"
        );
        assert!(at(40.0, 172, standard(14.5, 8.5, 15.0)).is_ok());
    }
}
