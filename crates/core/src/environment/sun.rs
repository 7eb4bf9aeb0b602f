//! The sun of the Preetham daylight model: where it is (solar position from time and place)
//! and how bright it is (its spectral radiance after the atmosphere's attenuation).
//!
//! A. J. Preetham, P. Shirley, B. Smits, "A Practical Analytic Model for Daylight",
//! SIGGRAPH 99, Appendix A.6 (solar position) and the paper's sun model, whose attenuation
//! terms and data come from M. Iqbal, *An Introduction to Solar Radiation* (1983).
//!
//! **Position.** Solar time `t = t_s + 0.170 sin(4π(J − 80)/373) − 0.129 sin(2π(J − 8)/355)
//! + 12(L − SM)/π` (hours, from standard time `t_s`, day of year `J`, longitude `L` and
//! standard meridian `SM` in radians), declination `δ = 0.4093 sin(2π(J − 81)/368)`, and the
//! sun's zenith angle `θ_s = π/2 − asin(sin l sin δ − cos l cos δ cos(πt/12))` at latitude `l`.
//!
//! **Radiance.** The extraterrestrial solar spectrum (380–750 nm in 10 nm steps) times the
//! transmittances of Rayleigh scattering, aerosols (Ångström's law with `α = 1.3` and the
//! turbidity-dependent `β = 0.04608 T − 0.04586`), ozone (0.35 cm), and water vapour (2 cm),
//! along the relative optical mass `m = 1 / (cos θ_s + 0.15 (93.885 − θ_s°)^−1.253)` (Kasten),
//! integrated against the CIE 1931 2° colour-matching functions.
//!
//! Deviations:
//! - Longitudes are positive **east** (ISO 6709). The appendix's `12(SM − L)/π` holds for
//!   longitudes counted positive west; with east-positive values the term is `12(L − SM)/π`.
//! - The azimuth is computed as the atan2 of the sun vector's west and south components (the
//!   paper's own code does the same); the appendix writes it as an arctangent of their ratio,
//!   which loses the quadrant. We return the direction vector and never form the angle.
//! - The mixed-gas term (the O₂ A band, 759–771 nm) lies outside the 380–750 nm range we
//!   integrate over, so it is left out; it changes nothing in that range.
//! - The disc is uniformly bright (no limb darkening) and its radiance is the one for the
//!   zenith angle of its centre.
//!
//! Compass: north is −z (where a default camera looks), east +x, south +z, west −x; +y is up.

use glam::Vec3;
use std::f64::consts::PI;

/// Angular radius of the sun disc in degrees (its apparent diameter is about 0.533°).
pub const SUN_ANGULAR_RADIUS_DEG: f64 = 0.2667;

/// First wavelength of the spectral tables, nm.
pub const LAMBDA_MIN: f64 = 380.0;
/// Wavelength step of the spectral tables, nm.
pub const LAMBDA_STEP: f64 = 10.0;
/// Number of wavelengths (380, 390, ..., 750 nm).
pub const SAMPLES: usize = 38;

/// Extraterrestrial solar spectral radiance, W m⁻² sr⁻¹ nm⁻¹, 380–750 nm. Iqbal's table as
/// used by the paper's code (which stores it in units of 100 W m⁻² sr⁻¹ nm⁻¹).
const SOLAR: [f64; SAMPLES] = [
    16550.0, 16230.0, 21120.0, 25880.0, 25820.0, 24230.0, 26760.0, 29660.0, 30540.0, 30060.0,
    30660.0, 28830.0, 28710.0, 27820.0, 27100.0, 27230.0, 26360.0, 25500.0, 25060.0, 25310.0,
    25350.0, 25130.0, 24630.0, 24170.0, 23680.0, 23210.0, 22820.0, 22340.0, 21970.0, 21530.0,
    21100.0, 20730.0, 20240.0, 19870.0, 19430.0, 19070.0, 18630.0, 18260.0,
];

