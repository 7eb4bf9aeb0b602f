//! Which camera renders, and at what size. Experiments render small images so that a grid of
//! runs and its references fit in minutes; [`ImageSize`] resizes the film without changing the
//! view.

use crate::SessionError;
use rt_core::{Camera, Scene};
use std::path::Path;

/// Largest image side a size override may ask for ([`rt_core::limits::MAX_IMAGE_SIDE`], the
/// scene format's own limit).
pub const MAX_SIDE: u32 = rt_core::limits::MAX_IMAGE_SIDE;

/// The camera named `name`, or the scene's first one. Errors name `scene_path`.
pub fn pick_camera<'s>(
    scene: &'s Scene,
    scene_path: &Path,
    name: Option<&str>,
) -> Result<&'s Camera, SessionError> {
    scene.camera(name).ok_or_else(|| match name {
        Some(name) => SessionError::NoSuchCamera {
            file: scene_path.to_path_buf(),
            name: name.to_string(),
            cameras: scene.cameras.iter().map(|c| c.name.clone()).collect(),
        },
        None => SessionError::NoCamera {
            file: scene_path.to_path_buf(),
        },
    })
}

/// How big to render, relative to the camera's own resolution.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImageSize {
    /// The camera's resolution.
    #[default]
    Native,
    /// Exactly this width and height. The field of view stays vertical, so a different aspect
    /// ratio shows more or less to the sides.
    Pixels(u32, u32),
    /// The camera's resolution times this factor, rounded, at least one pixel.
    Scale(f64),
}

impl ImageSize {
    /// Checks the values; `what` names where they came from for the message.
    pub fn validate(&self, what: &str) -> Result<(), SessionError> {
        let bad = |reason: String| {
            Err(SessionError::BadSize {
                what: what.to_string(),
                reason,
            })
        };
        match *self {
            ImageSize::Native => {}
            ImageSize::Pixels(w, h) => {
                if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
                    return bad(format!(
                        "resolution must be between 1 and {MAX_SIDE} per side, got {w}x{h}"
                    ));
                }
            }
            ImageSize::Scale(s) => {
                if !(s.is_finite() && s > 0.0 && s <= 16.0) {
                    return bad(format!("scale must be in (0, 16], got {s}"));
                }
            }
        }
        Ok(())
    }

    /// `camera` resized. Only the film changes: position, orientation, vertical field of view
    /// and lens stay, so a scaled image shows the same view.
    pub fn apply(&self, camera: &Camera) -> Camera {
        let (w, h) = match *self {
            ImageSize::Native => (camera.width, camera.height),
            ImageSize::Pixels(w, h) => (w, h),
            ImageSize::Scale(s) => {
                let side = |n: u32| ((n as f64 * s).round() as u32).clamp(1, MAX_SIDE);
                (side(camera.width), side(camera.height))
            }
        };
        let mut c = camera.clone();
        c.width = w;
        c.height = h;
        c
    }
}

/// `WxH` (or `WXH`, spaces around the numbers allowed) as two numbers, not yet checked
/// against any limit; `None` when it is not of that form.
pub fn split_size(s: &str) -> Option<(u32, u32)> {
    let (w, h) = s.split_once(['x', 'X'])?;
    Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
}

/// Parses a tile grid `WxH` (`render plan --tiles 4x2`): both positive.
pub fn parse_tiles(s: &str) -> Result<(u32, u32), String> {
    split_size(s)
        .filter(|&(w, h)| w > 0 && h > 0)
        .ok_or_else(|| format!("--tiles must be WxH with positive integers, got `{s}`"))
}

/// Parses `WxH` (`--resolution 128x96`).
pub fn parse_resolution(s: &str) -> Result<(u32, u32), SessionError> {
    let (w, h) = split_size(s).ok_or_else(|| SessionError::BadSize {
        what: "--resolution".into(),
        reason: format!("expected WIDTHxHEIGHT such as 128x96, got \"{s}\""),
    })?;
    ImageSize::Pixels(w, h).validate("--resolution")?;
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::glam::Vec3;

    fn cam() -> Camera {
        Camera::look_at("c", Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 512, 384, 0.0, 1.0)
    }

    #[test]
    fn image_size_overrides() {
        let c = cam();
        let s = ImageSize::Scale(0.25).apply(&c);
        assert_eq!((s.width, s.height), (128, 96));
        assert_eq!(s.fov_y_deg, c.fov_y_deg);
        let p = ImageSize::Pixels(32, 32).apply(&c);
        assert_eq!((p.width, p.height), (32, 32));
        let tiny = ImageSize::Scale(0.0001).apply(&c);
        assert_eq!((tiny.width, tiny.height), (1, 1));
        assert!(ImageSize::Scale(0.0).validate("x").is_err());
        assert!(ImageSize::Scale(f64::NAN).validate("x").is_err());
        assert!(ImageSize::Pixels(0, 4).validate("x").is_err());
        assert!(ImageSize::Pixels(4, 4).validate("x").is_ok());
    }

    #[test]
    fn resolution_flag() {
        assert_eq!(parse_resolution("128x96").unwrap(), (128, 96));
        assert_eq!(parse_resolution("8X8").unwrap(), (8, 8));
        for bad in ["128", "x96", "0x4", "ax4", "4x4x4"] {
            assert!(parse_resolution(bad).is_err(), "{bad}");
        }
    }
}
