//! The viewer's orbit camera: a point on a sphere around a target, as yaw, pitch and
//! distance, turned into a [`Camera`] by a pure function.
//!
//! Conventions: +y is up (the scene format's); yaw 0 puts the camera on the target's +z side,
//! and positive yaw turns it towards +x; pitch is the elevation above the target's horizontal
//! plane, kept inside ±[`MAX_PITCH_DEG`] so the view never lines up with the up axis (where
//! `look_at` has no right vector). The distance stays within [`ZOOM_RANGE`] times the starting
//! one, so the wheel can neither pass through the target nor lose the scene.

use rt_core::glam::Vec3;
use rt_core::Camera;

/// Largest elevation either way, in degrees.
pub const MAX_PITCH_DEG: f32 = 89.0;
/// Closest and farthest distance, as multiples of the starting distance.
pub const ZOOM_RANGE: (f32, f32) = (0.05, 20.0);
/// Radians turned per pixel dragged.
pub const RADIANS_PER_PIXEL: f32 = 0.01;
/// Distance factor per wheel line (zooming in by one line divides the distance by it).
pub const ZOOM_PER_LINE: f32 = 1.1;

/// Where the orbit camera is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The point looked at and turned about.
    pub target: Vec3,
    /// Radians about +y.
    pub yaw: f32,
    /// Radians of elevation, within ±[`MAX_PITCH_DEG`].
    pub pitch: f32,
    /// Distance from the target.
    pub distance: f32,
    /// The distance it started at (the zoom limits are relative to it).
    pub start_distance: f32,
}

impl Orbit {
    /// The orbit through `camera`'s position about its look-at point, which the camera keeps
    /// as its focus distance along the view direction (the scene format's default focus
    /// distance is the look-at distance).
    pub fn from_camera(camera: &Camera) -> Orbit {
        let distance = if camera.focus_distance.is_finite() && camera.focus_distance > 0.0 {
            camera.focus_distance
        } else {
            1.0
        };
        let target = camera.position + camera.forward * distance;
        let offset = (camera.position - target) / distance;
        let max = MAX_PITCH_DEG.to_radians();
        Orbit {
            target,
            yaw: offset.x.atan2(offset.z),
            pitch: offset.y.clamp(-1.0, 1.0).asin().clamp(-max, max),
            distance,
            start_distance: distance,
        }
    }

    /// Turned by a mouse drag of `(dx, dy)` pixels: right turns the camera left about the
    /// target (the scene follows the mouse), down lowers it; the pitch stays in its range.
    pub fn dragged(self, dx: f32, dy: f32) -> Orbit {
        let max = MAX_PITCH_DEG.to_radians();
        Orbit {
            yaw: self.yaw - dx * RADIANS_PER_PIXEL,
            pitch: (self.pitch + dy * RADIANS_PER_PIXEL).clamp(-max, max),
            ..self
        }
    }

    /// Zoomed by `lines` wheel lines (positive: closer), within [`ZOOM_RANGE`].
    pub fn zoomed(self, lines: f32) -> Orbit {
        let (near, far) = ZOOM_RANGE;
        let distance = (self.distance * ZOOM_PER_LINE.powf(-lines))
            .clamp(near * self.start_distance, far * self.start_distance);
        Orbit { distance, ..self }
    }

    /// The camera's position.
    pub fn position(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }

    /// A pinhole camera at the orbit's position looking at its target, with `like`'s name and
    /// vertical field of view, at `width` x `height` pixels.
    pub fn camera(&self, like: &Camera, width: u32, height: u32) -> Camera {
        Camera::look_at(
            like.name.clone(),
            self.position(),
            self.target,
            Vec3::Y,
            like.fov_y_deg,
            width,
            height,
            0.0,
            self.distance,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Camera {
        Camera::look_at(
            "main",
            Vec3::new(0.0, 1.6, 5.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::Y,
            45.0,
            320,
            240,
            0.0,
            (Vec3::new(0.0, 1.6, 5.0) - Vec3::new(0.0, 0.5, 0.0)).length(),
        )
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4
    }

    #[test]
    fn the_orbit_starts_at_the_scene_camera() {
        let c = scene_camera();
        let o = Orbit::from_camera(&c);
        assert!(close(o.target, Vec3::new(0.0, 0.5, 0.0)), "{:?}", o.target);
        let v = o.camera(&c, 256, 256);
        assert!(close(v.position, c.position), "{:?}", v.position);
        assert!(close(v.forward, c.forward));
        assert_eq!((v.width, v.height, v.fov_y_deg), (256, 256, 45.0));
    }

    #[test]
    fn angles_place_the_camera_on_the_sphere_looking_at_the_target() {
        let o = Orbit {
            target: Vec3::new(1.0, 2.0, 3.0),
            yaw: std::f32::consts::FRAC_PI_2,
            pitch: 0.0,
            distance: 2.0,
            start_distance: 2.0,
        };
        // Yaw 90°: on the +x side.
        assert!(
            close(o.position(), Vec3::new(3.0, 2.0, 3.0)),
            "{:?}",
            o.position()
        );
        let o = Orbit {
            yaw: 0.0,
            pitch: 30f32.to_radians(),
            ..o
        };
        let p = o.position();
        assert!((p.y - 2.0 - 2.0 * 0.5).abs() < 1e-5 && p.x == 1.0, "{p:?}");
        assert!((p.z - 3.0 - 2.0 * 30f32.to_radians().cos()).abs() < 1e-5);
        let c = o.camera(&scene_camera(), 8, 8);
        assert!(close(c.forward, (o.target - p).normalize()));
        // The image's right is horizontal.
        assert!(c.right.y.abs() < 1e-6);
    }

    #[test]
    fn dragging_turns_and_pitch_stays_clamped() {
        let o = Orbit::from_camera(&scene_camera());
        let turned = o.dragged(100.0, 0.0);
        assert!((turned.yaw - (o.yaw - 100.0 * RADIANS_PER_PIXEL)).abs() < 1e-6);
        assert_eq!(turned.distance, o.distance);
        let max = MAX_PITCH_DEG.to_radians();
        let up = o.dragged(0.0, 1e6);
        assert_eq!(up.pitch, max);
        let down = o.dragged(0.0, -1e6);
        assert_eq!(down.pitch, -max);
        // At the limit the camera still has a proper frame.
        for o in [up, down] {
            let c = o.camera(&scene_camera(), 8, 8);
            assert!(c.forward.is_finite() && c.right.is_finite() && c.up.is_finite());
            assert!((c.right.length() - 1.0).abs() < 1e-4);
            assert!(c.forward.dot(Vec3::Y).abs() < 0.9999);
        }
    }

    #[test]
    fn zoom_moves_along_the_view_and_stops_at_its_limits() {
        let o = Orbit::from_camera(&scene_camera());
        let d0 = o.distance;
        let closer = o.zoomed(1.0);
        assert!((closer.distance - d0 / ZOOM_PER_LINE).abs() < 1e-5);
        assert!(close(
            (closer.position() - o.target).normalize(),
            (o.position() - o.target).normalize()
        ));
        let mut far = o;
        let mut near = o;
        for _ in 0..1000 {
            far = far.zoomed(-3.0);
            near = near.zoomed(3.0);
        }
        assert!((far.distance - ZOOM_RANGE.1 * d0).abs() < 1e-3 * d0);
        assert!((near.distance - ZOOM_RANGE.0 * d0).abs() < 1e-5 * d0);
        // The limits hold relative to the start, not the current distance.
        assert_eq!(near.zoomed(-1.0).start_distance, d0);
    }
}
