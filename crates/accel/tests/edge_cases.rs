//! Inputs at the edges of what the BVH accepts: nothing, one triangle, all triangles equal,
//! extreme coordinates, inputs that need the depth limiter, and the `t_max` boundary.

mod common;

use common::{check_ray, rays, soup, Rng};
use glam::Vec3;
use rt_accel::{BruteForce, BuildParams, Bvh2};
use rt_core::{Accel, Ray, TraversalCounters};

fn default_bvh(tris: &[[Vec3; 3]]) -> Bvh2 {
    let bvh = Bvh2::build(tris, &BuildParams::default());
    bvh.validate().unwrap();
    bvh
}

/// Compares with brute force on rays from the soup generator; returns the number of hits.
fn agrees_with_brute_force(tris: &[[Vec3; 3]], rays: &[(Ray, f32)]) -> usize {
    let bvh = default_bvh(tris);
    let oracle = BruteForce::new(tris);
    let mut hits = 0;
    for (i, (ray, t_max)) in rays.iter().enumerate() {
        if let Err(e) = check_ray(&bvh, &oracle, ray, *t_max, tris) {
            panic!("ray {i} {ray:?}: {e}");
        }
        hits += usize::from(bvh.intersect(ray, *t_max).is_some());
    }
    hits
}

#[test]
fn empty_scene_hits_nothing() {
    let bvh = default_bvh(&[]);
    assert!(bvh.nodes().is_empty());
    assert!(bvh.bounds().is_empty());
    assert_eq!(bvh.memory_bytes(), 0);
    let s = bvh.stats();
    assert_eq!((s.nodes, s.leaves, s.triangles, s.max_depth), (0, 0, 0, 0));
    let mut rng = Rng::new(1);
    for _ in 0..100 {
        let ray = Ray::new(rng.vec_in(-1.0, 1.0), rng.unit_vec());
        let mut c = TraversalCounters::default();
        assert_eq!(bvh.closest_hit(&ray, f32::INFINITY, Some(&mut c)), None);
        assert_eq!(c, TraversalCounters::default());
        assert!(!bvh.occluded(&ray, f32::INFINITY));
    }
}

#[test]
fn single_triangle() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let bvh = default_bvh(&[tri]);
    let s = bvh.stats();
    assert_eq!(
        (s.nodes, s.leaves, s.max_depth, s.largest_leaf),
        (1, 1, 0, 1)
    );
    let down = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
    let hit = bvh.intersect(&down, f32::INFINITY).unwrap();
    assert_eq!((hit.prim, hit.t, hit.b1, hit.b2), (0, 1.0, 0.25, 0.25));
    assert!(bvh
        .intersect(&Ray::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z), 9.0)
        .is_none());
    assert!(bvh
        .intersect(&Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::Z), 9.0)
        .is_none());
    let mut c = TraversalCounters::default();
    bvh.closest_hit(&down, f32::INFINITY, Some(&mut c));
    assert_eq!(
        c,
        TraversalCounters {
            nodes_visited: 1,
            leaves_visited: 1,
            prims_tested: 1
        }
    );
}

#[test]
fn hits_exactly_at_t_max_count() {
    let tris: Vec<_> = (0..50)
        .map(|i| [Vec3::ZERO, Vec3::X, Vec3::Y].map(|v| v + Vec3::new(0.0, 0.0, i as f32)))
        .collect();
    let bvh = default_bvh(&tris);
    let ray = Ray::new(Vec3::new(0.25, 0.25, -2.0), Vec3::Z);
    let hit = bvh.intersect(&ray, 2.0).unwrap();
    assert_eq!((hit.prim, hit.t), (0, 2.0));
    assert!(bvh.occluded(&ray, 2.0));
    assert!(!bvh.occluded(&ray, 1.999_999_9));
    assert!(bvh.intersect(&ray, 1.999_999_9).is_none());
    // Starting just past a triangle, the next one is found.
    let ray = Ray::new(Vec3::new(0.25, 0.25, 10.5), Vec3::Z);
    assert_eq!(bvh.intersect(&ray, f32::INFINITY).unwrap().prim, 11);
}

