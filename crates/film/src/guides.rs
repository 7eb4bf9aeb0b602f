//! Per-frame guide buffers: the noise-free features of every pixel's primary hit that a temporal
//! filter reprojects and edge-stops with (Schied et al. 2017; Voorhuis 2018 §4 for the
//! reflected-hit features). They come from one ray through each pixel's centre, the same ray
//! as a sequence's sample 0 (the "guide ray" of Bauszat et al. 2011), so they match what that
//! sample saw.
//!
//! Plain data: `rt-integrators` writes them (`render_guides`), `rt-temporal` reads them.

use rt_core::glam::{Vec2, Vec3};
use rt_core::{Image, Rgb};

/// Object or instance id of a pixel that sees no surface (or a surface outside any instance).
pub const NO_ID: u32 = u32::MAX;

/// Noise-free features of the primary hit of every pixel, and how the pixel moved since the
/// previous frame.
#[derive(Clone, Debug, PartialEq)]
pub struct GuideBuffers {
    /// Distance of the hit along the camera's viewing axis (view-space depth); 0 where the
    /// pixel sees no surface.
    pub depth: Image<f32>,
    /// World-space position of the hit (zero where none).
    pub position: Image<Vec3>,
    /// Unit shading normal facing the camera (zero where none).
    pub normal: Image<Vec3>,
    /// Reflectance at normal incidence, texture included (zero where none).
    pub albedo: Image<Rgb>,
    /// Emitted radiance toward the camera (the environment's where the pixel sees no surface).
    pub emission: Image<Rgb>,
    /// Screen motion in pixels: where the hit was in the previous frame is the pixel centre
    /// minus this (Voorhuis' `prev = p - mv`). Zero for the first frame of a sequence.
    pub motion: Image<Vec2>,
    /// View-space depth the hit had in the previous frame (its point carried back by its
    /// instance's motion, seen by the previous camera): what the history's depth must be where
    /// the motion vector points, if the history saw the same surface. Equals `depth` for the
    /// first frame; 0 where no surface.
    pub previous_depth: Image<f32>,
    /// Object (mesh) index of the hit in `Scene::objects`, or [`NO_ID`].
    pub object: Image<u32>,
    /// Instance index of the hit in `Scene::instances`, or [`NO_ID`].
    pub instance: Image<u32>,
    /// Roughness of the hit's material in [0, 1] on Beckmann's scale: its sharpest significant
    /// layer's (`rt_integrators::guides::roughness`), so a mirror is 0 and a Lambertian
    /// surface 1 (1 where no surface).
    pub roughness: Image<f32>,
    /// Features along the mirror direction, for pixels whose primary hit is specular (roughness
    /// below the classifier's glossy limit); `None` when not asked for.
    pub reflected: Option<ReflectedGuides>,
}

/// What a specular pixel reflects: for a pure mirror the first non-mirror hit along the chain of
/// mirror bounces, for a glossy surface the hit of its representative ray (the mirror
/// direction, Voorhuis Eq. 4).
#[derive(Clone, Debug, PartialEq)]
pub struct ReflectedGuides {
    /// World position of the reflected hit (zero where none).
    pub position: Image<Vec3>,
    /// Its unit shading normal facing the incoming ray (zero where none).
    pub normal: Image<Vec3>,
    /// Unfolded path length from the primary hit to it; 0 where the pixel is not specular or
    /// the reflection escapes.
    pub distance: Image<f32>,
    /// Product of the mirror albedos along the chain and the reflected hit's albedo: what a
    /// pure specular pixel is demodulated by (Voorhuis §4.2: albedo_primary × albedo_reflected).
    pub albedo: Image<Rgb>,
    /// Unit direction of the representative ray from the primary hit (zero where not specular).
    pub direction: Image<Vec3>,
    /// For a pure mirror: the light the end of its chain sends back along it (an emitter's
    /// emission, or the environment where the chain escapes) times the mirror albedos on the
    /// way; zero elsewhere. It has no albedo to be demodulated by, so SVGF adds it back as it
    /// does the primary hit's emission instead of filtering it.
    pub emission: Image<Rgb>,
}

impl GuideBuffers {
    /// Width and height in pixels.
    pub fn size(&self) -> (usize, usize) {
        self.depth.size()
    }

    /// True if pixel `i` (row-major) sees a surface.
    #[inline]
    pub fn has_surface(&self, i: usize) -> bool {
        self.depth.pixels()[i] > 0.0
    }

    /// Checks that every buffer has the same size and every value is finite: what a consumer
    /// reading buffers from elsewhere relies on.
    pub fn check(&self) -> Result<(), GuideError> {
        let size = self.size();
        let sizes = [
            ("position", self.position.size()),
            ("normal", self.normal.size()),
            ("albedo", self.albedo.size()),
            ("emission", self.emission.size()),
            ("motion", self.motion.size()),
            ("previous_depth", self.previous_depth.size()),
            ("object", self.object.size()),
            ("instance", self.instance.size()),
            ("roughness", self.roughness.size()),
        ];
        let reflected = self.reflected.iter().flat_map(|r| {
            [
                ("reflected.position", r.position.size()),
                ("reflected.normal", r.normal.size()),
                ("reflected.distance", r.distance.size()),
                ("reflected.albedo", r.albedo.size()),
                ("reflected.direction", r.direction.size()),
            ]
        });
        for (name, s) in sizes.into_iter().chain(reflected) {
            if s != size {
                return Err(GuideError::Size {
                    buffer: name,
                    size: s,
                    expected: size,
                });
            }
        }
        let finite = self.depth.pixels().iter().all(|v| v.is_finite())
            && self.position.pixels().iter().all(|v| v.is_finite())
            && self.normal.pixels().iter().all(|v| v.is_finite())
            && self.albedo.pixels().iter().all(|v| v.is_finite())
            && self.emission.pixels().iter().all(|v| v.is_finite())
            && self.motion.pixels().iter().all(|v| v.is_finite())
            && self.previous_depth.pixels().iter().all(|v| v.is_finite())
            && self.roughness.pixels().iter().all(|v| v.is_finite());
        if !finite {
            return Err(GuideError::NotFinite);
        }
        Ok(())
    }
}

/// What is wrong with a set of guide buffers.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GuideError {
    /// A buffer's size differs from the depth buffer's.
    #[error("guide buffer {buffer} is {}x{}, the others are {}x{}", size.0, size.1, expected.0, expected.1)]
    Size {
        /// The buffer.
        buffer: &'static str,
        /// Its size.
        size: (usize, usize),
        /// The depth buffer's size.
        expected: (usize, usize),
    },
    /// A value is NaN or infinite.
    #[error("guide buffers hold a value that is not finite")]
    NotFinite,
}
