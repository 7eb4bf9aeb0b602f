//! Starting light paths: a particle's origin, direction and throughput, from emissive triangles
//! (position by power, cosine-distributed direction) or from the environment by plane sampling
//! (Dammertz 2011, §6.4.2, and Dammertz & Keller 2009, "Plane Sampling for Light Paths from
//! the Environment Map"): the direction from the environment's importance map, the origin
//! uniform on a rectangle perpendicular to it that covers the scene's projection.
//!
//! Deviations: the rectangle is the scene box's projection (the thesis' listing 6.1) grown by
//! a relative 10⁻⁴ so rounding never uncovers the box's own faces; it is the tightest
//! axis-aligned rectangle in the direction's frame, not the bounding-sphere disk pbrt, Mitsuba
//! and LuxCore sample (for a cube seen along an axis the disk is π/2 times larger). The choice
//! between the environment and the triangles is the light sampler's (see
//! [`LightSampler::sample`]): half and half when both emit.
//!
//! Delta lights ([`crate::delta_light`]) start particles too: a point light's uniformly on
//! the sphere, a spot's uniformly in its cone, a directional light's on the same covering
//! rectangle as the environment's, all along its direction.

use crate::lights::{Chosen, LightSampler};
use crate::ray::spawn_ray;
use crate::sampling::{cosine_hemisphere, uniform_triangle};
use crate::{delta_light::DeltaLight, frame::Frame, triangle, Aabb, Ray, Rgb, Scene};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A point on an emissive triangle, chosen by power.
#[derive(Clone, Copy, Debug)]
pub struct EmitterPoint {
    /// The point.
    pub point: Vec3,
    /// Its rounding-error bound ([`triangle::point_with_error`]).
    pub error: Vec3,
    /// Unit front normal of the triangle.
    pub normal: Vec3,
    /// Radiance leaving the front (and the back, if `two_sided`).
    pub emission: Rgb,
    /// Emits from both faces.
    pub two_sided: bool,
    /// Area pdf of the point, including the probability of choosing this triangle and of
    /// choosing the triangles over the environment.
    pub pdf_area: f32,
}

impl EmitterPoint {
    /// Radiance leaving the point towards unit direction `w`.
    pub fn radiance_toward(&self, w: Vec3) -> Rgb {
        if self.two_sided || w.dot(self.normal) > 0.0 {
            self.emission
        } else {
            Rgb::ZERO
        }
    }
}

/// Where a light path starts.
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    /// Origin of the first ray (outside the scene's box for the environment).
    pub origin: Vec3,
    /// Rounding-error bound of the origin (zero for the environment).
    pub origin_error: Vec3,
    /// Normal to offset the origin along (the emitting side's; the direction itself for the
    /// environment, whose origin lies on no surface).
    pub normal: Vec3,
    /// Unit direction of the first ray.
    pub dir: Vec3,
    /// `Le · |cos| / (pdf_position · pdf_direction)`: the particle's throughput.
    pub beta: Rgb,
    /// The triangle point the path starts at, for connecting it to the camera directly; `None`
    /// for the environment and delta lights.
    pub point: Option<EmitterPoint>,
    /// The delta light the path starts at (which no camera sees), if it does.
    pub delta_light: Option<DeltaLight>,
    /// Pdf of the start: the triangle point's area pdf (choice of light included), or for the
    /// environment the plane point's, `1 / plane area`.
    pub pdf_position: f32,
    /// Solid-angle pdf of `dir` given the start (for the environment, of the direction, with
    /// the choice of the environment included). `beta = Le |cos| / (pdf_position · pdf_direction)`.
    pub pdf_direction: f32,
}

impl LightSampler {
    /// Chooses a point on an emissive triangle by power; `None` without emissive triangles or
    /// when `u_sel` chooses the environment.
    /// Also `None` when it chooses a delta light.
    pub fn sample_emitter_point(&self, u_sel: f32, u_pos: Vec2) -> Option<EmitterPoint> {
        if u_sel < self.env_prob {
            return None;
        }
        let Some((Chosen::Triangle(e), p_choice)) = self.choose(u_sel) else {
            return None;
        };
        let (b1, b2) = uniform_triangle(u_pos);
        let (point, error) = triangle::point_with_error(&e.vertices, b1, b2);
        let pdf_area = p_choice / e.area;
        (pdf_area > 0.0 && pdf_area.is_finite()).then_some(EmitterPoint {
            point,
            error,
            normal: e.normal,
            emission: e.emission,
            two_sided: e.two_sided,
            pdf_area,
        })
    }

