//! What [`AccelSpec::build`](crate::AccelSpec::build) builds over: a scene, a scene it may
//! reorder, or bare triangles.

use glam::Vec3;
use rt_core::Scene;

/// The input of [`AccelSpec::build`](crate::AccelSpec::build), the one build entry point.
///
/// `&Scene` and triangle slices convert into it ([`From`]); a scene the build may reorder is
/// named explicitly, [`BuildInput::SceneToReorder`], so that a permutation is never a surprise.
#[derive(Debug)]
pub enum BuildInput<'a> {
    /// The scene's triangles as they are now. Two-level structures build their object BVHs
    /// from the scene's prototypes and place its instances (and then follow them with
    /// [`rt_core::Accel::update`]); the others see the flat triangles. IOSP answers in the
    /// scene's order through an index map (4 bytes per triangle).
    Scene(&'a Scene),
    /// As [`BuildInput::Scene`], but the structures that live in the triangle order (IOSP)
    /// reorder the scene's triangles and their attributes in place instead of storing an
    /// index map. A scene with instances is kept in its order: each frame rewrites an
    /// instance's world copy in its contiguous range, which a reordering would scatter.
    SceneToReorder(&'a mut Scene),
    /// Bare triangles, whose indices become [`rt_core::Hit::prim`]; a two-level structure gets
    /// them as one static object, IOSP answers through an index map.
    Triangles(&'a [[Vec3; 3]]),
}

impl<'a> From<&'a Scene> for BuildInput<'a> {
    fn from(scene: &'a Scene) -> Self {
        BuildInput::Scene(scene)
    }
}

impl<'a> From<&'a [[Vec3; 3]]> for BuildInput<'a> {
    fn from(triangles: &'a [[Vec3; 3]]) -> Self {
        BuildInput::Triangles(triangles)
    }
}

impl<'a> From<&'a Vec<[Vec3; 3]>> for BuildInput<'a> {
    fn from(triangles: &'a Vec<[Vec3; 3]>) -> Self {
        BuildInput::Triangles(triangles)
    }
}

impl<'a, const N: usize> From<&'a [[Vec3; 3]; N]> for BuildInput<'a> {
    fn from(triangles: &'a [[Vec3; 3]; N]) -> Self {
        BuildInput::Triangles(triangles)
    }
}