/// Ozone absorption coefficient, cm⁻¹ (Iqbal p. 127), as (wavelength nm, k) pairs covering
/// 355–760 nm; linear in between, as in the paper's code.
const OZONE: [(f64, f64); 51] = [
    (355.0, 0.0),
    (445.0, 0.003),
    (450.0, 0.003),
    (455.0, 0.004),
    (460.0, 0.006),
    (465.0, 0.008),
    (470.0, 0.009),
    (475.0, 0.012),
    (480.0, 0.014),
    (485.0, 0.017),
    (490.0, 0.021),
    (495.0, 0.025),
    (500.0, 0.03),
    (505.0, 0.035),
    (510.0, 0.04),
    (515.0, 0.045),
    (520.0, 0.048),
    (525.0, 0.057),
    (530.0, 0.063),
    (535.0, 0.07),
    (540.0, 0.075),
    (545.0, 0.08),
    (550.0, 0.085),
    (555.0, 0.095),
    (560.0, 0.103),
    (565.0, 0.11),
    (570.0, 0.12),
    (575.0, 0.122),
    (580.0, 0.12),
    (585.0, 0.118),
    (590.0, 0.115),
    (595.0, 0.12),
    (600.0, 0.125),
    (605.0, 0.13),
    (610.0, 0.12),
    (620.0, 0.105),
    (630.0, 0.09),
    (640.0, 0.079),
    (650.0, 0.067),
    (660.0, 0.057),
    (670.0, 0.048),
    (680.0, 0.036),
    (690.0, 0.028),
    (700.0, 0.023),
    (710.0, 0.018),
    (720.0, 0.014),
    (730.0, 0.011),
    (740.0, 0.01),
    (750.0, 0.009),
    (760.0, 0.007),
    (770.0, 0.004),
];

/// Water-vapour absorption coefficient, cm⁻¹ (Iqbal p. 130), as (wavelength nm, k) pairs;
/// zero below 689 nm.
const WATER: [(f64, f64); 9] = [
    (689.0, 0.0),
    (690.0, 0.016),
    (700.0, 0.024),
    (710.0, 0.0125),
    (720.0, 1.0),
    (730.0, 0.87),
    (740.0, 0.061),
    (750.0, 0.001),
    (760.0, 0.00001),
];

/// CIE 1931 2° colour-matching functions x̄, ȳ, z̄ at 380–750 nm in 10 nm steps.
pub const CIE_XYZ: [[f64; 3]; SAMPLES] = [
    [0.001368, 0.000039, 0.006450],
    [0.004243, 0.000120, 0.020050],
    [0.014310, 0.000396, 0.067850],
    [0.043510, 0.001210, 0.207400],
    [0.134380, 0.004000, 0.645600],
    [0.283900, 0.011600, 1.385600],
    [0.348280, 0.023000, 1.747060],
    [0.336200, 0.038000, 1.772110],
    [0.290800, 0.060000, 1.669200],
    [0.195360, 0.090980, 1.287640],
    [0.095640, 0.139020, 0.812950],
    [0.032010, 0.208020, 0.465180],
    [0.004900, 0.323000, 0.272000],
    [0.009300, 0.503000, 0.158200],
    [0.063270, 0.710000, 0.078250],
    [0.165500, 0.862000, 0.042160],
    [0.290400, 0.954000, 0.020300],
    [0.433450, 0.994950, 0.008750],
    [0.594500, 0.995000, 0.003900],
    [0.762100, 0.952000, 0.002100],
    [0.916300, 0.870000, 0.001650],
    [1.026300, 0.757000, 0.001100],
    [1.062200, 0.631000, 0.000800],
    [1.002600, 0.503000, 0.000340],
    [0.854450, 0.381000, 0.000190],
    [0.642400, 0.265000, 0.000050],
    [0.447900, 0.175000, 0.000020],
    [0.283500, 0.107000, 0.0],
    [0.164900, 0.061000, 0.0],
    [0.087400, 0.032000, 0.0],
    [0.046770, 0.017000, 0.0],
    [0.022700, 0.008210, 0.0],
    [0.011359, 0.004102, 0.0],
    [0.005790, 0.002091, 0.0],
    [0.002899, 0.001047, 0.0],
    [0.001440, 0.000520, 0.0],
    [0.000690, 0.000249, 0.0],
    [0.000332, 0.000120, 0.0],
];

/// Maximum luminous efficacy, lm/W: photometric = 683 × radiometric weighted by ȳ.
pub const LUMINOUS_EFFICACY: f64 = 683.0;

