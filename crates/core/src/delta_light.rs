//! Lights of no extent: a point, a spot and a distant directional light, as Mitsuba 3 defines
//! them (`src/emitters/point.cpp`, `spot.cpp`, `directional.cpp`). Light sampling picks one
//! among the emissive triangles by power ([`crate::lights::LightSampler`]) and reaches it by a
//! deterministic connection: the light's "pdf" is a delta, so a light-sampled contribution gets
//! no MIS weight, and BSDF-sampled rays never find one.
//!
//! Units: a point or spot light has a radiant intensity `I` (power per steradian), so a point
//! at distance `r` receives `I / r²` across a surface facing it; a directional light has an
//! irradiance `E` on a surface perpendicular to it.
//!
//! The spot's falloff is Mitsuba's: full intensity within `beam_width` of the axis, zero beyond
//! `cutoff`, linear in the angle between. Deviation: the spot keeps only its axis, so a
//! `to_world` that shears or scales unevenly does not squash the cone as Mitsuba's inverse
//! transform does (the readers refuse such transforms).

use crate::{color::luminance, frame::Frame, sampling, Aabb, Rgb};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A light of no extent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DeltaLight {
    /// Emits `intensity` (W/sr per channel) evenly in every direction from `position`.
    Point {
        /// Where the light is.
        position: Vec3,
        /// Radiant intensity.
        intensity: Rgb,
    },
    /// Emits `intensity` along `axis`, falling off linearly in the angle from `beam_width` to
    /// `cutoff` (radians, `0 ≤ beam_width ≤ cutoff ≤ π`).
    Spot {
        /// Where the light is.
        position: Vec3,
        /// Unit direction of the beam's centre.
        axis: Vec3,
        /// Radiant intensity on the axis.
        intensity: Rgb,
        /// Half-angle beyond which the light is black.
        cutoff: f32,
        /// Half-angle of the full-intensity centre.
        beam_width: f32,
    },
    /// Light arriving from infinitely far along the unit vector `direction` (the way it
    /// travels), with irradiance `irradiance` on a surface facing it.
    Directional {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Irradiance perpendicular to `direction`.
        irradiance: Rgb,
    },
}

/// Light arriving at a point from a [`DeltaLight`].
#[derive(Clone, Copy, Debug)]
pub struct DeltaIncidence {
    /// Unit direction from the point to the light.
    pub wi: Vec3,
    /// Where the shadow ray ends (unused for a directional light).
    pub point: Vec3,
    /// Distance to the light (`f32::INFINITY` for a directional light).
    pub dist: f32,
    /// What multiplies `f · |cos|` at the point: `I · falloff / r²` or `E`.
    pub le: Rgb,
}

/// A particle leaving a [`DeltaLight`] (light paths start here).
#[derive(Clone, Copy, Debug)]
pub struct DeltaEmission {
    /// Origin of the first ray (on the covering plane before the scene for a directional
    /// light).
    pub origin: Vec3,
    /// Unit direction of the first ray.
    pub dir: Vec3,
    /// Power the particle carries: what the light emits towards `dir` over the pdf of the
    /// start (the light's choice not included).
    pub beta: Rgb,
    /// Pdf of `origin`: 1 for a point or spot (a delta), the plane's `1 / area` for a
    /// directional light.
    pub pdf_position: f32,
    /// Solid-angle pdf of `dir` (1 for a directional light, a delta).
    pub pdf_direction: f32,
}

impl DeltaLight {
    /// True if the light sends out anything.
    pub fn emits(&self) -> bool {
        let c = match *self {
            DeltaLight::Point { intensity, .. } | DeltaLight::Spot { intensity, .. } => intensity,
            DeltaLight::Directional { irradiance, .. } => irradiance,
        };
        c.max_element() > 0.0
    }

