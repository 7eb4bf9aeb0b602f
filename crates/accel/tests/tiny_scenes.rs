//! A closed room of a few dozen large triangles (the Cornell box's case): the default `bvh8`
//! must let a closest-hit ray from inside stop after a few triangle tests. The SAH alone keeps
//! such rooms in leaves of 16 triangles, every one of which each ray tests.

mod common;

use common::{grid_cube, Rng};
use rt_accel::{AccelSpec, BruteForce, FINE_LEAVES_MAX_TRIANGLES};
use rt_core::{Accel, Ray, TraversalCounters};

#[test]
fn rays_inside_a_small_room_test_few_triangles() {
    // 6 faces x 2 x 2 quads x 2 triangles = 48, with two small boxes inside.
    let mut tris = grid_cube(2).triangles();
    for centre in [
        glam::Vec3::new(-0.4, -0.6, 0.2),
        glam::Vec3::new(0.4, -0.7, -0.3),
    ] {
        tris.extend(grid_cube(1).transformed(|p| centre + p * 0.25).triangles());
    }
    assert!(tris.len() <= FINE_LEAVES_MAX_TRIANGLES);
    let accel = AccelSpec::default()
        .build(&tris)
        .expect("the structure builds");
    let oracle = BruteForce::new(&tris);
    let mut rng = Rng::new(77);
    let mut counters = TraversalCounters::default();
    let rays = 4_000;
    for _ in 0..rays {
        let origin = rng.vec_in(-0.9, 0.9) * glam::Vec3::new(1.0, 0.2, 1.0) + glam::Vec3::Y * 0.5;
        let ray = Ray::new(origin, rng.unit_vec());
        let hit = accel.closest_hit(&ray, f32::INFINITY, Some(&mut counters));
        let want = oracle.intersect(&ray, f32::INFINITY);
        assert_eq!(hit.map(|h| h.t), want.map(|h| h.t), "{ray:?}");
    }
    let per_ray = counters.prims_tested as f64 / rays as f64;
    // Leaves of up to 16 (the SAH's choice) test 17.4 triangles per ray here, one-triangle
    // binary leaves 3.2.
    assert!(per_ray < 8.0, "{per_ray:.2} triangle tests per ray");
}
