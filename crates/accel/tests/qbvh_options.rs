//! Every traversal option of the wide BVHs (QBVH and BVH8) gives the brute-force answer, and
//! the shadow cache never changes a visibility answer.

mod common;

use common::{check_ray, rays, soup, Rng};
use glam::Vec3;
use rt_accel::{AccelSpec, BruteForce};
use rt_core::{Accel, Ray};

const SPECS: [&str; 19] = [
    "qbvh",
    "qbvh:order=distance",
    "qbvh:order=unsorted",
    "qbvh:tstack",
    "qbvh:order=distance:tstack",
    "qbvh:order=unsorted:tstack",
    "qbvh:shadow-cache",
    "qbvh:leaf=4",
    "qbvh:leaf=1",
    "qbvh:icost=0.05",
    "qbvh:evh=20",
    "qbvh:evh=14:compact",
    "qbvh:bbah=12:compact",
    "bvh8",
    "bvh8:order=split",
    "bvh8:order=unsorted:tstack",
    "bvh8:shadow-cache",
    "bvh8:leaf=1",
    "bvh8:evh=14:compact",
];

#[test]
fn every_option_matches_brute_force() {
    for (k, spec) in SPECS.iter().enumerate() {
        for seed in 0..3u64 {
            let mut rng = Rng::new(9_000 + 10 * k as u64 + seed);
            let tris = soup(&mut rng, 1500);
            let accel = spec
                .parse::<AccelSpec>()
                .unwrap()
                .build(&tris)
                .expect("the structure builds");
            let oracle = BruteForce::new(&tris);
            let mut hits = 0;
            for (i, (ray, t_max)) in rays(&mut rng, &tris, 2000).into_iter().enumerate() {
                if let Err(e) = check_ray(accel.as_ref(), &oracle, &ray, t_max, &tris) {
                    panic!("{spec} seed {seed} ray {i} {ray:?} t_max {t_max}: {e}");
                }
                // Any-hit agrees with closest-hit, with and without a light-side endpoint.
                let closest = accel.intersect(&ray, t_max).is_some();
                assert_eq!(accel.occluded(&ray, t_max), closest, "{spec} ray {i}");
                let target = ray.origin + ray.dir * t_max.min(4.0);
                assert_eq!(
                    accel.occluded_toward(&ray, t_max, target),
                    closest,
                    "{spec} ray {i}"
                );
                hits += usize::from(closest);
            }
            assert!(hits > 500, "{spec}: only {hits} hits");
        }
    }
}

/// Shadow rays from points on the geometry toward a few light points, in coherent runs (as a
/// renderer issues them), so the cache is really used: every answer equals brute force.
#[test]
fn shadow_cache_never_changes_an_answer() {
    for (spec, other_spec) in [
        ("qbvh:shadow-cache", "qbvh:shadow-cache"),
        ("bvh8:shadow-cache", "qbvh:shadow-cache"),
    ] {
        shadow_cache_matches_brute_force(spec, other_spec);
    }
}

fn shadow_cache_matches_brute_force(spec: &str, other_spec: &str) {
    let mut rng = Rng::new(4242);
    let tris = soup(&mut rng, 300);
    let cached = spec
        .parse::<AccelSpec>()
        .unwrap()
        .build(&tris)
        .expect("the structure builds");
    // A second cached structure queried on the same thread, interleaved: tables must not
    // leak node indices between structures.
    let other_tris = soup(&mut rng, 500);
    let other = other_spec
        .parse::<AccelSpec>()
        .unwrap()
        .build(&other_tris)
        .expect("the structure builds");
    let oracle = BruteForce::new(&tris);
    let other_oracle = BruteForce::new(&other_tris);
    let lights: Vec<Vec3> = (0..4).map(|_| rng.unit_vec() * 3.0).collect();
    let (mut blocked, mut n) = (0, 0);
    for _ in 0..200 {
        let light = lights[rng.below(lights.len())];
        let base = tris[rng.below(tris.len())][0];
        for _ in 0..50 {
            let p = base + rng.vec_in(-0.1, 0.1);
            let target = light + rng.vec_in(-0.01, 0.01);
            let ray = Ray::new(p, target - p);
            let want = oracle.occluded(&ray, 1.0);
            assert_eq!(cached.occluded_toward(&ray, 1.0, target), want);
            assert_eq!(
                other.occluded_toward(&ray, 1.0, target),
                other_oracle.occluded(&ray, 1.0)
            );
            blocked += usize::from(want);
            n += 1;
        }
    }
    assert!(
        blocked > n / 20 && blocked < n * 19 / 20,
        "{blocked} of {n}"
    );
}

