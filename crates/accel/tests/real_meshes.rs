//! Every structure and option against brute force on real meshes from `../shared/data` (a
//! visible skip when absent, a failure under `RT_REQUIRE_DATA=1`): a scanned mesh, and the
//! conference room, whose triangles are 16% degenerate and which has coplanar overlapping
//! surfaces. Brute force over the conference room's 330k triangles costs too much per ray for
//! many rays, so there every structure is also checked on 20,000 rays against the binary BVH,
//! which the brute-force rays check first.

mod common;

use common::{check_ray, rays, shared_mesh, Agreement, Rng};
use rt_accel::{AccelSpec, BruteForce};
use rt_core::Accel;

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

/// Checks every spec on `n_brute` rays against brute force, then on `n_bvh` other rays against
/// the binary BVH (`bvh`, itself checked by the first set).
fn check_mesh(relative: &str, n_brute: usize, n_bvh: usize) {
    let Some(tris) = shared_mesh(relative) else {
        return;
    };
    let mut rng = Rng::new(2026);
    check_specs(
        relative,
        &tris,
        &BruteForce::new(&tris),
        &rays(&mut rng, &tris, n_brute),
    );
    if n_bvh > 0 {
        let bvh = AccelSpec::new(rt_accel::AccelKind::Bvh)
            .build(&tris)
            .expect("the structure builds");
        check_specs(relative, &tris, bvh.as_ref(), &rays(&mut rng, &tris, n_bvh));
    }
}

fn check_specs(
    relative: &str,
    tris: &[[rt_core::glam::Vec3; 3]],
    oracle: &dyn Accel,
    rays: &[(rt_core::Ray, f32)],
) {
    let n_rays = rays.len();
    let oracle_name = oracle.name();
    for spec in SPECS {
        let accel = spec
            .parse::<AccelSpec>()
            .unwrap()
            .build(tris)
            .expect("the structure builds");
        let (mut hits, mut outside_box) = (0, 0);
        for (i, (ray, t_max)) in rays.iter().enumerate() {
            match check_ray(accel.as_ref(), oracle, ray, *t_max, tris) {
                Ok(Agreement::OracleOutsideBox) => outside_box += 1,
                Ok(_) => {}
                Err(e) => {
                    panic!("{relative} {spec} vs {oracle_name}: ray {i} {ray:?} t_max {t_max}: {e}")
                }
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
    check_mesh("models/stanford-bunny.obj", 800, 0);
}

#[test]
fn conference_room() {
    check_mesh("scenes/conference/conference.obj", 200, 20_000);
}