    /// The fraction of the spot's axial intensity it emits at angle `acos(cos_theta)` from its
    /// axis (Mitsuba's `falloff_curve`); 1 for the other kinds.
    pub fn falloff(cutoff: f32, beam_width: f32, cos_theta: f32) -> f32 {
        if cos_theta <= cutoff.cos() {
            0.0
        } else if cos_theta >= beam_width.cos() {
            1.0
        } else {
            ((cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (cutoff - beam_width)).clamp(0.0, 1.0)
        }
    }

    /// The light as seen from `x`. `None` where it sends nothing (outside a spot's cone, or `x`
    /// on the light itself).
    pub fn incident(&self, x: Vec3) -> Option<DeltaIncidence> {
        let (position, intensity) = match *self {
            DeltaLight::Directional {
                direction,
                irradiance,
            } => {
                return Some(DeltaIncidence {
                    wi: -direction,
                    point: Vec3::ZERO,
                    dist: f32::INFINITY,
                    le: irradiance,
                })
            }
            DeltaLight::Point {
                position,
                intensity,
            } => (position, intensity),
            DeltaLight::Spot {
                position,
                intensity,
                ..
            } => (position, intensity),
        };
        let d = position - x;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = d / dist;
        let falloff = match *self {
            DeltaLight::Spot {
                axis,
                cutoff,
                beam_width,
                ..
            } => Self::falloff(cutoff, beam_width, axis.dot(-wi)),
            _ => 1.0,
        };
        let le = intensity * (falloff / dist2);
        (le.max_element() > 0.0).then_some(DeltaIncidence {
            wi,
            point: position,
            dist,
            le,
        })
    }

    /// Emitted power over π, by luminance: the unit [`crate::lights::LightSampler`] weighs
    /// emissive triangles in (area · luminance of radiance), so lights of both kinds are
    /// chosen in proportion to their power. A directional light's power is what crosses the
    /// disk of the scene's bounding sphere (`bounds`), as pbrt and Mitsuba estimate it.
    pub fn power_over_pi(&self, bounds: &Aabb) -> f32 {
        match *self {
            DeltaLight::Point { intensity, .. } => 4.0 * luminance(intensity),
            DeltaLight::Spot {
                intensity,
                cutoff,
                beam_width,
                ..
            } => 2.0 * luminance(intensity) * Self::cone_integral(cutoff, beam_width),
            DeltaLight::Directional { irradiance, .. } => {
                if bounds.is_empty() {
                    return 0.0;
                }
                let r = bounds.bounding_radius();
                luminance(irradiance) * r * r
            }
        }
    }

    /// `∫ falloff dω / 2π` over the sphere: `1 − cos c` for a hard cone, and for the linear
    /// ramp `1 − (sin c − sin b) / (c − b)` (integrating `(c − θ)/(c − b) · sin θ` by parts).
    fn cone_integral(cutoff: f32, beam_width: f32) -> f32 {
        let (c, b) = (cutoff as f64, beam_width as f64);
        let v = if c - b < 1e-6 {
            1.0 - c.cos()
        } else {
            1.0 - (c.sin() - b.sin()) / (c - b)
        };
        v.max(0.0) as f32
    }

    /// Solid-angle pdf with which [`DeltaLight::emit`] sends a particle along unit `w`: the
    /// uniform sphere's for a point, the uniform cone's inside a spot's cutoff (0 outside); 0
    /// for a directional light, whose direction is a delta (bidirectional MIS reads that as
    /// "no other strategy samples it").
    pub fn pdf_emit_direction(&self, w: Vec3) -> f32 {
        match *self {
            DeltaLight::Point { .. } => sampling::UNIFORM_SPHERE_PDF,
            DeltaLight::Spot { axis, cutoff, .. } => {
                let cos_max = cutoff.cos();
                if axis.dot(w) >= cos_max {
                    1.0 / (2.0 * PI * (1.0 - cos_max))
                } else {
                    0.0
                }
            }
            DeltaLight::Directional { .. } => 0.0,
        }
    }

    /// Starts a particle from the light: a point light's direction uniform on the sphere, a
    /// spot's uniform in its cutoff cone, a directional light's origin uniform on the plane
    /// covering `bounds` ([`crate::emission::plane_sample`]). `None` if it carries nothing.
    pub fn emit(&self, bounds: &Aabb, u_pos: Vec2, u_dir: Vec2) -> Option<DeltaEmission> {
        let e = match *self {
            DeltaLight::Point {
                position,
                intensity,
            } => DeltaEmission {
                origin: position,
                dir: sampling::uniform_sphere(u_dir),
                beta: intensity / sampling::UNIFORM_SPHERE_PDF,
                pdf_position: 1.0,
                pdf_direction: sampling::UNIFORM_SPHERE_PDF,
            },
            DeltaLight::Spot {
                position,
                axis,
                intensity,
                cutoff,
                beam_width,
            } => {
                let cos_max = cutoff.cos();
                let cos_t = 1.0 - u_dir.x * (1.0 - cos_max);
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u_dir.y;
                let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
                let pdf = 1.0 / (2.0 * PI * (1.0 - cos_max));
                DeltaEmission {
                    origin: position,
                    dir: Frame::from_normal(axis).to_world(local).normalize(),
                    beta: intensity * (Self::falloff(cutoff, beam_width, cos_t) / pdf),
                    pdf_position: 1.0,
                    pdf_direction: pdf,
                }
            }
            DeltaLight::Directional {
                direction,
                irradiance,
            } => {
                let (origin, area) = crate::emission::plane_sample(bounds, direction, u_pos)?;
                DeltaEmission {
                    origin,
                    dir: direction,
                    beta: irradiance * area,
                    pdf_position: 1.0 / area,
                    pdf_direction: 1.0,
                }
            }
        };
        (e.beta.is_finite() && e.beta.max_element() > 0.0 && e.pdf_direction.is_finite())
            .then_some(e)
    }
}

impl crate::content_hash::ContentHash for DeltaLight {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        match self {
            DeltaLight::Point {
                position,
                intensity,
            } => {
                0u32.content_hash(out);
                position.content_hash(out);
                intensity.content_hash(out);
            }
            DeltaLight::Spot {
                position,
                axis,
                intensity,
                cutoff,
                beam_width,
            } => {
                1u32.content_hash(out);
                position.content_hash(out);
                axis.content_hash(out);
                intensity.content_hash(out);
                cutoff.content_hash(out);
                beam_width.content_hash(out);
            }
            DeltaLight::Directional {
                direction,
                irradiance,
            } => {
                2u32.content_hash(out);
                direction.content_hash(out);
                irradiance.content_hash(out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_falloff_ramps_linearly_in_the_angle_between_beam_and_cutoff() {
        let (c, b) = (20f32.to_radians(), 15f32.to_radians());
        assert_eq!(DeltaLight::falloff(c, b, 1.0), 1.0);
        assert_eq!(DeltaLight::falloff(c, b, 14f32.to_radians().cos()), 1.0);
        let mid = DeltaLight::falloff(c, b, 17.5f32.to_radians().cos());
        assert!((mid - 0.5).abs() < 1e-3, "{mid}");
        assert_eq!(DeltaLight::falloff(c, b, 21f32.to_radians().cos()), 0.0);
        // A hard cone (beam = cutoff) has no ramp and no 0/0.
        assert_eq!(DeltaLight::falloff(c, c, 19f32.to_radians().cos()), 1.0);
        assert_eq!(DeltaLight::falloff(c, c, 21f32.to_radians().cos()), 0.0);
    }

    #[test]
    fn the_cone_integral_matches_quadrature() {
        for (c, b) in [(20f32, 15f32), (90.0, 10.0), (40.0, 40.0), (180.0, 0.0)] {
            let (c, b) = (c.to_radians(), b.to_radians());
            let n = 200_000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let t = (i as f64 + 0.5) / n as f64 * std::f64::consts::PI;
                    DeltaLight::falloff(c, b, t.cos() as f32) as f64 * t.sin()
                })
                .sum::<f64>()
                * std::f64::consts::PI
                / n as f64;
            let exact = DeltaLight::cone_integral(c, b) as f64;
            assert!((sum - exact).abs() < 1e-4, "{c} {b}: {sum} vs {exact}");
        }
    }

    #[test]
    fn a_spot_particle_carries_the_falloff_over_its_cone_pdf() {
        let spot = DeltaLight::Spot {
            position: Vec3::ZERO,
            axis: Vec3::Y,
            intensity: Rgb::ONE,
            cutoff: 0.5,
            beam_width: 0.3,
        };
        // Mean particle power = ∫ I falloff dω = 2π · cone integral.
        let mut rng = crate::rng::SplitMix64::new(3);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let e = spot.emit(&Aabb::default(), rng.vec2(), rng.vec2());
            if let Some(e) = e {
                assert!(e.dir.dot(Vec3::Y) >= 0.5f32.cos() - 1e-5);
                sum += e.beta.x as f64;
            }
        }
        let expect = 2.0 * std::f64::consts::PI * DeltaLight::cone_integral(0.5, 0.3) as f64;
        assert!(
            (sum / n as f64 / expect - 1.0).abs() < 0.01,
            "{sum} {expect}"
        );
    }
}
