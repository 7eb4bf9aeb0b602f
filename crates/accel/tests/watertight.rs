//! Watertightness: a ray that crosses a closed mesh exactly at a shared edge or vertex must hit.
//!
//! Every mesh here shares its vertices exactly between triangles, so the watertight triangle
//! test guarantees that such a ray hits at least one of the triangles around the point, and the
//! BVH must not lose that hit to culling. 200,000 rays per mesh, one million in all, start
//! outside the mesh and aim at vertices, edge midpoints and random points along edges.
//!
//! Rays come from within 30 degrees of the surface normal at the target and cross every triangle
//! around it at more than 5 degrees: at a grazing angle the triangles around a point no longer
//! surround it in the ray's view, and whether such a ray "should" hit is not well defined.

mod common;

use common::{grid_cube, icosphere, rotation, torus, Mesh, Rng};
use glam::Vec3;
use rt_accel::{BuildParams, Bvh2, Bvh8, Qbvh};
use rt_core::{triangle::geometric_normal, Accel, Ray};

const RAYS_PER_MESH: usize = 200_000;

/// A point on the surface and the unit normals of the triangles around it.
struct Target {
    point: Vec3,
    normals: Vec<Vec3>,
}

/// Which targets to aim at, and how.
#[derive(Clone, Copy, PartialEq)]
enum Aim {
    /// Directions in a cone around the normal.
    Cone,
    /// A quarter of the rays exactly along the (axis-aligned) normal, as a ray along an axis
    /// through a grid vertex or grid line of an axis-aligned face.
    ConeAndAxes,
}

fn fire(mesh: &Mesh, seed: u64, aim: Aim) {
    mesh.assert_closed();
    let tris = mesh.triangles();
    let volume: f32 = tris.iter().map(|t| t[0].dot(t[1].cross(t[2]))).sum();
    assert!(volume > 0.0, "mesh must face outwards");
    let unit_normal: Vec<Vec3> = tris
        .iter()
        .map(|t| geometric_normal(t).normalize())
        .collect();

    let (vertex_faces, edges) = mesh.adjacency();

    let bvh = Bvh2::build(&tris, &BuildParams::default());
    bvh.validate().unwrap();
    let qbvh = Qbvh::from_bvh2(&bvh);
    qbvh.validate().unwrap();
    let bvh8 = Bvh8::from_bvh2(&bvh);
    bvh8.validate().unwrap();
    let accels: [&dyn Accel; 3] = [&bvh, &qbvh, &bvh8];
    let radius = bvh.bounds().bounding_radius();
    let mut rng = Rng::new(seed);
    let mut fired = 0;
    while fired < RAYS_PER_MESH {
        let target = match rng.below(3) {
            0 => {
                let v = rng.below(mesh.positions.len());
                Target {
                    point: mesh.positions[v],
                    normals: vertex_faces[v].iter().map(|&f| unit_normal[f]).collect(),
                }
            }
            k => {
                let ((a, b), faces) = &edges[rng.below(edges.len())];
                let (a, b) = (mesh.positions[*a as usize], mesh.positions[*b as usize]);
                let s = if k == 1 { 0.5 } else { rng.f32() };
                Target {
                    point: a + (b - a) * s,
                    normals: faces.iter().map(|&f| unit_normal[f]).collect(),
                }
            }
        };
        let Some(out) = outgoing_direction(&mut rng, &target.normals, aim) else {
            continue;
        };
        let origin = target.point + out * radius * rng.range(2.0, 6.0);
        let ray = Ray::new(origin, target.point - origin);
        fired += 1;
        for accel in accels {
            let hit = accel.intersect(&ray, f32::INFINITY);
            let ok = hit.is_some_and(|h| h.t <= 1.0 + 1e-3);
            assert!(
                ok,
                "{}: ray {fired} {ray:?} at {:?} found {hit:?}",
                accel.name(),
                target.point
            );
            if fired % 8 == 0 {
                assert!(
                    accel.occluded(&ray, 1.0 + 1e-3),
                    "{}: ray {fired} {ray:?} not occluded",
                    accel.name()
                );
            }
        }
    }
}

/// A direction pointing away from the surface at the target, crossing all its triangles
/// transversally, or `None` if a few tries found none (a sharp crease).
fn outgoing_direction(rng: &mut Rng, normals: &[Vec3], aim: Aim) -> Option<Vec3> {
    let n = normals.iter().sum::<Vec3>().normalize();
    if aim == Aim::ConeAndAxes && rng.chance(0.25) && n.abs().max_element() == 1.0 {
        return normals.iter().all(|&nf| nf == n).then_some(n);
    }
    let min_sin = 5f32.to_radians().sin();
    (0..16)
        .map(|_| (n + rng.unit_vec() * 0.5).normalize())
        .find(|d| normals.iter().all(|nf| nf.dot(*d) > min_sin))
}

#[test]
fn icosphere_is_watertight() {
    fire(&icosphere(5), 1, Aim::Cone);
}

#[test]
fn bumpy_rotated_icosphere_is_watertight() {
    let mut rng = Rng::new(2);
    let q = rotation(&mut rng);
    let shift = Vec3::new(3.3, -1.7, 0.9);
    let mesh = icosphere(4).transformed(|p| q * (p * rng.range(0.85, 1.15)) + shift);
    fire(&mesh, 2, Aim::Cone);
}

#[test]
fn axis_aligned_grid_cube_is_watertight() {
    fire(&grid_cube(16), 3, Aim::ConeAndAxes);
}

#[test]
fn rotated_grid_cube_is_watertight() {
    let mut rng = Rng::new(4);
    let q = rotation(&mut rng);
    let shift = Vec3::new(-0.3, 10.1, 2.7);
    fire(&grid_cube(12).transformed(|p| q * p + shift), 4, Aim::Cone);
}

#[test]
fn rotated_torus_is_watertight() {
    let mut rng = Rng::new(5);
    let q = rotation(&mut rng);
    fire(
        &torus(64, 32, 1.0, 0.35).transformed(|p| q * p),
        5,
        Aim::Cone,
    );
}
