//! Inline shapes, tessellated on load: quad, box, icosphere, disk, cylinder.
//!
//! The functions here take already-validated parameters (finite, positive radius, ordered box
//! corners; `geometry.rs` checks them against the TOML) and produce triangles whose front
//! (counter-clockwise) faces point out of the solid, or towards the given normal.

use crate::geometry::Mesh;
use glam::{Vec2, Vec3};

/// Texture coordinates of the four corners of a quad.
const QUAD_UV: [Vec2; 4] = [
    Vec2::new(0.0, 0.0),
    Vec2::new(1.0, 0.0),
    Vec2::new(1.0, 1.0),
    Vec2::new(0.0, 1.0),
];

/// A quad from four corners in counter-clockwise order seen from the front, as the triangles
/// (0,1,2) and (0,2,3). The corners get uvs (0,0), (1,0), (1,1), (0,1).
pub(crate) fn quad(v: [Vec3; 4]) -> Mesh {
    let mut m = Mesh::default();
    push_quad(&mut m, v);
    m
}

fn push_quad(m: &mut Mesh, v: [Vec3; 4]) {
    let uv = QUAD_UV;
    m.push([v[0], v[1], v[2]], None, Some([uv[0], uv[1], uv[2]]), None);
    m.push([v[0], v[2], v[3]], None, Some([uv[0], uv[2], uv[3]]), None);
}

/// An axis-aligned box from `min` to `max` (each component of `max` greater): 12 triangles,
/// faces outward, each face with uvs over [0,1]².
pub(crate) fn cuboid(min: Vec3, max: Vec3) -> Mesh {
    let mut m = Mesh::default();
    let center = (min + max) * 0.5;
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |sb: f32, sc: f32| {
                let mut p = Vec3::ZERO;
                let pick = |s: f32, i: usize| if s > 0.5 { max[i] } else { min[i] };
                p[axis] = pick(side, axis);
                p[b] = pick(sb, b);
                p[c] = pick(sc, c);
                p
            };
            let mut v = [
                corner(0.0, 0.0),
                corner(1.0, 0.0),
                corner(1.0, 1.0),
                corner(0.0, 1.0),
            ];
            // Orient the face outward: its normal must point away from the centre.
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let face_center = (v[0] + v[2]) * 0.5;
            if n.dot(face_center - center) < 0.0 {
                v.swap(1, 3);
            }
            push_quad(&mut m, v);
        }
    }
    m
}

/// An icosphere: the icosahedron subdivided `subdivisions` times (20·4^s triangles), outward,
/// with smooth normals.
pub(crate) fn sphere(center: Vec3, radius: f32, subdivisions: u32) -> Mesh {
    let rt_core::shapes::IndexedMesh {
        positions: verts,
        faces,
    } = rt_core::shapes::icosphere(subdivisions);
    let mut m = Mesh::default();
    for [a, b, c] in faces {
        let mut n = [verts[a as usize], verts[b as usize], verts[c as usize]];
        // The table above is outward already; keep the guarantee explicit.
        if (n[1] - n[0]).cross(n[2] - n[0]).dot(n[0] + n[1] + n[2]) < 0.0 {
            n.swap(1, 2);
        }
        m.push(n.map(|d| center + d * radius), Some(n), None, None);
    }
    m
}

/// A disk of `segments` triangles around `center`, front face towards `normal` (unit), with
/// planar uvs (centre at (0.5, 0.5)).
pub(crate) fn disk(center: Vec3, normal: Vec3, radius: f32, segments: u32) -> Mesh {
    // Tangents with t × b = normal, so increasing angle runs counter-clockwise seen from the
    // normal side.
    let (t, b) = normal.any_orthonormal_pair();
    let (t, b) = if t.cross(b).dot(normal) > 0.0 {
        (t, b)
    } else {
        (b, t)
    };
    let at = |i: u32| {
        let a = std::f32::consts::TAU * (i % segments) as f32 / segments as f32;
        let (s, c) = a.sin_cos();
        (
            center + (t * c + b * s) * radius,
            Vec2::new(0.5 + 0.5 * c, 0.5 + 0.5 * s),
        )
    };
    let mut m = Mesh::default();
    let uc = Vec2::splat(0.5);
    for i in 0..segments {
        let (p0, u0) = at(i);
        let (p1, u1) = at(i + 1);
        m.push([center, p0, p1], None, Some([uc, u0, u1]), None);
    }
    m
}

