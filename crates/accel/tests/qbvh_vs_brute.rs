//! The QBVH must give the brute-force answer under the same rule as the binary BVH (see
//! `common::check_ray`), be watertight on a closed mesh, and pass its own structural check.

mod common;

use common::{check_ray, icosphere, rays, soup, Agreement, Rng};
use glam::Vec3;
use rt_accel::{BruteForce, BuildParams, Bvh2, QNode, Qbvh};
use rt_core::{triangle::geometric_normal, Accel, Ray, TraversalCounters};
use std::collections::HashMap;

fn check_soup(seed: u64, n_tris: usize, n_rays: usize, params: &BuildParams) -> usize {
    let mut rng = Rng::new(seed);
    let tris = soup(&mut rng, n_tris);
    let q = Qbvh::build(&tris, params);
    q.validate()
        .unwrap_or_else(|e| panic!("seed {seed}, {n_tris} tris: {e}"));
    for (slot, &id) in q.prim_ids().iter().enumerate() {
        assert_eq!(q.triangles()[slot], tris[id as usize]);
    }
    let oracle = BruteForce::new(&tris);
    let mut hits = 0;
    let mut outside_box = 0;
    for (i, (ray, t_max)) in rays(&mut rng, &tris, n_rays).into_iter().enumerate() {
        match check_ray(&q, &oracle, &ray, t_max, &tris) {
            Ok(Agreement::OracleOutsideBox) => outside_box += 1,
            Ok(_) => {}
            Err(e) => panic!("seed {seed}, {n_tris} tris, ray {i} {ray:?} t_max {t_max}: {e}"),
        }
        let got = q.intersect(&ray, t_max);
        let mut counters = TraversalCounters::default();
        assert_eq!(q.intersect_counted(&ray, t_max, &mut counters), got);
        assert!(counters.nodes_visited >= 1);
        if got.is_some() {
            assert!(counters.prims_tested >= 1);
        }
        hits += usize::from(got.is_some());
    }
    assert!(
        outside_box * 1000 <= n_rays,
        "{outside_box} of {n_rays} rays"
    );
    hits
}

#[test]
fn node_is_128_bytes() {
    assert_eq!(std::mem::size_of::<QNode>(), 128);
    assert_eq!(std::mem::align_of::<QNode>(), 64);
}

#[test]
fn empty_scene() {
    let q = Qbvh::build(&[], &BuildParams::default());
    q.validate().unwrap();
    assert!(q.nodes().is_empty());
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(q.intersect(&ray, f32::INFINITY), None);
    assert!(!q.occluded(&ray, f32::INFINITY));
    assert!(q.bounds().is_empty());
    assert_eq!(q.name(), "qbvh");
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
fn big_and_single_triangle_leaves_match_brute_force() {
    // Leaves of up to 100 triangles are split into runs of at most 16; leaves of one triangle
    // give the deepest trees.
    for (k, max_leaf_size) in [1, 16, 100].into_iter().enumerate() {
        let params = BuildParams {
            max_leaf_size,
            traversal_cost: 10.0,
            ..BuildParams::default()
        };
        check_soup(5_000 + k as u64, 3000, 3000, &params);
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
    let mut rng = Rng::new(77);
    for _ in 0..20_000 {
        let ray = Ray::new(rng.vec_in(-3.0, 3.0), rng.unit_vec());
        assert_eq!(
            q.intersect(&ray, f32::INFINITY),
            bvh.intersect(&ray, f32::INFINITY)
        );
    }
}

/// As `watertight.rs`: rays from outside aimed at vertices, edge midpoints and points on edges
/// of a closed mesh, from within a cone around the normal, must hit.
#[test]
fn icosphere_is_watertight() {
    let mesh = icosphere(5);
    mesh.assert_closed();
    let tris = mesh.triangles();
    let unit_normal: Vec<Vec3> = tris
        .iter()
        .map(|t| geometric_normal(t).normalize())
        .collect();
    let mut vertex_faces: Vec<Vec<usize>> = vec![Vec::new(); mesh.positions.len()];
    let mut edge_faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (fi, f) in mesh.faces.iter().enumerate() {
        for k in 0..3 {
            vertex_faces[f[k] as usize].push(fi);
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edge_faces.entry((a.min(b), a.max(b))).or_default().push(fi);
        }
    }
    let mut edges: Vec<_> = edge_faces.into_iter().collect();
    edges.sort_unstable_by_key(|e| e.0);

    let q = Qbvh::build(&tris, &BuildParams::default());
    q.validate().unwrap();
    let radius = q.bounds().bounding_radius();
    let mut rng = Rng::new(1);
    let min_sin = 5f32.to_radians().sin();
    let mut fired = 0;
    while fired < 200_000 {
        let (point, normals): (Vec3, Vec<Vec3>) = match rng.below(3) {
            0 => {
                let v = rng.below(mesh.positions.len());
                let n = vertex_faces[v].iter().map(|&f| unit_normal[f]).collect();
                (mesh.positions[v], n)
            }
            k => {
                let ((a, b), faces) = &edges[rng.below(edges.len())];
                let (a, b) = (mesh.positions[*a as usize], mesh.positions[*b as usize]);
                let s = if k == 1 { 0.5 } else { rng.f32() };
                (
                    a + (b - a) * s,
                    faces.iter().map(|&f| unit_normal[f]).collect(),
                )
            }
        };
        let n = normals.iter().sum::<Vec3>().normalize();
        let Some(out) = (0..16)
            .map(|_| (n + rng.unit_vec() * 0.5).normalize())
            .find(|d| normals.iter().all(|nf| nf.dot(*d) > min_sin))
        else {
            continue;
        };
        let origin = point + out * radius * rng.range(2.0, 6.0);
        let ray = Ray::new(origin, point - origin);
        fired += 1;
        let hit = q.intersect(&ray, f32::INFINITY);
        assert!(
            hit.is_some_and(|h| h.t <= 1.0 + 1e-3),
            "ray {fired} {ray:?} at {point:?} found {hit:?}"
        );
        if fired % 8 == 0 {
            assert!(q.occluded(&ray, 1.0 + 1e-3), "ray {fired} not occluded");
        }
    }
}
