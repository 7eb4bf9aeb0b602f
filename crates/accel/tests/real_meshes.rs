//! Every structure and option against brute force on real meshes from `../shared/data` (skipped
//! with a message when absent): a scanned mesh, and the conference room, whose triangles are
//! 16% degenerate and which has coplanar overlapping surfaces.

mod common;

use common::{check_ray, rays, shared_mesh, Agreement, Rng};
use rt_accel::{AccelSpec, BruteForce};

const SPECS: [&str; 11] = [
    "bvh",
    "qbvh",
    "qbvh:order=distance",
    "qbvh:order=unsorted:tstack",
    "qbvh:evh=14:compact",
    "qbvh:bbah=12:compact",
    "qbvh:shadow-cache",
    "qbvh:lazy",
    "bvh8",
    "bvh8:order=split:shadow-cache",
    "bvh:evh=14",
];

fn check_mesh(relative: &str, n_rays: usize) {
    let Some(tris) = shared_mesh(relative) else {
        return;
    };
    let oracle = BruteForce::new(&tris);
    let mut rng = Rng::new(2026);
    let rays = rays(&mut rng, &tris, n_rays);
    for spec in SPECS {
        let accel = spec.parse::<AccelSpec>().unwrap().build(&tris);
        let (mut hits, mut outside_box) = (0, 0);
        for (i, (ray, t_max)) in rays.iter().enumerate() {
            match check_ray(accel.as_ref(), &oracle, ray, *t_max, &tris) {
                Ok(Agreement::OracleOutsideBox) => outside_box += 1,
                Ok(_) => {}
                Err(e) => panic!("{relative} {spec}: ray {i} {ray:?} t_max {t_max}: {e}"),
            }
            let closest = accel.intersect(ray, *t_max).is_some();
            let target = ray.origin + ray.dir * t_max.min(1.0);
            assert_eq!(
                accel.occluded_toward(ray, *t_max, target),
                accel.occluded(ray, *t_max),
                "{relative} {spec}: ray {i}"
            );
            hits += usize::from(closest);
        }
        assert!(hits > n_rays / 4, "{relative} {spec}: {hits} hits");
        // The oracle's hits outside a triangle's own box come from nearly degenerate triangles.
        assert!(
            outside_box * 500 <= n_rays,
            "{relative} {spec}: {outside_box}"
        );
    }
}

#[test]
fn bunny() {
    check_mesh("models/stanford-bunny.obj", 800);
}

#[test]
fn conference_room() {
    check_mesh("scenes/conference/conference.obj", 200);
}