/// Linear interpolation in a table of (x, y) pairs sorted by x; zero outside it.
fn interpolate(table: &[(f64, f64)], x: f64) -> f64 {
    let i = table.partition_point(|&(tx, _)| tx <= x);
    if i == 0 || i == table.len() {
        return 0.0;
    }
    let ((x0, y0), (x1, y1)) = (table[i - 1], table[i]);
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

/// Relative optical air mass for sun zenith angle `theta` (radians, clamped to [0, π/2]):
/// Kasten's formula as in the paper, which stays finite (about 38) at the horizon.
pub fn optical_mass(theta: f64) -> f64 {
    let theta = theta.clamp(0.0, PI / 2.0);
    1.0 / (theta.cos() + 0.15 * (93.885 - theta.to_degrees()).powf(-1.253))
}

/// The sun's spectral radiance at the ground, W m⁻² sr⁻¹ nm⁻¹, at 380–750 nm in 10 nm steps,
/// for turbidity `turbidity` and sun zenith angle `theta` (radians).
pub fn spectral_radiance(turbidity: f64, theta: f64) -> [f64; SAMPLES] {
    let m = optical_mass(theta);
    let beta = 0.04608365822050 * turbidity - 0.04586025928522;
    const ALPHA: f64 = 1.3;
    const OZONE_CM: f64 = 0.35;
    const WATER_CM: f64 = 2.0;
    std::array::from_fn(|i| {
        let nm = LAMBDA_MIN + LAMBDA_STEP * i as f64;
        let um = nm / 1000.0;
        let rayleigh = (-m * 0.008735 * um.powf(-4.08)).exp();
        let aerosol = (-m * beta * um.powf(-ALPHA)).exp();
        let ozone = (-m * interpolate(&OZONE, nm) * OZONE_CM).exp();
        let kwa = interpolate(&WATER, nm) * WATER_CM * m;
        let water = (-0.2385 * kwa / (1.0 + 20.07 * kwa).powf(0.45)).exp();
        SOLAR[i] * rayleigh * aerosol * ozone * water
    })
}

/// The extraterrestrial solar spectrum (no atmosphere), W m⁻² sr⁻¹ nm⁻¹.
pub fn extraterrestrial_radiance() -> [f64; SAMPLES] {
    SOLAR
}

/// CIE XYZ of a spectral radiance sampled like [`spectral_radiance`], in cd/m² (Y is the
/// luminance): the rectangle rule over the 10 nm samples, times 683 lm/W.
pub fn spectrum_to_xyz(spectrum: &[f64; SAMPLES]) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for (s, cmf) in spectrum.iter().zip(&CIE_XYZ) {
        for c in 0..3 {
            xyz[c] += s * cmf[c];
        }
    }
    xyz.map(|v| v * LAMBDA_STEP * LUMINOUS_EFFICACY)
}

/// Time of day for [`SolarTime`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeOfDay {
    /// Local standard (clock) time in hours, at a place given by its longitude and its time
    /// zone's standard meridian, both in degrees east; the equation of time and the longitude
    /// correction turn it into solar time.
    Standard {
        /// Hours since midnight, [0, 24].
        hour: f64,
        /// Degrees, positive east, [−180, 180].
        longitude: f64,
        /// Degrees, positive east, [−180, 180] (e.g. 15 for Central European Time).
        standard_meridian: f64,
    },
    /// Local apparent solar time in hours (12 is solar noon).
    Solar(f64),
}

/// A date, time and place, from which the paper's appendix formula gives the sun's position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolarTime {
    /// Degrees, positive north, [−90, 90].
    pub latitude: f64,
    /// Day of the year, 1 = 1 January (the paper's "Julian day"), [1, 366].
    pub day: u32,
    /// The time.
    pub time: TimeOfDay,
}

impl SolarTime {
    /// Apparent solar time in hours (12 at solar noon), not wrapped into [0, 24).
    pub fn solar_hour(&self) -> f64 {
        match self.time {
            TimeOfDay::Solar(t) => t,
            TimeOfDay::Standard {
                hour,
                longitude,
                standard_meridian,
            } => {
                hour + equation_of_time(self.day)
                    + 12.0 * (longitude - standard_meridian).to_radians() / PI
            }
        }
    }

