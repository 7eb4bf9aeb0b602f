//! Pinhole and thin-lens cameras.

use crate::{animation::CameraKey, pixel_filter::PixelFilter, sampling::concentric_disk, Ray};
use glam::{Vec2, Vec3};

/// A perspective camera. Image right is `forward × up` (right-handed: looking down -z with +y
/// up, +x is to the right) and row 0 of the image is the top.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Name from the scene file.
    pub name: String,
    /// Centre of projection (centre of the lens).
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit image-right direction.
    pub right: Vec3,
    /// Unit image-up direction (orthogonal to `forward` and `right`).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Thin-lens radius in scene units; 0 is a pinhole.
    pub aperture: f32,
    /// Distance along `forward` of the plane in focus.
    pub focus_distance: f32,
    /// Where in its pixel a sample lands ([`PixelFilter::film_position`]); box by default.
    pub filter: PixelFilter,
    /// The part of a larger image this camera renders (a crop window), or `None` for the
    /// whole image. The field of view is the larger image's; `width × height` is the crop's.
    pub crop: Option<Crop>,
    /// Near clipping distance along the view axis: primary rays start on the plane at this
    /// depth in front of the lens and light paths connect only to points beyond it (Mitsuba's
    /// `near_clip`); 0 (the default) clips nothing.
    pub near_clip: f32,
    tan_half: f32,
}

/// A crop window: the rectangle `[x0, x1) × [y0, y1)` of the full image, as fractions of its
/// width and height (row 0 at the top), so that a resized camera keeps its window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop {
    /// Left edge, fraction of the full width.
    pub x0: f32,
    /// Top edge, fraction of the full height.
    pub y0: f32,
    /// Right edge (exclusive).
    pub x1: f32,
    /// Bottom edge (exclusive).
    pub y1: f32,
}

impl Crop {
    /// The window `[x, x + w) × [y, y + h)` in pixels of a `full_w × full_h` image, or `None`
    /// if it is empty or does not fit.
    pub fn from_pixels(x: u32, y: u32, w: u32, h: u32, full_w: u32, full_h: u32) -> Option<Crop> {
        let fits = w > 0 && h > 0 && x.checked_add(w)? <= full_w && y.checked_add(h)? <= full_h;
        fits.then(|| Crop {
            x0: x as f32 / full_w as f32,
            y0: y as f32 / full_h as f32,
            x1: (x + w) as f32 / full_w as f32,
            y1: (y + h) as f32 / full_h as f32,
        })
    }
}

impl Camera {
    /// Builds a camera looking from `position` at `look_at`. The caller validates the inputs
    /// (`rt-scene` does): distinct points, `up` not parallel to the view direction, fov in (0,180).
    #[allow(clippy::too_many_arguments)]
    pub fn look_at(
        name: impl Into<String>,
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
        aperture: f32,
        focus_distance: f32,
    ) -> Self {
        let forward = (look_at - position).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Self {
            name: name.into(),
            position,
            forward,
            right,
            up,
            fov_y_deg,
            width,
            height,
            aperture,
            focus_distance,
            filter: PixelFilter::Box,
            crop: None,
            near_clip: 0.0,
            tan_half: (fov_y_deg.to_radians() * 0.5).tan(),
        }
    }

    /// The window of the full image this camera renders ([0, 1]² without a crop).
    #[inline]
    fn window(&self) -> Crop {
        self.crop.unwrap_or(Crop {
            x0: 0.0,
            y0: 0.0,
            x1: 1.0,
            y1: 1.0,
        })
    }

    /// Width over height of the full image (the crop's own aspect without a crop).
    #[inline]
    fn full_aspect(&self) -> f32 {
        let c = self.window();
        (self.width as f32 / (c.x1 - c.x0)) / (self.height as f32 / (c.y1 - c.y0))
    }

    /// The full image's height in pixels (this camera's height without a crop).
    #[inline]
    fn full_height(&self) -> f32 {
        let c = self.window();
        self.height as f32 / (c.y1 - c.y0)
    }

