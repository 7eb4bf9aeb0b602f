//! Checks of the wide BVHs (QBVH and BVH8). The brute-force soups (`bvh_vs_brute.rs`) and the watertightness tests
//! (`watertight.rs`) run for the QBVH as well as the binary BVH.

mod common;

use common::{icosphere, soup, Rng};
use glam::Vec3;

use rt_accel::{BuildParams, Bvh2, Bvh8, Node8, QNode, Qbvh, WideBvh, WideNode};
use rt_core::{Accel, Ray};

#[test]
fn node_sizes() {
    assert_eq!(std::mem::size_of::<QNode>(), 128);
    assert_eq!(std::mem::align_of::<QNode>(), 64);
    assert_eq!(std::mem::size_of::<Node8>(), 256);
    assert_eq!(std::mem::align_of::<Node8>(), 64);
}

fn check_empty_scene<N: WideNode>() {
    let q = WideBvh::<N>::build(&[], &BuildParams::default());
    q.validate().unwrap();
    assert!(q.nodes().is_empty());
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(q.intersect(&ray, f32::INFINITY), None);
    assert!(!q.occluded(&ray, f32::INFINITY));
    assert!(q.bounds().is_empty());
    assert_eq!(q.name(), N::NAME);
}

#[test]
fn empty_scene() {
    check_empty_scene::<QNode>();
    check_empty_scene::<Node8>();
}

#[test]
fn big_and_single_triangle_leaves_match_brute_force() {
    // Leaves of up to 100 triangles are split into runs of at most 16; leaves of one triangle
    // give the deepest trees.
    for (k, max_leaf_size) in [1, 16, 100].into_iter().enumerate() {
        let params = BuildParams {
            max_leaf_size,
            traversal_cost: 10.0,
            ..BuildParams::default()
        };
        common::check_soup::<Qbvh>(5_000 + k as u64, 3000, 3000, &params);
        common::check_soup::<Bvh8>(5_000 + k as u64, 3000, 3000, &params);
    }
    // Make sure the over-long leaves really occur.
    let tris = soup(&mut Rng::new(5_002), 3000);
    let params = BuildParams {
        max_leaf_size: 100,
        traversal_cost: 10.0,
        ..BuildParams::default()
    };
    let bvh = Bvh2::build(&tris, &params);
    let longest = bvh
        .nodes()
        .iter()
        .filter_map(|n| n.prims())
        .map(|p| p.len());
    assert!(longest.max().unwrap() > 32);
}

#[test]
fn agrees_with_bvh2_exactly_on_a_mesh() {
    let tris = icosphere(4).triangles();
    let bvh = Bvh2::build(&tris, &BuildParams::default());
    let q = Qbvh::from_bvh2(&bvh);
    q.validate().unwrap();
    assert!(q.nodes().len() * 2 <= bvh.nodes().len());
    assert_eq!(q.bounds(), bvh.bounds());
    let o = Bvh8::from_bvh2(&bvh);
    o.validate().unwrap();
    assert!(o.nodes().len() * 4 <= bvh.nodes().len());
    assert_eq!(o.bounds(), bvh.bounds());
    let mut rng = Rng::new(77);
    for _ in 0..20_000 {
        let ray = Ray::new(rng.vec_in(-3.0, 3.0), rng.unit_vec());
        let want = bvh.intersect(&ray, f32::INFINITY);
        assert_eq!(q.intersect(&ray, f32::INFINITY), want);
        assert_eq!(o.intersect(&ray, f32::INFINITY), want);
    }
}
