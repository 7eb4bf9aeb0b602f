//! Shading normals bent by a texture: Mitsuba 3's `bumpmap` and `normalmap` wrappers, which
//! evaluate the BSDF they wrap in a perturbed shading frame.
//!
//! Bump mapping (Blinn, "Simulation of Wrinkled Surfaces", SIGGRAPH 1978, in Mitsuba 3's form):
//! the surface is displaced along the shading normal `n` by `scale · h(u, v)`, with `h` a
//! texture's luminance; the displaced tangents are `∂p/∂u + n·(scale·∂h/∂u − n·∂p/∂u)` (and
//! likewise in `v`), and the bumped normal is their cross product, turned to the geometric
//! normal's side. Normal mapping reads a tangent-space normal `2·rgb − 1` in the frame whose
//! first axis is `∂p/∂u` made orthogonal to `n` and whose second is `n × s`.
//!
//! The scene applies the perturbation where it builds a hit's shading normal
//! ([`crate::scene::Scene::surface`]), so every integrator shades bumped surfaces alike.
//!
//! Deviations from Mitsuba 3: a normal map's normal that points away from the geometric
//! normal's side is turned to it (our BSDFs require the shading normal on that side; Mitsuba
//! keeps it); directions that the bent frame and the geometric normal see on different sides
//! carry nothing ([`crate::material::Bsdf`]), where Mitsuba compares with the unbent shading
//! normal instead; the shading frame's tangent follows the normal, not `∂p/∂u`, which only
//! anisotropic BSDFs could tell.

use crate::frame::Frame;
use crate::Rgb;
use glam::{Vec2, Vec3};

/// How a material bends its shading normal; `texture` indexes `Scene::textures`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalPerturbation {
    /// `bumpmap`: the texture's luminance times `scale` is a height along the normal.
    Bump {
        /// The height texture.
        texture: u32,
        /// Height per unit of luminance (Mitsuba's `scale`, default 1).
        scale: f32,
    },
    /// `normalmap`: the texture holds tangent-space normals as `(n + 1) / 2` (linear data).
    NormalMap {
        /// The normal texture.
        texture: u32,
    },
}

/// Tangents `(∂p/∂u, ∂p/∂v)` of the triangle with vertices `p` and texture coordinates `uv`;
/// for a triangle whose uvs span no area, two tangents of the frame around the unit geometric
/// normal `ng` (as Mitsuba 3 does).
pub fn triangle_tangents(p: &[Vec3; 3], uv: &[Vec2; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (dp0, dp1) = (p[1] - p[0], p[2] - p[0]);
    let (duv0, duv1) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = duv0.x * duv1.y - duv0.y * duv1.x;
    let dpdu = (dp0 * duv1.y - dp1 * duv0.y) / det;
    let dpdv = (dp1 * duv0.x - dp0 * duv1.x) / det;
    if det == 0.0 || !dpdu.is_finite() || !dpdv.is_finite() {
        let f = Frame::from_normal(ng);
        return (f.s, f.t);
    }
    (dpdu, dpdv)
}

/// The bumped shading normal for shading normal `ns`, geometric normal `ng` (unit, same
/// side), tangents `dpdu`, `dpdv` and the height's gradient `grad = scale · (∂h/∂u, ∂h/∂v)`;
/// `ns` itself where the bent tangents are degenerate.
pub fn bumped_normal(ns: Vec3, ng: Vec3, dpdu: Vec3, dpdv: Vec3, grad: Vec2) -> Vec3 {
    let du = dpdu + ns * (grad.x - ns.dot(dpdu));
    let dv = dpdv + ns * (grad.y - ns.dot(dpdv));
    let n = du.cross(dv).normalize_or(ns);
    if n.dot(ng) < 0.0 {
        -n
    } else {
        n
    }
}

/// The shading normal a normal map's texel `rgb` gives at a point with shading normal `ns`,
/// geometric normal `ng` (unit, same side) and tangent `dpdu`.
pub fn mapped_normal(ns: Vec3, ng: Vec3, dpdu: Vec3, rgb: Rgb) -> Vec3 {
    let local = rgb * 2.0 - Rgb::ONE;
    let s = (dpdu - ns * ns.dot(dpdu))
        .try_normalize()
        .unwrap_or_else(|| Frame::from_normal(ns).s);
    let t = ns.cross(s);
    let n = (s * local.x + t * local.y + ns * local.z).normalize_or(ns);
    if n.dot(ng) < 0.0 {
        -n
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat triangle with uvs equal to its x and y: a height `h = 0.2·u` tilts the normal to
    /// `(−0.2, 0, 1)/|·|` (the displaced surface `z = 0.2·x`), and a flat map leaves it be.
    #[test]
    fn a_linear_height_tilts_the_normal_by_its_slope() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let (du, dv) = triangle_tangents(&p, &uv, Vec3::Z);
        assert!((du - Vec3::X).length() < 1e-6 && (dv - Vec3::Y).length() < 1e-6);
        let n = bumped_normal(Vec3::Z, Vec3::Z, du, dv, Vec2::new(0.2, 0.0));
        assert!(
            (n - Vec3::new(-0.2, 0.0, 1.0).normalize()).length() < 1e-6,
            "{n}"
        );
        assert_eq!(bumped_normal(Vec3::Z, Vec3::Z, du, dv, Vec2::ZERO), Vec3::Z);
        // Mirrored uvs (v down the triangle) give the same normal: the side comes from `ng`.
        let flipped = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::ZERO];
        let (du, dv) = triangle_tangents(&p, &flipped, Vec3::Z);
        assert!((dv + Vec3::Y).length() < 1e-6);
        let n2 = bumped_normal(Vec3::Z, Vec3::Z, du, dv, Vec2::new(0.2, 0.0));
        assert!((n2 - n).length() < 1e-6, "{n2}");
        // Degenerate uvs fall back to a tangent frame of the normal.
        let (du, dv) = triangle_tangents(&p, &[Vec2::ZERO; 3], Vec3::Z);
        assert!(du.dot(Vec3::Z).abs() < 1e-6 && dv.dot(Vec3::Z).abs() < 1e-6);
    }

    /// The flat normal-map colour (0.5, 0.5, 1) keeps the normal; (1, 0.5, 0.5) turns it to
    /// the tangent ∂p/∂u, and (0.5, 1, 0.5) to n × ∂p/∂u.
    #[test]
    fn a_normal_map_reads_tangent_space() {
        let ns = Vec3::Z;
        let n = mapped_normal(ns, ns, Vec3::new(2.0, 0.0, 0.3), Rgb::new(0.5, 0.5, 1.0));
        assert!((n - ns).length() < 1e-6);
        let n = mapped_normal(ns, ns, Vec3::new(2.0, 0.0, 0.3), Rgb::new(1.0, 0.5, 0.5));
        assert!((n - Vec3::X).length() < 1e-6, "{n}");
        let n = mapped_normal(ns, ns, Vec3::new(2.0, 0.0, 0.3), Rgb::new(0.5, 1.0, 0.5));
        assert!((n - Vec3::Y).length() < 1e-6, "{n}");
        // A normal below the surface is turned to the geometric side.
        let n = mapped_normal(ns, ns, Vec3::X, Rgb::new(0.5, 0.5, 0.0));
        assert!(n.dot(Vec3::Z) > 0.0);
    }
}