    /// The side of one pixel on the image plane at distance 1 (pixels are square).
    #[inline]
    pub fn pixel_size(&self) -> f32 {
        2.0 * self.tan_half / self.full_height()
    }

    /// Position on the full image in [0, 1]² (x right, y down) of raster position `film`.
    #[inline]
    fn full_image_position(&self, film: Vec2) -> Vec2 {
        match &self.crop {
            None => film / Vec2::new(self.width as f32, self.height as f32),
            Some(c) => Vec2::new(
                c.x0 + film.x / self.width as f32 * (c.x1 - c.x0),
                c.y0 + film.y / self.height as f32 * (c.y1 - c.y0),
            ),
        }
    }

    /// The same view rendering a `width × height` image (the field of view stays vertical).
    pub fn resized(&self, width: u32, height: u32) -> Camera {
        Camera {
            width,
            height,
            name: self.name.clone(),
            filter: self.filter.clone(),
            ..*self
        }
    }

    /// The point of the lens that lens sample `lens` in [0,1)² picks (the centre of
    /// projection for a pinhole): where a primary ray leaves the lens, before any near clip.
    #[inline]
    pub fn lens_point(&self, lens: Vec2) -> Vec3 {
        if self.is_pinhole() {
            return self.position;
        }
        let l = concentric_disk(lens) * self.aperture;
        self.position + self.right * l.x + self.up * l.y
    }

    /// True for a pinhole (aperture 0): [`Camera::generate_ray`] ignores its lens sample, so
    /// the render driver does not draw one.
    #[inline]
    pub fn is_pinhole(&self) -> bool {
        self.aperture <= 0.0
    }

