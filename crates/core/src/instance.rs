//! Instances: a geometry (a [`Prototype`], in its own object space) placed in the world by a
//! transform that may change over time ([`Motion`]).
//!
//! The scene keeps every instance's triangles in world space too, at the scene's current time,
//! in its flat arrays (`Scene::triangles` and the per-triangle attributes, one contiguous range
//! per instance, after the static geometry). Everything that reads the scene's triangles (flat
//! acceleration structures, shading, the light table) therefore sees the instances as plain
//! geometry, while two-level structures read the prototypes and the transforms and never
//! rebuild an object's hierarchy when it moves. [`place_triangle`] is the one function that
//! maps a prototype triangle into the world, so the flat copy and anything computed from the
//! prototype agree bit for bit.
//!
//! The flat copy costs the instances' triangles once more: instancing here is for rigid
//! motion, not for memory (a thousand copies of a mesh take a thousand copies).

use crate::animation::Motion;
use crate::ray::gamma;
use crate::transform::Transform;
use glam::{Mat3, Vec2, Vec3};

/// A geometry in its own object space, placed by instances.
#[derive(Clone, Debug, Default)]
pub struct Prototype {
    /// Name of the geometry in the scene file.
    pub name: String,
    /// Object-space vertex positions, three per triangle.
    pub triangles: Vec<[Vec3; 3]>,
    /// Per-triangle vertex normals (object space, unit), or empty when none has any.
    pub normals: Vec<Option<[Vec3; 3]>>,
    /// Per-triangle texture coordinates, or empty when none has any.
    pub uvs: Vec<Option<[Vec2; 3]>>,
    /// Material index of every triangle.
    pub material_ids: Vec<u32>,
}

/// A prototype placed in the world.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Name (an `[[instance]]`'s, or an animated geometry's own).
    pub name: String,
    /// Index into `Scene::prototypes`.
    pub prototype: u32,
    /// The fixed placement (the `[[instance]]`'s `transform`); the motion applies after it.
    pub base: Transform,
    /// Keyframed motion, if animated.
    pub motion: Option<Motion>,
    /// Object-to-world transform at the scene's current time.
    pub transform: Transform,
    /// First triangle of its world copy in the scene's flat arrays.
    pub first: u32,
    /// Number of triangles.
    pub count: u32,
}

impl Instance {
    /// The object-to-world transform at time `t`.
    pub fn transform_at(&self, t: f32) -> Transform {
        match &self.motion {
            Some(m) => m.at(t).then(&self.base),
            None => self.base,
        }
    }

    /// The object-to-world matrix at time `t` (the matrix of [`Instance::transform_at`]).
    pub fn matrix_at(&self, t: f32) -> glam::Mat4 {
        match &self.motion {
            Some(m) => m.matrix_at(t) * self.base.m,
            None => self.base.m,
        }
    }

    /// True if the instance is animated and its keys span part of the interval `(t0, t1)`:
    /// it may be somewhere else at some time of the interval than at `t0`.
    pub fn moves_during(&self, t0: f32, t1: f32) -> bool {
        self.is_animated() && self.motion.as_ref().is_some_and(|m| m.spans(t0, t1))
    }

    /// True if the instance moves (its transform depends on time).
    pub fn is_animated(&self) -> bool {
        self.motion.as_ref().is_some_and(|m| !m.is_static())
    }
}

/// Triangle `v` of a prototype in the world under `t`, with winding reversed when `t` mirrors
/// (so front faces stay front faces); the same swap applies to the triangle's attributes
/// ([`place_attributes`]).
#[inline]
pub fn place_triangle(t: &Transform, flip: bool, v: &[Vec3; 3]) -> [Vec3; 3] {
    let mut w = v.map(|p| t.point(p));
    if flip {
        w.swap(1, 2);
    }
    w
}

/// A triangle's vertex attributes (normals through the inverse transpose, normalised; uvs
/// unchanged) in the world under `t`, swapped like [`place_triangle`] when `t` mirrors.
#[inline]
pub fn place_attributes(
    t: &Transform,
    flip: bool,
    normals: Option<[Vec3; 3]>,
    uvs: Option<[Vec2; 3]>,
) -> (Option<[Vec3; 3]>, Option<[Vec2; 3]>) {
    let mut n = normals.map(|n| n.map(|d| t.normal(d)));
    let mut uv = uvs;
    if flip {
        if let Some(n) = &mut n {
            n.swap(1, 2);
        }
        if let Some(uv) = &mut uv {
            uv.swap(1, 2);
        }
    }
    (n, uv)
}

