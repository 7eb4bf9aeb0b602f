//! The shading-normal factor of importance transport, shared by the techniques that trace
//! paths from the lights.

use rt_core::glam::Vec3;

/// The cosine factor of importance transport with shading normals (Veach 1997, eq. 5.17):
/// `|wo·ns| |wi·ng| / |wo·ng|` in place of the radiance transport's `|wi·ns|`, where `wo`
/// points to the light side and `wi` onward (to the camera for a connection). Equal to
/// `|wi·n|` when the normals agree.
#[inline]
pub(crate) fn adjoint_cos(wo: Vec3, wi: Vec3, ns: Vec3, ng: Vec3) -> f32 {
    let wo_ng = wo.dot(ng).abs();
    if wo_ng <= 0.0 {
        return 0.0;
    }
    wo.dot(ns).abs() * wi.dot(ng).abs() / wo_ng
}
