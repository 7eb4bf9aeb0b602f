//! The BVHs (binary, four- and eight-wide) must give exactly the brute-force answer: same triangle and bit-identical distance and
//! barycentrics, or, when several triangles are hit at the identical distance, any of them (see
//! `common::check_ray` for the precise rule).

mod common;

use common::{soup, Rng};
use rt_accel::{BuildParams, Bvh2, Bvh8, Qbvh};

/// The soup check for the three structures.
fn check_soup(seed: u64, n_tris: usize, n_rays: usize, params: &BuildParams) -> usize {
    let hits = common::check_soup::<Bvh2>(seed, n_tris, n_rays, params);
    assert_eq!(
        common::check_soup::<Qbvh>(seed, n_tris, n_rays, params),
        hits
    );
    assert_eq!(
        common::check_soup::<Bvh8>(seed, n_tris, n_rays, params),
        hits
    );
    hits
}

#[test]
fn tiny_soups_match_brute_force() {
    for seed in 0..300 {
        for n in [1, 2, 10] {
            check_soup(seed, n, 200, &BuildParams::default());
        }
    }
}

#[test]
fn soup_of_1000_matches_brute_force() {
    for seed in 0..4 {
        let hits = check_soup(1000 + seed, 1000, 10_000, &BuildParams::default());
        assert!(hits > 5_000, "only {hits} hits");
    }
}

#[test]
fn soup_of_20000_matches_brute_force() {
    let hits = check_soup(20_000, 20_000, 4_000, &BuildParams::default());
    assert!(hits > 2_000, "only {hits} hits");
}

#[test]
fn other_build_parameters_match_brute_force() {
    let variants = [
        BuildParams {
            max_leaf_size: 1,
            bins: 2,
            ..BuildParams::default()
        },
        BuildParams {
            max_leaf_size: 8,
            bins: 64,
            parallel: false,
            ..BuildParams::default()
        },
        BuildParams {
            max_leaf_size: 16,
            bins: 8,
            traversal_cost: 0.1,
            intersection_cost: 2.0,
            ..BuildParams::default()
        },
        BuildParams {
            max_leaf_size: 0,
            bins: 0,
            traversal_cost: f32::INFINITY,
            intersection_cost: f32::NAN,
            ..BuildParams::default()
        },
    ];
    for (k, params) in variants.iter().enumerate() {
        for seed in 0..3 {
            check_soup(7_000 + 10 * k as u64 + seed, 3000, 3000, params);
        }
    }
}

#[test]
fn parallel_and_sequential_builds_are_identical() {
    let tris = soup(&mut Rng::new(99), 30_000);
    let par = Bvh2::build(&tris, &BuildParams::default());
    let seq = Bvh2::build(
        &tris,
        &BuildParams {
            parallel: false,
            ..BuildParams::default()
        },
    );
    assert_eq!(par.nodes(), seq.nodes());
    assert_eq!(par.prim_ids(), seq.prim_ids());
    par.validate().unwrap();
}