/// An open tube (no caps) of `segments` quads from `p0` to `p1` (distinct), outward, with
/// smooth normals and uvs `(angle / 2π, distance along the axis / its length)`: Mitsuba's
/// `cylinder` parameterisation.
pub(crate) fn cylinder(p0: Vec3, p1: Vec3, radius: f32, segments: u32) -> Mesh {
    let axis = p1 - p0;
    let dir = axis.normalize();
    // Mitsuba's local frame: x, y around the axis with x × y = axis, so the angle runs
    // counter-clockwise seen from `p1`.
    let (t, b) = dir.any_orthonormal_pair();
    let (t, b) = if t.cross(b).dot(dir) > 0.0 {
        (t, b)
    } else {
        (b, t)
    };
    let around = |i: u32| {
        let a = std::f32::consts::TAU * (i % segments) as f32 / segments as f32;
        let (s, c) = a.sin_cos();
        (t * c + b * s, i as f32 / segments as f32)
    };
    let mut m = Mesh::default();
    for i in 0..segments {
        let (n0, u0) = around(i);
        let (n1, u1) = around(i + 1);
        let [a, b_, c, d] = [
            p0 + n0 * radius,
            p0 + n1 * radius,
            p1 + n1 * radius,
            p1 + n0 * radius,
        ];
        let uv = [
            Vec2::new(u0, 0.0),
            Vec2::new(u1, 0.0),
            Vec2::new(u1, 1.0),
            Vec2::new(u0, 1.0),
        ];
        m.push(
            [a, b_, c],
            Some([n0, n1, n1]),
            Some([uv[0], uv[1], uv[2]]),
            None,
        );
        m.push(
            [a, c, d],
            Some([n0, n1, n0]),
            Some([uv[0], uv[2], uv[3]]),
            None,
        );
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn normal(v: &[Vec3; 3]) -> Vec3 {
        (v[1] - v[0]).cross(v[2] - v[0])
    }

    #[test]
    fn cylinder_faces_outward_and_spans_its_axis() {
        let (p0, p1) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, 5.0));
        let m = cylinder(p0, p1, 0.5, 16);
        assert_eq!(m.tris.len(), 32);
        for (v, n) in m.tris.iter().zip(&m.normals) {
            let c = (v[0] + v[1] + v[2]) / 3.0;
            let radial = c - Vec3::new(1.0, 2.0, c.z);
            assert!(normal(v).dot(radial) > 0.0, "inward triangle {v:?}");
            for (p, n) in v.iter().zip(n.unwrap()) {
                assert!((Vec3::new(p.x - 1.0, p.y - 2.0, 0.0).length() - 0.5).abs() < 1e-6);
                assert!((n - Vec3::new(p.x - 1.0, p.y - 2.0, 0.0) / 0.5).length() < 1e-5);
                assert!((3.0..=5.0).contains(&p.z));
            }
        }
    }

    #[test]
    fn quad_is_split_as_0_1_2_and_0_2_3() {
        let v = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let m = quad(v);
        assert_eq!(m.tris, vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]]);
        assert!(normal(&m.tris[0]).z > 0.0 && normal(&m.tris[1]).z > 0.0);
        assert_eq!(m.uvs[1], Some([QUAD_UV[0], QUAD_UV[2], QUAD_UV[3]]));
    }

    #[test]
    fn box_faces_point_outward_and_cover_the_surface() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 3.0, 2.5));
        let m = cuboid(lo, hi);
        assert_eq!(m.tris.len(), 12);
        let c = (lo + hi) * 0.5;
        let mut area = 0.0;
        for t in &m.tris {
            let n = normal(t);
            assert!(n.dot((t[0] + t[1] + t[2]) / 3.0 - c) > 0.0, "{t:?}");
            area += n.length() * 0.5;
        }
        let d = hi - lo;
        assert!((area - 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)).abs() < 1e-4);
    }

    #[test]
    fn icosphere_is_outward_with_unit_normals_on_the_sphere() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        for s in 0..4 {
            let m = sphere(c, 0.5, s);
            assert_eq!(m.tris.len(), 20 * 4usize.pow(s));
            for (t, n) in m.tris.iter().zip(&m.normals) {
                assert!(normal(t).dot((t[0] + t[1] + t[2]) / 3.0 - c) > 0.0);
                for (p, n) in t.iter().zip(n.unwrap()) {
                    assert!(((*p - c).length() - 0.5).abs() < 1e-5);
                    assert!((n - (*p - c) * 2.0).length() < 1e-5);
                }
            }
        }
    }

    #[test]
    fn disk_faces_its_normal_and_has_the_right_area() {
        let n = Vec3::new(1.0, 1.0, 0.0).normalize();
        let m = disk(Vec3::ONE, n, 2.0, 64);
        assert_eq!(m.tris.len(), 64);
        let mut area = 0.0;
        for t in &m.tris {
            let g = normal(t);
            assert!(g.normalize().dot(n) > 0.9999);
            area += g.length() * 0.5;
        }
        let exact = 0.5 * 64.0 * 4.0 * (std::f32::consts::TAU / 64.0).sin();
        assert!((area - exact).abs() < 1e-3, "{area} {exact}");
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y] {
            let m = disk(Vec3::ZERO, axis, 1.0, 3);
            assert!(m.tris.iter().all(|t| normal(t).dot(axis) > 0.0), "{axis}");
        }
    }
}