    /// Starts a light path: from the environment with the light sampler's probability of
    /// choosing it (by plane sampling over `bounds`, the scene's box), else from a triangle.
    /// `None` if the chosen start cannot carry light.
    pub fn sample_emission(
        &self,
        scene: &Scene,
        bounds: &Aabb,
        u_sel: f32,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<Emission> {
        if u_sel < self.env_prob {
            let s = scene.environment.sample(u_dir)?;
            let dir = -s.dir;
            let (origin, area) = plane_sample(bounds, dir, u_pos)?;
            let beta = s.radiance * (area / (s.pdf * self.env_prob));
            return (beta.is_finite() && beta.max_element() > 0.0).then_some(Emission {
                origin,
                origin_error: Vec3::ZERO,
                normal: dir,
                dir,
                beta,
                point: None,
                delta_light: None,
                pdf_position: 1.0 / area,
                pdf_direction: s.pdf * self.env_prob,
            });
        }
        if let (Chosen::Delta(light), p_choice) = self.choose(u_sel)? {
            let e = light.emit(bounds, u_pos, u_dir)?;
            return Some(Emission {
                origin: e.origin,
                origin_error: Vec3::ZERO,
                normal: e.dir,
                dir: e.dir,
                beta: e.beta / p_choice,
                point: None,
                delta_light: Some(*light),
                pdf_position: e.pdf_position * p_choice,
                pdf_direction: e.pdf_direction,
            });
        }
        let p = self.sample_emitter_point(u_sel, u_pos)?;
        let (n, dir, cos) = cosine_emission(p.normal, p.two_sided, u_dir)?;
        // Le cos / (pdf_area · cos/π · face choice): the cosine cancels.
        let faces = if p.two_sided { 2.0 } else { 1.0 };
        let beta = p.emission * (PI * faces / p.pdf_area);
        (beta.is_finite() && beta.max_element() > 0.0).then_some(Emission {
            origin: p.point,
            origin_error: p.error,
            normal: n,
            dir,
            beta,
            point: Some(p),
            delta_light: None,
            pdf_position: p.pdf_area,
            pdf_direction: cos / (PI * faces),
        })
    }
}

impl Emission {
    /// The light path's first ray: offset off the emitter, or from the plane point as it is.
    pub fn ray(&self) -> Ray {
        if self.point.is_some() {
            spawn_ray(self.origin, self.origin_error, self.normal, self.dir)
        } else {
            Ray::new(self.origin, self.dir)
        }
    }
}

/// A cosine-distributed direction leaving a surface of front normal `normal` for `u` in
/// [0,1)²: the emitting side's normal, the unit direction and its cosine to that normal. A
/// two-sided emitter picks its face with the first coordinate, rescaled for the lobe. `None`
/// for a direction in the surface.
pub fn cosine_emission(normal: Vec3, two_sided: bool, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
    let (side, u) = if two_sided {
        if u.x < 0.5 {
            (1.0, Vec2::new(u.x * 2.0, u.y))
        } else {
            (-1.0, Vec2::new(u.x * 2.0 - 1.0, u.y))
        }
    } else {
        (1.0, u)
    };
    let n = normal * side;
    let local = cosine_hemisphere(u);
    if local.z <= 0.0 {
        return None;
    }
    Some((
        n,
        Frame::from_normal(n).to_world(local).normalize(),
        local.z,
    ))
}

/// A point uniform on a rectangle perpendicular to travel direction `dir` (unit) that covers
/// the projection of `bounds` along `dir`, upstream of the box, and the rectangle's area (its
/// reciprocal is the point's area pdf). `None` for an empty box or a rectangle of no area.
pub fn plane_sample(bounds: &Aabb, dir: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
    if bounds.is_empty() {
        return None;
    }
    let (a, b) = plane_extent(bounds, dir);
    let (du, dv) = (a.max.x - a.min.x, a.max.y - a.min.y);
    let area = du * dv;
    if area.is_nan() || area <= 0.0 || !area.is_finite() {
        return None;
    }
    let frame = Frame::from_normal(dir);
    let local = Vec3::new(a.min.x + du * u.x, a.min.y + dv * u.y, b);
    Some((frame.to_world(local), area))
}

/// The covering rectangle of [`plane_sample`] in the frame of `dir` (x, y: its bounds; z
/// unused) and the rectangle's distance along `dir`, before the box.
fn plane_extent(bounds: &Aabb, dir: Vec3) -> (Aabb, f32) {
    let frame = Frame::from_normal(dir);
    // Grown so that rounding in the frame change cannot leave the box's faces uncovered.
    let pad = bounds.extent().max_element().max(f32::MIN_POSITIVE) * 1e-4;
    let padded = Aabb::new(bounds.min - pad, bounds.max + pad);
    let mut rect = Aabb::default();
    let mut upstream = f32::INFINITY;
    for c in padded.corners() {
        let l = frame.to_local(c);
        rect = rect.grown(Vec3::new(l.x, l.y, 0.0));
        upstream = upstream.min(l.z);
    }
    (rect, upstream - pad)
}

/// The area of the rectangle [`plane_sample`] draws from for direction `dir`: the hit fraction
/// of its particles is the scene's projected area over this.
pub fn plane_area(bounds: &Aabb, dir: Vec3) -> f32 {
    let (a, _) = plane_extent(bounds, dir);
    (a.max.x - a.min.x) * (a.max.y - a.min.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rectangle_of_a_cube_seen_along_an_axis_is_its_face() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let area = plane_area(&b, Vec3::Z);
        assert!((area - 4.0).abs() < 1e-2, "{area}");
        // Along a diagonal the projected box is a hexagon inside a larger rectangle.
        let d = Vec3::ONE.normalize();
        assert!(plane_area(&b, d) > 4.0 * 3f32.sqrt());
    }

    #[test]
    fn plane_points_lie_upstream_and_project_into_the_box() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.5, 4.0));
        let mut rng = crate::rng::SplitMix64::new(5);
        for _ in 0..1000 {
            let dir = crate::sampling::uniform_sphere(rng.vec2());
            let (o, _) = plane_sample(&b, dir, Vec2::new(0.5, 0.5)).unwrap();
            // The centre of the rectangle projects onto the box's centre's line.
            let c = b.center();
            let off = (c - o) - dir * (c - o).dot(dir);
            assert!(off.length() < 1e-3 * 4.0, "{off}");
            assert!((c - o).dot(dir) > 0.0, "upstream");
        }
    }
}