/// Several threads share one structure, each with its own table.
#[test]
fn shadow_cache_is_per_thread() {
    for spec in ["qbvh:shadow-cache", "bvh8:shadow-cache"] {
        shadow_cache_per_thread_matches_brute_force(spec);
    }
}

fn shadow_cache_per_thread_matches_brute_force(spec: &str) {
    let mut rng = Rng::new(777);
    let tris = soup(&mut rng, 2000);
    let cached = spec
        .parse::<AccelSpec>()
        .unwrap()
        .build(&tris)
        .expect("the structure builds");
    let oracle = BruteForce::new(&tris);
    std::thread::scope(|s| {
        for t in 0..4u64 {
            let (cached, oracle, tris) = (&cached, &oracle, &tris);
            s.spawn(move || {
                let mut rng = Rng::new(100 + t);
                let light = rng.vec_in(-1.5, 1.5);
                for _ in 0..5000 {
                    let p = tris[rng.below(tris.len())][1] + rng.vec_in(-0.05, 0.05);
                    let ray = Ray::new(p, light - p);
                    assert_eq!(
                        cached.occluded_toward(&ray, 1.0, light),
                        oracle.occluded(&ray, 1.0)
                    );
                }
            });
        }
    });
}

/// The thesis' crack-free tests in the leaves: every ray aimed at a closed mesh's vertices,
/// edge midpoints and faces hits it, at the distance the watertight test finds.
#[test]
fn crack_free_leaves_hit_closed_meshes() {
    let mesh = common::icosphere(3);
    let tris = mesh.triangles();
    let watertight = "qbvh"
        .parse::<AccelSpec>()
        .unwrap()
        .build(&tris)
        .expect("the structure builds");
    let mut rng = Rng::new(31);
    let targets: Vec<Vec3> = (0..3000)
        .map(|i| {
            let t = tris[rng.below(tris.len())];
            match i % 3 {
                0 => t[rng.below(3)],
                1 => (t[0] + t[1]) * 0.5,
                _ => (t[0] + t[1] + t[2]) / 3.0,
            }
        })
        .collect();
    for spec in [
        "qbvh:isect=subdivision",
        "qbvh:isect=hybrid",
        "bvh8:isect=subdivision",
    ] {
        let accel = spec
            .parse::<AccelSpec>()
            .unwrap()
            .build(&tris)
            .expect("the structure builds");
        for &p in &targets {
            // From outside, well away from grazing (a grazing ray may pass an ulp beside
            // a convex edge).
            let o = p.normalize() * 3.0 + rng.vec_in(-0.5, 0.5);
            let ray = Ray::new(o, p - o);
            let got = accel.intersect(&ray, f32::INFINITY);
            let want = watertight
                .intersect(&ray, f32::INFINITY)
                .unwrap_or_else(|| panic!("watertight missed {ray:?} aimed at {p:?}"));
            let got = got.unwrap_or_else(|| panic!("{spec}: {ray:?} missed"));
            assert!(
                (got.t - want.t).abs() <= 1e-5 * want.t,
                "{spec}: {got:?} {want:?}"
            );
            assert!(accel.occluded(&ray, f32::INFINITY));
        }
    }
}