    /// Primary ray through continuous raster position `film` (x right, y down, in pixels) with
    /// lens sample `lens` in [0,1)² (ignored by a pinhole). The direction is normalised.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Ray {
        self.ray_from(
            self.position,
            [self.forward, self.right, self.up],
            self.tan_half,
            film,
            lens,
        )
    }

    /// [`Camera::generate_ray`] from the pose and field of view of keyframe `key` (this
    /// camera's resolution, aperture and focus distance), at shutter time `time`: a moving
    /// camera's ray during the shutter, without building a camera per sample. A degenerate
    /// blend of two keys (the position crossing the look-at point) keeps this camera's pose.
    #[inline]
    pub fn generate_ray_at(&self, key: &CameraKey, time: f32, film: Vec2, lens: Vec2) -> Ray {
        let forward = (key.look_at - key.position).normalize();
        let right = forward.cross(key.up).normalize();
        let up = right.cross(forward);
        let ray = if forward.is_finite() && right.is_finite() && up.is_finite() {
            let tan_half = (key.fov.to_radians() * 0.5).tan();
            self.ray_from(key.position, [forward, right, up], tan_half, film, lens)
        } else {
            self.generate_ray(film, lens)
        };
        ray.at_time(time)
    }

    #[inline]
    fn ray_from(
        &self,
        position: Vec3,
        [forward, right, up]: [Vec3; 3],
        tan_half: f32,
        film: Vec2,
        lens: Vec2,
    ) -> Ray {
        let aspect = self.full_aspect();
        let f = self.full_image_position(film);
        let sx = (2.0 * f.x - 1.0) * tan_half * aspect;
        let sy = (1.0 - 2.0 * f.y) * tan_half;
        let d = forward + right * sx + up * sy;
        if self.is_pinhole() {
            // `d` has depth 1 along the view axis, so `d · near` lies on the near plane.
            let o = if self.near_clip > 0.0 {
                position + d * self.near_clip
            } else {
                position
            };
            return Ray::new(o, d.normalize());
        }
        let focus = position + d * self.focus_distance;
        let l = concentric_disk(lens) * self.aperture;
        let o = position + right * l.x + up * l.y;
        let dir = (focus - o).normalize();
        if self.near_clip > 0.0 {
            // As Mitsuba's thin lens: the ray starts where it crosses the near plane.
            return Ray::new(o + dir * (self.near_clip / dir.dot(forward)), dir);
        }
        Ray::new(o, dir)
    }

    /// Solid-angle pdf with which [`Camera::generate_ray`], at a raster position uniform over
    /// the whole image, produces unit direction `dir` (from a pinhole or from the lens point
    /// the ray leaves): `1 / (A_image · cos³θ)`, `A_image` the image's area on the plane at
    /// distance 1 and `θ` the angle to the view direction (for a thin lens too: the focus plane
    /// is at a fixed depth, so the lens point does not change the measure). Zero behind the
    /// camera. Bidirectional MIS compares camera and light strategies with it; it does not test
    /// whether `dir` is inside the image (callers only ask about directions that are).
    pub fn pdf_direction(&self, dir: Vec3) -> f32 {
        let cos = dir.dot(self.forward);
        if cos.is_nan() || cos <= 0.0 {
            return 0.0;
        }
        let image_area = self.pixel_size().powi(2) * (self.width as f32 * self.height as f32);
        1.0 / (image_area * cos * cos * cos)
    }

    /// Signed circle of confusion of world point `p`, in pixels: the radius of the disc the
    /// thin lens blurs `p` into on the image, positive behind the focal plane, negative in
    /// front of it, zero on it and for a pinhole.
    ///
    /// With `z` the depth of `p` along the view axis, `z_f` the focus distance and `A` the lens
    /// radius, the rays from the lens disc through `p` cross the focal plane in a disc of radius
    /// `A·|z − z_f| / z` (similar triangles: the lens point `l` maps to `l·(1 − z_f/z)`). A pixel
    /// on the focal plane is `z_f · 2·tan(fov/2) / height` wide, so the radius in pixels is
    /// `A·(z − z_f)·height / (2·tan(fov/2)·z_f·z)`, signed by `z − z_f`. It tends to
    /// [`Camera::coc_at_infinity`] far away; points at or behind the lens plane (`z ≤ 0`, which
    /// no primary ray hits) get the value at `z = 10⁻⁶·z_f` so that the result stays finite.
    pub fn signed_coc_px(&self, p: Vec3) -> f32 {
        if self.is_pinhole() {
            return 0.0;
        }
        let fd = self.focus_distance;
        let z = (p - self.position).dot(self.forward);
        let z = if z.is_nan() { fd } else { z.max(1e-6 * fd) };
        self.coc_at_infinity() * (z - fd) / z
    }

    /// The signed circle of confusion in pixels of a point infinitely far away, the largest
    /// positive value [`Camera::signed_coc_px`] approaches: `A·height / (2·tan(fov/2)·z_f)`
    /// (zero for a pinhole). Samples that hit nothing (the environment) are given this.
    pub fn coc_at_infinity(&self) -> f32 {
        if self.is_pinhole() {
            return 0.0;
        }
        self.aperture / (self.pixel_size() * self.focus_distance)
    }

    /// Raster position (x right, y down) of a world point seen through the pinhole, if it is in
    /// front of the camera. Used by tests and later by splatting integrators.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let v = p - self.position;
        let z = v.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let aspect = self.full_aspect();
        let sx = v.dot(self.right) / z / (self.tan_half * aspect);
        let sy = v.dot(self.up) / z / self.tan_half;
        let (fx, fy) = ((sx + 1.0) * 0.5, (1.0 - sy) * 0.5);
        Some(match &self.crop {
            None => Vec2::new(fx * self.width as f32, fy * self.height as f32),
            Some(c) => Vec2::new(
                (fx - c.x0) / (c.x1 - c.x0) * self.width as f32,
                (fy - c.y0) / (c.y1 - c.y0) * self.height as f32,
            ),
        })
    }
}

