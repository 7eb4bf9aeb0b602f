//! Automatic views of a bare mesh, which has no camera of its own: from outside for scanned
//! objects, from inside for rooms. `render bench-accel` aims its primary rays with them and the
//! stress suite looks into the rooms it renders.

use rt_core::{glam::Vec3, Aabb, Accel, Camera, Ray};

/// Width and height of the automatic views.
pub const VIEW_SIDE: u32 = 512;

/// A camera looking at the centre of the triangles' bounding box from the fixed diagonal
/// (1, 0.7, 1.3), just far enough for every vertex to be in its 40° field of view.
pub fn outside_view(triangles: &[[Vec3; 3]], bounds: &Aabb) -> Camera {
    let centre = bounds.center();
    let fov = 40.0f32;
    let tan_half = (0.5 * fov).to_radians().tan();
    let back = Vec3::new(1.0, 0.7, 1.3).normalize();
    let right = (-back).cross(Vec3::Y).normalize();
    let up = right.cross(-back);
    let dist = triangles
        .iter()
        .flatten()
        .map(|&p| {
            let v = p - centre;
            let lateral = v.dot(right).abs().max(v.dot(up).abs());
            v.dot(back) + lateral / tan_half
        })
        .fold(f32::MIN_POSITIVE, f32::max)
        * 1.05;
    Camera::look_at(
        "auto",
        centre + back * dist,
        centre,
        Vec3::Y,
        fov,
        VIEW_SIDE,
        VIEW_SIDE,
        0.0,
        dist,
    )
}

/// The automatic camera and light of a room: from the middle of the bounds at 60 % of the
/// height, backed off along the long horizontal axis by 70 % of the free distance behind
/// (measured with `reference`), looking down that axis and a little down, 60° field of view;
/// the light under the middle of the ceiling (90 % of the height).
pub fn inside_view(bounds: &Aabb, reference: &dyn Accel) -> (Camera, Vec3) {
    let (lo, centre, ext) = (bounds.min, bounds.center(), bounds.extent());
    let axis = if ext.x >= ext.z { Vec3::X } else { Vec3::Z };
    let mid = Vec3::new(centre.x, lo.y + 0.6 * ext.y, centre.z);
    let behind = reference
        .intersect(&Ray::new(mid, -axis), f32::INFINITY)
        .map_or(0.5 * ext.dot(axis), |h| h.t);
    let eye = mid - axis * (0.7 * behind);
    let target = Vec3::new(centre.x, lo.y + 0.3 * ext.y, centre.z) + axis * (0.5 * behind);
    let camera = Camera::look_at(
        "inside",
        eye,
        target,
        Vec3::Y,
        60.0,
        VIEW_SIDE,
        VIEW_SIDE,
        0.0,
        (target - eye).length(),
    );
    (camera, Vec3::new(centre.x, lo.y + 0.9 * ext.y, centre.z))
}