    /// Solar declination δ in radians.
    pub fn declination(&self) -> f64 {
        declination(self.day)
    }

    /// Unit direction towards the sun (+y up, north −z, east +x). Below the horizon when
    /// `y < 0`.
    pub fn sun_direction(&self) -> Vec3 {
        let (l, d) = (self.latitude.to_radians(), self.declination());
        // The appendix's angle πt/12 is measured from midnight: cos(πt/12) = −cos H for the
        // hour angle H from noon.
        let a = PI * self.solar_hour() / 12.0;
        let up = l.sin() * d.sin() - l.cos() * d.cos() * a.cos();
        let west = -d.cos() * a.sin();
        let south = -(l.cos() * d.sin() + l.sin() * d.cos() * a.cos());
        Vec3::new(-west as f32, up as f32, south as f32).normalize()
    }

    /// The sun's zenith angle θ_s in radians (the appendix formula; above π/2 when the sun is
    /// below the horizon).
    pub fn zenith_angle(&self) -> f64 {
        let (l, d) = (self.latitude.to_radians(), self.declination());
        let a = PI * self.solar_hour() / 12.0;
        PI / 2.0 - (l.sin() * d.sin() - l.cos() * d.cos() * a.cos()).asin()
    }
}

/// Apparent minus mean solar time in hours for day of year `day` (the appendix's fit).
pub fn equation_of_time(day: u32) -> f64 {
    let j = day as f64;
    0.170 * (4.0 * PI * (j - 80.0) / 373.0).sin() - 0.129 * (2.0 * PI * (j - 8.0) / 355.0).sin()
}