#[test]
fn counters_count_boxes_and_triangles() {
    let far_apart = [
        [Vec3::ZERO, Vec3::X, Vec3::Y],
        [Vec3::ZERO, Vec3::X, Vec3::Y].map(|v| v + Vec3::splat(10.0)),
    ];
    let bvh = Bvh2::build(
        &far_apart,
        &BuildParams {
            max_leaf_size: 1,
            ..BuildParams::default()
        },
    );
    assert!(bvh.counts_traversal());
    assert_eq!(bvh.name(), "bvh");
    let mut c = TraversalCounters::default();
    let hit = bvh.closest_hit(
        &Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z),
        9.0,
        Some(&mut c),
    );
    assert_eq!(hit.unwrap().prim, 0);
    assert_eq!(
        c,
        TraversalCounters {
            nodes_visited: 3,
            leaves_visited: 1,
            prims_tested: 1
        }
    );
}

#[test]
fn identical_triangles() {
    let tri = [
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(1.0, 0.0, 0.5),
        Vec3::new(0.0, 1.0, -0.5),
    ];
    let tris = vec![tri; 1000];
    let bvh = default_bvh(&tris);
    let s = bvh.stats();
    assert!(s.largest_leaf <= 4 && s.max_depth < 64, "{s}");
    let mut rng = Rng::new(2);
    let hits = agrees_with_brute_force(&tris, &rays(&mut rng, &tris, 5000));
    assert!(hits > 1000, "{hits}");
}

#[test]
fn degenerate_triangles_only() {
    // Points and segments (a repeated vertex) have exactly zero area and are never hit, but
    // must build and traverse.
    let mut rng = Rng::new(3);
    let tris: Vec<_> = (0..500)
        .map(|i| {
            let a = rng.vec_in(-1.0, 1.0);
            let b = a + rng.vec_in(-0.1, 0.1);
            match i % 3 {
                0 => [a; 3],
                1 => [a, b, b],
                _ => [a, a, b],
            }
        })
        .collect();
    assert_eq!(
        agrees_with_brute_force(&tris, &rays(&mut rng, &tris, 3000)),
        0
    );
}

#[test]
fn extreme_scales_agree_with_brute_force() {
    for (k, scale) in [1e-30f32, 1e-12, 1e12, 1e30].into_iter().enumerate() {
        let mut rng = Rng::new(10 + k as u64);
        let unit = soup(&mut rng, 500);
        let rays: Vec<_> = rays(&mut rng, &unit, 3000)
            .into_iter()
            .map(|(r, t)| (Ray::new(r.origin * scale, r.dir), t * scale))
            .collect();
        let tris: Vec<_> = unit.iter().map(|t| t.map(|v| v * scale)).collect();
        let hits = agrees_with_brute_force(&tris, &rays);
        // At 1e+-30 the products in rt-core's f32 edge functions overflow or underflow, so
        // nothing is hit there at all; agreeing on that and not panicking is what is tested.
        if scale.log10().abs() < 20.0 {
            assert!(hits > 1000, "scale {scale:e}: only {hits} hits");
        }
    }
}

#[test]
fn infinite_and_max_coordinates_do_not_panic() {
    let mut rng = Rng::new(4);
    let mut tris = soup(&mut rng, 300);
    for (i, t) in tris.iter_mut().enumerate().step_by(7) {
        t[i % 3][(i / 3) % 3] = match i % 4 {
            0 => f32::INFINITY,
            1 => f32::NEG_INFINITY,
            2 => f32::MAX,
            _ => f32::MIN,
        };
    }
    let bvh = default_bvh(&tris);
    let stats = bvh.stats();
    assert_eq!(stats.triangles, 300);
    // Even hits on the triangles with infinite vertices agree: both structures see the same
    // per-triangle results and ignore NaN distances.
    agrees_with_brute_force(&tris, &rays(&mut rng, &tris, 3000));
}