/// Per-axis bound on how far a world point computed from a prototype's triangle through `t`
/// may lie from the exact image of that triangle, and on the error of mapping such a point
/// back into object space and out again: what a spawned ray's offset must add for a two-level
/// structure, which intersects the object-space triangle with an inverse-transformed ray, to
/// agree with the flat copy about which side of the surface the origin is on. `object` is the
/// triangle in object space, `p` the world point.
///
/// Forward: each world coordinate is a 3-term dot product plus a translation, `γ₃(|M||v| + |t|)`
/// per vertex. Back and forth: the inverse map's rounding `γ₃(|M⁻¹||p| + |t⁻¹|)` in object
/// space, carried out by `|M|`. Non-uniform scale makes `|M||M⁻¹|` large, and the bound with
/// it; for rigid motions both terms are a few ULPs of the coordinates.
pub fn placement_error(t: &Transform, object: &[Vec3; 3], p: Vec3) -> Vec3 {
    let m = Mat3::from_mat4(t.m);
    let abs = |a: Mat3| Mat3::from_cols(a.x_axis.abs(), a.y_axis.abs(), a.z_axis.abs());
    let m_abs = abs(m);
    let translate = t.m.w_axis.truncate().abs();
    let v_max = object[0].abs().max(object[1].abs()).max(object[2].abs());
    let forward = gamma(3) * (m_abs * v_max + translate);
    // The inverse's linear part is the transpose of the normal matrix (no 4×4 inverse per
    // hit), and `|M⁻¹ t| ≤ |M⁻¹| |t|` bounds its translation.
    let inv_abs = abs(t.normal.transpose());
    let back = m_abs * (gamma(3) * (inv_abs * (p.abs() + translate)));
    // Two more roundings of each sum (the bound itself and its addition to the point's).
    (forward + back) * (1.0 + gamma(2))
}

impl crate::content_hash::ContentHash for Prototype {
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Prototype {
            name,
            triangles,
            normals,
            uvs,
            material_ids,
        } = self;
        name.content_hash(out);
        triangles.content_hash(out);
        normals.content_hash(out);
        uvs.content_hash(out);
        material_ids.content_hash(out);
    }
}

impl crate::content_hash::ContentHash for Instance {
    /// The placement and the motion; the current transform follows from them and the time.
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Instance {
            name,
            prototype,
            base,
            motion,
            transform: _,
            first,
            count,
        } = self;
        name.content_hash(out);
        prototype.content_hash(out);
        base.m.to_cols_array().content_hash(out);
        motion.content_hash(out);
        first.content_hash(out);
        count.content_hash(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::Key;

    #[test]
    fn mirrored_placement_keeps_the_front_face() {
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let n_before = (v[1] - v[0]).cross(v[2] - v[0]);
        let t = Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(-1.0, 1.0, 1.0));
        let w = place_triangle(&t, t.flips_handedness(), &v);
        let n_after = (w[1] - w[0]).cross(w[2] - w[0]);
        // The mirrored triangle's front still faces the mirrored normal's way.
        assert!(n_after.dot(t.normal(n_before)) > 0.0);
    }

    #[test]
    fn motion_applies_after_the_base_placement() {
        let motion = Motion::new(vec![
            Key::from_trs(0.0, Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
            Key::from_trs(1.0, Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::ONE),
        ])
        .unwrap();
        let i = Instance {
            name: "i".into(),
            prototype: 0,
            base: Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::splat(2.0)),
            motion: Some(motion),
            transform: Transform::default(),
            first: 0,
            count: 0,
        };
        // Scaled first (x 1 -> 2), then moved by the key (z + 1 at t = 0.5).
        let p = i.transform_at(0.5).point(Vec3::X);
        assert!((p - Vec3::new(2.0, 0.0, 1.0)).length() < 1e-6);
        assert!(i.is_animated());
    }

    #[test]
    fn the_placement_error_grows_with_non_uniform_scale() {
        let v = [
            Vec3::ONE,
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(1.0, 2.0, 1.0),
        ];
        let rigid = Transform::from_trs(Vec3::splat(10.0), Vec3::new(10.0, 20.0, 30.0), Vec3::ONE);
        let squashed = Transform::from_trs(
            Vec3::splat(10.0),
            Vec3::new(10.0, 20.0, 30.0),
            Vec3::new(1000.0, 1.0, 0.001),
        );
        let p = rigid.point(v[0]);
        let e_rigid = placement_error(&rigid, &v, p);
        assert!(e_rigid.max_element() < 1e-4 && e_rigid.min_element() > 0.0);
        let e_squashed = placement_error(&squashed, &v, squashed.point(v[0]));
        assert!(e_squashed.max_element() > 10.0 * e_rigid.max_element());
    }
}
