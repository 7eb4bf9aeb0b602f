//! Procedural meshes shared by the scene loader, the examples and the tests.

use glam::Vec3;

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices, counter-clockwise seen from the front.
    pub faces: Vec<[u32; 3]>,
}

/// The unit icosphere: the icosahedron subdivided `subdivisions` times (20·4^s triangles), all
/// vertices on the unit sphere, every face outward, vertices shared between faces (so the mesh
/// is closed and each edge is used by exactly two faces).
pub fn icosphere(subdivisions: u32) -> IndexedMesh {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| Vec3::from(p).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        // Each edge's midpoint is created once and shared by both faces of the edge.
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    IndexedMesh { positions, faces }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed_outward_and_on_the_sphere() {
        let m = icosphere(2);
        assert_eq!(m.faces.len(), 320);
        let mut edges = std::collections::HashMap::new();
        for f in &m.faces {
            let [a, b, c] = f.map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "outward");
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(edges.keys().all(|&(a, b)| edges.get(&(b, a)) == Some(&1)));
        assert!(m.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
    }
}