/// A deterministic connection from a scene point to the camera, for light paths
/// ([`Camera::connect`]).
#[derive(Clone, Copy, Debug)]
pub struct CameraConnection {
    /// Raster position (x right, y down, in pixels) the point is seen at, inside the image.
    pub raster: Vec2,
    /// The point on the lens the connection ends at (the centre of projection for a pinhole).
    pub lens_point: Vec3,
    /// Where the segment from the scene point to `lens_point` crosses the near clipping plane
    /// (`lens_point` itself without a near clip): what lies beyond it, toward the lens, is
    /// clipped away, as for primary rays, so visibility is tested up to here.
    pub near_point: Vec3,
    /// Unit direction from the scene point towards `lens_point`.
    pub wi: Vec3,
    /// Distance from the scene point to `lens_point`.
    pub dist: f32,
    /// The camera's importance over the solid-angle pdf of the connection, per pixel:
    /// `1 / (dist² · A_pixel · cos³θ)`, with `A_pixel` one pixel's area on the image plane at
    /// distance 1 and `θ` the angle between the view direction and the ray at the lens. A light
    /// path's contribution to pixel `raster` is `β · f · |cos| · importance`, averaged over
    /// the light paths: that is the box-filtered pixel mean the camera-ray driver estimates.
    pub importance: f32,
}

impl Camera {
    /// Connects world point `p` to the camera through lens sample `lens` in [0,1)² (ignored by a
    /// pinhole), for light tracing. `None` if `p` is behind the lens or nearer than
    /// [`Camera::near_clip`] along the view axis, or projects outside the image.
    ///
    /// Why `importance` is what it is: the driver averages radiance over a pixel's area `s` on
    /// the image plane at distance 1 and over the lens; through a lens point the solid angle
    /// of `ds` is `cos³θ ds` (for a thin lens too: the focus plane is at a fixed depth), so a
    /// pixel's value is `∫ L dω / (A_pixel cos³θ)`, and `dω = cos_p dA / dist²` at the scene
    /// point. The uniform lens sample's pdf cancels the lens average.
    pub fn connect(&self, p: Vec3, lens: Vec2) -> Option<CameraConnection> {
        let lens_point = self.lens_point(lens);
        let v = p - lens_point;
        let z = v.dot(self.forward);
        let dist2 = v.length_squared();
        if z <= 0.0 || z < self.near_clip || dist2.is_nan() || dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        // The point of the focus plane on the line from the lens point through `p` is what the
        // pinhole at the lens centre images at the raster position.
        let q = if self.is_pinhole() {
            p
        } else {
            lens_point + v * (self.focus_distance / z)
        };
        let raster = self.project(q)?;
        let inside = (0.0..self.width as f32).contains(&raster.x)
            && (0.0..self.height as f32).contains(&raster.y);
        if !inside {
            return None;
        }
        let dist = dist2.sqrt();
        let near_point = if self.near_clip > 0.0 {
            lens_point + v * (self.near_clip / z)
        } else {
            lens_point
        };
        let cos = z / dist;
        let pixel_area = self.pixel_size().powi(2);
        let importance = 1.0 / (dist2 * pixel_area * cos * cos * cos);
        Some(CameraConnection {
            raster,
            lens_point,
            near_point,
            wi: -v / dist,
            dist,
            importance,
        })
    }
}