/// Solar declination in radians for day of year `day` (the appendix's fit).
pub fn declination(day: u32) -> f64 {
    0.4093 * (2.0 * PI * (day as f64 - 81.0) / 368.0).sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_matching_functions_integrate_to_the_equal_energy_white() {
        // ∫x̄ = ∫ȳ = ∫z̄ = 106.86 nm over the visible range; the 380–750 nm part at 10 nm
        // steps holds all but a few thousandths of it.
        let sums = (0..3).map(|c| CIE_XYZ.iter().map(|r| r[c]).sum::<f64>() * 10.0);
        for (c, s) in sums.enumerate() {
            assert!((s - 106.86).abs() < 0.2, "channel {c}: {s}");
        }
    }

    #[test]
    fn extraterrestrial_sun_has_the_published_luminance_and_illuminance() {
        // The sun outside the atmosphere: luminance about 1.9e9 cd/m² and illuminance at
        // normal incidence about 128 klx (the "solar illuminance constant", 127.5–133.8 klx
        // in the literature). Iqbal's table integrated over 380–750 nm gives 128.1 klx.
        let xyz = spectrum_to_xyz(&extraterrestrial_radiance());
        let r = SUN_ANGULAR_RADIUS_DEG.to_radians();
        let omega = 2.0 * PI * (1.0 - r.cos());
        let lux = xyz[1] * omega;
        assert!((1.8e9..2.0e9).contains(&xyz[1]), "{}", xyz[1]);
        assert!((124e3..134e3).contains(&lux), "{lux}");
        // Chromaticity near the sun's 5800 K (x ≈ 0.32, y ≈ 0.33).
        let s = xyz.iter().sum::<f64>();
        assert!((xyz[0] / s - 0.317).abs() < 0.01 && (xyz[1] / s - 0.326).abs() < 0.01);
    }

    #[test]
    fn atmosphere_dims_and_reddens_the_sun_with_air_mass_and_turbidity() {
        // Values of the paper's model computed independently in double precision (Python,
        // same formulas and tables): luminance of the disc in cd/m².
        for (t, elevation, expected) in [
            (2.0, 90.0, 1.49660e9),
            (3.0, 45.0, 1.18463e9),
            (5.0, 10.0, 1.04807e8),
        ] {
            let y = spectrum_to_xyz(&spectral_radiance(t, (90.0f64 - elevation).to_radians()))[1];
            assert!(
                (y / expected - 1.0).abs() < 2e-3,
                "T {t}, elevation {elevation}: {y} vs {expected}"
            );
        }
        let blue_over_red = |t: f64, el: f64| {
            let s = spectral_radiance(t, (90.0f64 - el).to_radians());
            s[7] / s[27] // 450 nm over 650 nm
        };
        assert!(blue_over_red(3.0, 60.0) > blue_over_red(3.0, 10.0));
        assert!(blue_over_red(2.0, 45.0) > blue_over_red(8.0, 45.0));
        assert!((optical_mass(0.0) - 1.0).abs() < 1e-3);
        assert!((30.0..40.0).contains(&optical_mass(PI / 2.0)));
    }

    fn elevation_deg(t: &SolarTime) -> f64 {
        90.0 - t.zenith_angle().to_degrees()
    }

    #[test]
    fn solar_noon_elevation_at_equinox_and_solstice() {
        // Day 81 has δ = 0 exactly in the fit, so at solar noon the elevation is 90° − |lat|.
        for lat in [-33.9, 0.0, 40.0, 52.5, 70.0] {
            let t = SolarTime {
                latitude: lat,
                day: 81,
                time: TimeOfDay::Solar(12.0),
            };
            assert!(
                (elevation_deg(&t) - (90.0 - f64::abs(lat))).abs() < 1e-9,
                "{lat}"
            );
            let d = t.sun_direction();
            assert!((d.y as f64 - elevation_deg(&t).to_radians().sin()).abs() < 1e-6);
            // Noon: due south north of the equator, due north south of it, no east-west part.
            assert!(d.x.abs() < 1e-6, "{d}");
            if lat > 0.0 {
                assert!(d.z > 0.0, "{d}");
            } else if lat < 0.0 {
                assert!(d.z < 0.0, "{d}");
            }
        }
        // June solstice (day 172) at 52.5° N: 90 − 52.5 + 23.44 = 60.94° (almanac value for
        // Berlin's noon sun on 21 June is 60.9°); the declination fit is within 0.05°.
        let t = SolarTime {
            latitude: 52.5,
            day: 172,
            time: TimeOfDay::Solar(12.0),
        };
        assert!(
            (elevation_deg(&t) - 60.94).abs() < 0.1,
            "{}",
            elevation_deg(&t)
        );
    }

    #[test]
    fn equation_of_time_and_longitude_correction() {
        // Almanac equation of time: about −14.2 min on 11 February, +16.4 min on 3 November,
        // −7.0 min on 22 March. The fit is good to about half a minute there.
        for (day, minutes) in [(42, -14.2), (307, 16.4), (81, -7.0)] {
            let e = equation_of_time(day) * 60.0;
            assert!((e - minutes).abs() < 0.6, "day {day}: {e} min vs {minutes}");
        }
        // 15° east of the standard meridian the sun is an hour ahead of the clock.
        let at = |longitude: f64| SolarTime {
            latitude: 47.0,
            day: 100,
            time: TimeOfDay::Standard {
                hour: 12.0,
                longitude,
                standard_meridian: 15.0,
            },
        };
        let dt = at(30.0).solar_hour() - at(15.0).solar_hour();
        assert!((dt - 1.0).abs() < 1e-12, "{dt}");
        assert!((at(15.0).solar_hour() - (12.0 + equation_of_time(100))).abs() < 1e-12);
    }

    #[test]
    fn sun_rises_in_the_east_and_sets_in_the_west() {
        let at = |hour: f64| {
            SolarTime {
                latitude: 40.0,
                day: 172,
                time: TimeOfDay::Solar(hour),
            }
            .sun_direction()
        };
        let (morning, evening, midnight) = (at(8.0), at(16.0), at(0.0));
        assert!(morning.x > 0.5 && evening.x < -0.5, "{morning} {evening}");
        // Symmetric about solar noon.
        assert!((morning.y - evening.y).abs() < 1e-6 && (morning.z - evening.z).abs() < 1e-6);
        assert!(midnight.y < 0.0, "{midnight}");
        // In June at 40° N the sun rises north of east: at 6 h it is already up, in the
        // north-east quadrant.
        let six = at(6.0);
        assert!(six.y > 0.0 && six.x > 0.0 && six.z < 0.0, "{six}");
    }
}