#[test]
fn lopsided_input_needs_the_depth_limiter_and_still_agrees() {
    // Small triangles at exponentially growing distances: SAH splits peel off one at a time.
    let tris: Vec<_> = (0..400)
        .map(|i| {
            let x = 1.2f32.powi(i);
            [
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x, 1e-2, 0.0),
                Vec3::new(x, 0.0, 1e-2),
            ]
        })
        .collect();
    let bvh = Bvh2::build(
        &tris,
        &BuildParams {
            max_leaf_size: 1,
            ..BuildParams::default()
        },
    );
    bvh.validate().unwrap();
    let depth = bvh.stats().max_depth;
    assert!((20..64).contains(&depth), "depth {depth}");
    let oracle = BruteForce::new(&tris);
    for (i, tri) in tris.iter().enumerate() {
        let target = (tri[0] + tri[1] + tri[2]) / 3.0;
        for origin in [
            target + Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.003, 0.003),
        ] {
            let ray = Ray::new(origin, target - origin);
            let want = oracle.intersect(&ray, f32::INFINITY);
            assert_eq!(bvh.intersect(&ray, f32::INFINITY), want, "triangle {i}");
        }
    }
}

/// A row of `n` tiny disjoint triangles at `x = 0, 1, 2, ...`: any node's box is as long as the
/// run of triangles it holds, so a node holding a non-contiguous set costs at least as much as
/// one holding the run that spans it, and the cheapest tree is found by dynamic programming
/// over contiguous runs. The builder's tree must cost no less than that optimum (or the cost
/// is miscomputed) and within 5 % of it (binned SAH on evenly spaced centroids finds the
/// balanced splits; a tree that splits off one triangle at a time costs about `n / 2`).
#[test]
fn sah_cost_of_a_row_is_near_optimal() {
    const N: usize = 128;
    const E: f32 = 0.01;
    let tris: Vec<[Vec3; 3]> = (0..N)
        .map(|i| {
            let x = i as f32;
            [
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + E, E, 0.0),
                Vec3::new(x, E, E),
            ]
        })
        .collect();
    let params = BuildParams::default();
    let bvh = default_bvh(&tris);
    let got = bvh.stats().sah_cost;
    // Surface area of the box of the run i..=j, relative to the root's.
    let area = |i: usize, j: usize| {
        let (l, e) = ((j - i) as f64 + E as f64, E as f64);
        2.0 * (2.0 * l * e + e * e)
    };
    let weight = |i: usize, j: usize| area(i, j) / area(0, N - 1);
    let (ct, ci) = (
        params.traversal_cost as f64,
        params.intersection_cost as f64,
    );
    // best[i][j]: cheapest subtree over the run i..=j.
    let mut best = vec![vec![f64::INFINITY; N]; N];
    for len in 1..=N {
        for i in 0..=N - len {
            let j = i + len - 1;
            let mut c = if len <= params.max_leaf_size {
                ci * len as f64 * weight(i, j)
            } else {
                f64::INFINITY
            };
            for k in i..j {
                c = c.min(ct * weight(i, j) + best[i][k] + best[k + 1][j]);
            }
            best[i][j] = c;
        }
    }
    let optimum = best[0][N - 1];
    assert!(
        got >= optimum * (1.0 - 1e-9) && got <= optimum * 1.05,
        "SAH cost {got} vs optimum {optimum}"
    );
}

#[test]
fn stats_are_consistent() {
    let tris = soup(&mut Rng::new(5), 5000);
    let bvh = default_bvh(&tris);
    let s = bvh.stats();
    assert_eq!(s.nodes, 2 * s.leaves - 1);
    assert_eq!(s.triangles, 5000);
    assert_eq!(s.memory_bytes, s.nodes * 32 + s.triangles * (36 + 4));
    assert_eq!(s.memory_bytes, bvh.memory_bytes());
    assert!(s.largest_leaf <= 4 && s.max_depth < 64);
    // (The SAH cost is checked against the optimum in `sah_cost_of_a_row_is_near_optimal`.)
    assert!(!s.to_string().is_empty());
    // Smaller leaves cost more traversal steps and fewer tests; both stay valid.
    for max_leaf_size in [1, 2, 8, 32] {
        let b = Bvh2::build(
            &tris,
            &BuildParams {
                max_leaf_size,
                ..BuildParams::default()
            },
        );
        b.validate().unwrap();
        assert!(b.stats().largest_leaf <= max_leaf_size);
    }
    let bf = BruteForce::new(&tris);
    assert_eq!(bf.bounds(), bvh.bounds());
    assert_eq!(bf.name(), "brute-force");
}