impl crate::content_hash::ContentHash for Camera {
    /// Everything but `tan_half`, which follows from the field of view.
    fn content_hash(&self, out: &mut crate::content_hash::Sink<'_>) {
        let Camera {
            name,
            position,
            forward,
            right,
            up,
            fov_y_deg,
            width,
            height,
            aperture,
            focus_distance,
            filter,
            crop,
            near_clip,
            tan_half: _,
        } = self;
        name.content_hash(out);
        position.content_hash(out);
        forward.content_hash(out);
        right.content_hash(out);
        up.content_hash(out);
        fov_y_deg.content_hash(out);
        width.content_hash(out);
        height.content_hash(out);
        aperture.content_hash(out);
        focus_distance.content_hash(out);
        // Only a non-box filter adds to the hash, so that hashes from before filters existed
        // (reference caches) still match.
        if *filter != PixelFilter::Box {
            filter.to_string().content_hash(out);
        }
        // Likewise a crop window.
        if let Some(c) = crop {
            [c.x0, c.y0, c.x1, c.y1].content_hash(out);
        }
        // And a near clip.
        if *near_clip > 0.0 {
            "near_clip".content_hash(out);
            near_clip.content_hash(out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(aperture: f32) -> Camera {
        Camera::look_at(
            "c",
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            200,
            100,
            aperture,
            5.0,
        )
    }

    #[test]
    fn primary_rays_start_on_the_near_plane_and_nearer_points_do_not_connect() {
        for aperture in [0.0, 0.2] {
            let mut c = cam(aperture);
            let open = c.clone();
            c.near_clip = 1.5;
            for film in [
                Vec2::new(0.5, 0.5),
                Vec2::new(100.0, 50.0),
                Vec2::new(199.0, 7.0),
            ] {
                let lens = Vec2::new(0.8, 0.1);
                let (r, o) = (c.generate_ray(film, lens), open.generate_ray(film, lens));
                let depth = (r.origin - c.position).dot(c.forward);
                assert!((depth - 1.5).abs() < 1e-5, "{depth}");
                // The same line, moved along it.
                assert!((r.dir - o.dir).length() < 1e-6);
                let along = (r.origin - o.origin).cross(o.dir).length();
                assert!(along < 1e-5, "{along}");
                // A point just beyond the plane connects, one just before it does not.
                let beyond = o.origin + o.dir * (1.6 / o.dir.dot(c.forward));
                let before = o.origin + o.dir * (1.4 / o.dir.dot(c.forward));
                assert!(c.connect(beyond, lens).is_some() && c.connect(before, lens).is_none());
                assert!(open.connect(before, lens).is_some());
            }
        }
    }

    #[test]
    fn a_crop_sees_its_part_of_the_full_image() {
        for aperture in [0.0, 0.2] {
            let full = cam(aperture);
            let mut crop = full.resized(60, 40);
            crop.crop = Crop::from_pixels(50, 20, 60, 40, 200, 100);
            let offset = Vec2::new(50.0, 20.0);
            let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
            for film in [
                Vec2::new(0.5, 0.5),
                Vec2::new(59.9, 3.0),
                Vec2::new(30.0, 39.5),
            ] {
                let lens = Vec2::new(0.3, 0.7);
                let (a, b) = (
                    crop.generate_ray(film, lens),
                    full.generate_ray(film + offset, lens),
                );
                assert!(close(a.origin, b.origin) && close(a.dir, b.dir), "{film}");
                // Projection is the inverse, in the crop's pixels.
                let p = full.position + b.dir * 3.0;
                let back = crop.project(p).unwrap();
                assert!((back - full.project(p).unwrap() + offset).length() < 1e-3);
                // A light path's connection: the same per-pixel importance, raster shifted.
                let (cc, fc) = (crop.connect(p, lens), full.connect(p, lens).unwrap());
                if aperture == 0.0 {
                    let cc = cc.unwrap();
                    assert!((cc.importance / fc.importance - 1.0).abs() < 1e-4);
                    assert!((cc.raster + offset - fc.raster).length() < 1e-3);
                }
                // The direction pdf is over the crop's smaller image: 200·100 / (60·40) times.
                let ratio = crop.pdf_direction(b.dir) / full.pdf_direction(b.dir);
                assert!((ratio - 200.0 * 100.0 / 2400.0).abs() < 1e-3, "{ratio}");
            }
            let coc = (crop.coc_at_infinity(), full.coc_at_infinity());
            assert!((coc.0 - coc.1).abs() <= 1e-5 * coc.1, "{coc:?}");
            // Outside the window a point does not connect.
            let outside = full.position + full.generate_ray(Vec2::new(10.0, 10.0), Vec2::ZERO).dir;
            assert!(crop.connect(outside, Vec2::ZERO).is_none());
        }
        assert!(Crop::from_pixels(150, 0, 60, 10, 200, 100).is_none());
        assert!(Crop::from_pixels(0, 0, 0, 10, 200, 100).is_none());
    }

    #[test]
    fn orientation_matches_the_documented_convention() {
        let c = cam(0.0);
        assert!(c.is_pinhole() && !cam(0.2).is_pinhole());
        assert!((c.right - Vec3::X).length() < 1e-6);
        // Left column looks to -x, top row to +y.
        let r = c.generate_ray(Vec2::new(0.0, 50.0), Vec2::ZERO);
        assert!(r.dir.x < 0.0);
        let r = c.generate_ray(Vec2::new(100.0, 0.0), Vec2::ZERO);
        assert!(r.dir.y > 0.0 && r.dir.x.abs() < 1e-6);
        // Top edge is fov/2 above the axis.
        assert!((r.dir.y.atan2(-r.dir.z).to_degrees() - 20.0).abs() < 1e-3);
    }

    #[test]
    fn circle_of_confusion_is_zero_in_focus_and_grows_signed_away_from_it() {
        let c = cam(0.2);
        let at = |z: f32| c.signed_coc_px(c.position + c.forward * z + c.right * 0.3);
        assert!(at(5.0).abs() < 1e-5, "{}", at(5.0));
        assert!(
            at(4.0) < 0.0 && at(3.0) < at(4.0),
            "in front: negative, growing"
        );
        assert!(
            at(6.0) > 0.0 && at(9.0) > at(6.0),
            "behind: positive, growing"
        );
        assert!(at(1e9) <= c.coc_at_infinity() && at(1e9) > 0.999 * c.coc_at_infinity());
        assert!(at(-1.0).is_finite() && at(-1.0) < 0.0);
        assert_eq!(cam(0.0).signed_coc_px(Vec3::new(0.0, 0.0, -10.0)), 0.0);
        // The disc a thin lens actually draws: two lens points at the rim, seen from the
        // pinhole, land `2·radius` pixels apart on the image.
        let p = c.position + c.forward * 8.0;
        let through = |lens_x: f32| {
            let o = c.position + c.right * lens_x;
            let q = o + (p - o) * (c.focus_distance / (p - o).dot(c.forward));
            c.project(q).unwrap()
        };
        let diameter = (through(0.2) - through(-0.2)).length();
        assert!(
            (diameter - 2.0 * c.signed_coc_px(p)).abs() < 1e-3,
            "{diameter}"
        );
    }

    #[test]
    fn project_inverts_generate_ray() {
        let c = cam(0.0);
        let px = Vec2::new(37.5, 81.25);
        let r = c.generate_ray(px, Vec2::ZERO);
        let q = c.project(r.at(3.0)).unwrap();
        assert!((q - px).length() < 1e-3);
    }

    #[test]
    fn thin_lens_rays_converge_on_the_focus_plane() {
        let c = cam(0.2);
        let px = Vec2::new(120.0, 30.0);
        let a = c.generate_ray(px, Vec2::new(0.1, 0.9));
        let b = c.generate_ray(px, Vec2::new(0.8, 0.3));
        assert!(a.origin != b.origin);
        let ta = 5.0 / a.dir.dot(c.forward);
        let tb = 5.0 / b.dir.dot(c.forward);
        let pa =
            a.origin + a.dir * (ta - (a.origin - c.position).dot(c.forward) / a.dir.dot(c.forward));
        let pb =
            b.origin + b.dir * (tb - (b.origin - c.position).dot(c.forward) / b.dir.dot(c.forward));
        assert!((pa - pb).length() < 1e-4, "{pa} {pb}");
    }
}
