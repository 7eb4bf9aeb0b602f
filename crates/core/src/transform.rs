//! Affine transforms for placing geometry.

use glam::{Mat3, Mat4, Quat, Vec3};

/// An affine transform with the matrix that transforms normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Point transform.
    pub m: Mat4,
    /// Normal transform: inverse transpose of the linear part.
    pub normal: Mat3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::from_mat4(Mat4::IDENTITY)
    }
}

impl Transform {
    /// From a matrix (must be invertible).
    pub fn from_mat4(m: Mat4) -> Self {
        Self {
            m,
            normal: Mat3::from_mat4(m).inverse().transpose(),
        }
    }

    /// Scale, then rotate about x, then y, then z (degrees), then translate.
    pub fn from_trs(translate: Vec3, rotate_deg: Vec3, scale: Vec3) -> Self {
        let r = Quat::from_rotation_z(rotate_deg.z.to_radians())
            * Quat::from_rotation_y(rotate_deg.y.to_radians())
            * Quat::from_rotation_x(rotate_deg.x.to_radians());
        Self::from_mat4(Mat4::from_scale_rotation_translation(scale, r, translate))
    }

    /// Transforms a point.
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.m.transform_point3(p)
    }

    /// Transforms a normal (result normalised).
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.normal * n).normalize_or_zero()
    }

    /// True if the transform mirrors (negative determinant): triangle winding must then be
    /// reversed to keep front faces in front.
    pub fn flips_handedness(&self) -> bool {
        Mat3::from_mat4(self.m).determinant() < 0.0
    }

    /// Composition: `self` after `inner`.
    pub fn then(&self, inner: &Transform) -> Transform {
        Self::from_mat4(self.m * inner.m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_order_is_x_then_y_then_z() {
        let t = Transform::from_trs(Vec3::ZERO, Vec3::new(90.0, 90.0, 0.0), Vec3::ONE);
        // +y rotated 90° about x goes to +z; then 90° about y takes +z to +x.
        assert!((t.point(Vec3::Y) - Vec3::X).length() < 1e-5);
        let t = Transform::from_trs(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::splat(2.0));
        assert!((t.point(Vec3::ONE) - Vec3::new(3.0, 4.0, 5.0)).length() < 1e-6);
        assert!(
            Transform::from_trs(Vec3::ZERO, Vec3::ZERO, Vec3::new(-1.0, 1.0, 1.0))
                .flips_handedness()
        );
    }
}
