//! The on-demand QBVH: the same answers as brute force and as an eagerly built QBVH, groups
//! built only when reached and exactly once under concurrent queries.
//!
//! The timing test is ignored by default; run it with `cargo test -p rt-accel --release --test
//! on_demand -- --ignored --nocapture`.

mod common;

use common::{check_soup, icosphere, soup, Built, Rng};
use glam::Vec3;
use rayon::prelude::*;
use rt_accel::wide::DEFAULT_LEAF_SIZE;
use rt_accel::{BuildParams, OnDemandQbvh, Qbvh, Split, WideOptions};
use rt_core::{Aabb, Accel, Hit, Ray, TraversalCounters};
use std::time::Instant;

/// An on-demand QBVH with small groups, so that the soups of a few thousand triangles have
/// dozens of groups.
struct Small<const G: usize>(OnDemandQbvh);

impl<const G: usize> Accel for Small<G> {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn closest_hit(&self, ray: &Ray, t_max: f32, c: Option<&mut TraversalCounters>) -> Option<Hit> {
        self.0.closest_hit(ray, t_max, c)
    }
    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        toward: Option<Vec3>,
        c: Option<&mut TraversalCounters>,
    ) -> bool {
        self.0.any_hit(ray, t_max, toward, c)
    }
    fn bounds(&self) -> Aabb {
        self.0.bounds()
    }
    fn memory_bytes(&self) -> usize {
        self.0.memory_bytes()
    }
    fn counts_traversal(&self) -> bool {
        self.0.counts_traversal()
    }
}

impl<const G: usize> Built for Small<G> {
    fn build(tris: &[[Vec3; 3]], params: &BuildParams) -> Self {
        let q = OnDemandQbvh::with_group_size(tris, params, &WideOptions::default(), G);
        assert_eq!(q.built_groups(), 0);
        Small(q)
    }
    fn validate(&self) -> Result<(), rt_accel::ValidationError> {
        self.0.validate()
    }
    fn references(&self) -> Vec<([Vec3; 3], u32)> {
        self.0.references()
    }
}

fn qbvh_params() -> BuildParams {
    BuildParams {
        max_leaf_size: DEFAULT_LEAF_SIZE,
        ..BuildParams::default()
    }
}

/// A ray from outside the unit sphere towards a random point near it.
fn ray_at_sphere(rng: &mut Rng) -> Ray {
    let o = rng.unit_vec() * rng.range(1.5, 4.0);
    let target = rng.vec_in(-1.2, 1.2);
    Ray::new(o, target - o)
}

/// Same distance (bit for bit) and either the same triangle or one the other's triangle test
/// puts at exactly that distance too (a ray through a shared edge or vertex).
fn same_answer(got: Option<Hit>, want: Option<Hit>, ray: &Ray, tris: &[[Vec3; 3]]) -> bool {
    match (got, want) {
        (None, None) => true,
        (Some(g), Some(w)) => {
            g.t.to_bits() == w.t.to_bits()
                && (g == w
                    || common::hit_one(ray, &tris[g.prim as usize], f32::INFINITY)
                        == Some((g.t, g.b1, g.b2)))
        }
        _ => false,
    }
}

#[test]
fn soups_match_brute_force() {
    // Default group size: one or two groups at these sizes.
    for (k, n) in [1, 2, 10, 100, 3000].into_iter().enumerate() {
        check_soup::<OnDemandQbvh>(9_000 + k as u64, n, 1000, &qbvh_params());
    }
    // Dozens to thousands of groups, groups of one triangle included.
    for seed in 0..3 {
        assert!(check_soup::<Small<64>>(9_100 + seed, 3000, 3000, &qbvh_params()) > 500);
        check_soup::<Small<7>>(9_200 + seed, 2000, 2000, &BuildParams::default());
    }
    check_soup::<Small<1>>(9_300, 500, 2000, &BuildParams::default());
    // Beyond 2^16 triangles the top tree's planes come from a sample.
    assert!(check_soup::<Small<500>>(9_350, 70_000, 600, &qbvh_params()) > 100);
    // Other build parameters pass through to the groups, parallel ones included.
    let params = [
        BuildParams {
            max_leaf_size: 1,
            ..BuildParams::default()
        },
        BuildParams {
            split: Split::Evh { t: 10 },
            compact_leaves: true,
            ..qbvh_params()
        },
        BuildParams {
            parallel: false,
            ..qbvh_params()
        },
    ];
    for (k, p) in params.iter().enumerate() {
        check_soup::<Small<100>>(9_400 + k as u64, 3000, 2000, p);
    }
}

#[test]
fn occluded_agrees_with_intersect() {
    let mut rng = Rng::new(77);
    let mut tris = icosphere(4).triangles();
    tris.extend(soup(&mut rng, 2000));
    let q = OnDemandQbvh::with_group_size(&tris, &qbvh_params(), &WideOptions::default(), 200);
    let mut hits = 0;
    for (ray, t_max) in common::rays(&mut rng, &tris, 5000) {
        let hit = q.intersect(&ray, t_max);
        assert_eq!(q.occluded(&ray, t_max), hit.is_some(), "{ray:?} {t_max}");
        hits += usize::from(hit.is_some());
    }
    assert!(hits > 1000);
    q.validate().unwrap();
}

#[test]
fn a_narrow_bundle_builds_only_the_groups_it_reaches() {
    let tris = icosphere(5).triangles();
    let q = OnDemandQbvh::with_group_size(&tris, &qbvh_params(), &WideOptions::default(), 256);
    let full = Qbvh::build_with(&tris, &qbvh_params(), &WideOptions::default());
    assert!(q.groups() >= tris.len() / 256);
    assert_eq!((q.built_groups(), q.build_count()), (0, 0));
    let top_only = q.memory_bytes();
    q.validate().unwrap();

    // A tight bundle from z = 3 at the sphere's pole.
    let mut rng = Rng::new(3);
    for _ in 0..2000 {
        let d = Vec3::new(rng.range(-0.01, 0.01), rng.range(-0.01, 0.01), -1.0);
        let ray = Ray::new(Vec3::new(0.0, 0.0, 3.0), d);
        let hit = q.intersect(&ray, f32::INFINITY);
        assert!(hit.is_some());
        assert!(same_answer(
            hit,
            full.intersect(&ray, f32::INFINITY),
            &ray,
            &tris
        ));
    }
    let built = q.built_groups();
    assert!(built >= 1);
    assert!(
        built * 10 < q.groups(),
        "{built} of {} groups built",
        q.groups()
    );
    assert_eq!(q.build_count(), built);
    assert!(q.memory_bytes() > top_only);
    q.validate().unwrap();

    // Missing the scene builds nothing more.
    let miss = Ray::new(Vec3::new(5.0, 5.0, 5.0), Vec3::X);
    assert_eq!(q.intersect(&miss, f32::INFINITY), None);
    assert!(!q.occluded(&miss, f32::INFINITY));
    assert_eq!(q.built_groups(), built);

    q.build_all();
    assert_eq!(q.built_groups(), q.groups());
    assert_eq!(q.build_count(), q.groups());
    q.validate().unwrap();
}

#[test]
fn counted_queries_count_the_top_tree_too() {
    let tris = icosphere(4).triangles();
    let q = OnDemandQbvh::with_group_size(&tris, &qbvh_params(), &WideOptions::default(), 64);
    assert!(q.counts_traversal());
    let ray = Ray::new(Vec3::new(0.1, 0.2, 3.0), -Vec3::Z);
    let mut c = TraversalCounters::default();
    let hit = q.closest_hit(&ray, f32::INFINITY, Some(&mut c));
    assert_eq!(hit, q.intersect(&ray, f32::INFINITY));
    assert!(hit.is_some());
    // Root, at least one pair of top-tree children and the group's own root.
    assert!(c.nodes_visited >= 4, "{c:?}");
    assert!(c.leaves_visited >= 1 && c.prims_tested >= 1, "{c:?}");
    // Counters accumulate.
    let before = c;
    q.closest_hit(&ray, f32::INFINITY, Some(&mut c));
    assert_eq!(c.nodes_visited, 2 * before.nodes_visited);
}

/// Many rayon threads querying a fresh structure at once: the answers of an eagerly built QBVH,
/// and no group built twice. With `parallel` on and groups above the binary builder's parallel
/// threshold (4096), a group build that used rayon inside `get_or_init` could deadlock.
#[test]
fn concurrent_queries_build_each_group_once() {
    let tris = icosphere(6).triangles();
    let params = qbvh_params();
    let full = Qbvh::build_with(&tris, &params, &WideOptions::default());
    let mut rng = Rng::new(11);
    let rays: Vec<Ray> = (0..100_000).map(|_| ray_at_sphere(&mut rng)).collect();
    let want: Vec<Option<Hit>> = rays
        .par_iter()
        .map(|r| full.intersect(r, f32::INFINITY))
        .collect();
    assert!(want.iter().filter(|h| h.is_some()).count() > 30_000);

    for group_size in [None, Some(300), Some(10_000)] {
        let q = match group_size {
            None => OnDemandQbvh::new(&tris, &params, &WideOptions::default()),
            Some(g) => OnDemandQbvh::with_group_size(&tris, &params, &WideOptions::default(), g),
        };
        assert_eq!(q.built_groups(), 0);
        let got: Vec<(Option<Hit>, bool)> = rays
            .par_iter()
            .map(|r| (q.intersect(r, f32::INFINITY), q.occluded(r, f32::INFINITY)))
            .collect();
        for (i, ((hit, occluded), w)) in got.iter().zip(&want).enumerate() {
            assert!(
                same_answer(*hit, *w, &rays[i], &tris),
                "groups {group_size:?}, ray {i}: {hit:?} vs {w:?}"
            );
            assert_eq!(*occluded, w.is_some());
        }
        let built = q.built_groups();
        assert!(built <= q.groups());
        assert_eq!(q.build_count(), built, "a group was built twice");
        assert!(built > 0);
        q.validate().unwrap();
    }
}

#[test]
fn empty_scene() {
    let q = OnDemandQbvh::new(&[], &BuildParams::default(), &WideOptions::default());
    q.validate().unwrap();
    assert_eq!((q.groups(), q.built_groups()), (0, 0));
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(q.intersect(&ray, f32::INFINITY), None);
    assert!(!q.occluded(&ray, f32::INFINITY));
    let mut c = TraversalCounters::default();
    assert_eq!(q.closest_hit(&ray, f32::INFINITY, Some(&mut c)), None);
    assert!(q.bounds().is_empty());
    assert_eq!(q.name(), "qbvh-lazy");
    q.build_all();
    assert_eq!(q.memory_bytes(), 0);
}

#[test]
fn single_triangle() {
    let tri = [[
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ]];
    let q = OnDemandQbvh::new(&tri, &BuildParams::default(), &WideOptions::default());
    q.validate().unwrap();
    assert_eq!((q.groups(), q.built_groups()), (1, 0));
    assert_eq!(q.bounds(), Aabb::from_points(&tri[0]));

    // A miss of the bounds builds nothing.
    let miss = Ray::new(Vec3::new(2.0, 2.0, 1.0), -Vec3::Z);
    assert_eq!(q.intersect(&miss, f32::INFINITY), None);
    assert_eq!(q.built_groups(), 0);

    let ray = Ray::new(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z);
    let hit = q.intersect(&ray, f32::INFINITY).unwrap();
    assert_eq!((hit.prim, hit.t, hit.b1, hit.b2), (0, 2.0, 0.25, 0.25));
    assert_eq!(q.built_groups(), 1);
    assert!(q.occluded(&ray, 2.0));
    assert!(!q.occluded(&ray, 1.5));
    assert_eq!(q.intersect(&ray, 1.5), None);
    q.validate().unwrap();
}

/// Pinhole camera rays: `n` x `n` pixels from `eye` looking down -z with half-angle `half_fov`.
fn camera(eye: Vec3, half_fov_deg: f32, n: usize) -> Vec<Ray> {
    let s = half_fov_deg.to_radians().tan();
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            let d = Vec3::new(
                (2.0 * (x + 0.5) / n as f32 - 1.0) * s,
                (1.0 - 2.0 * (y + 0.5) / n as f32) * s,
                -1.0,
            );
            Ray::new(eye, d)
        })
        .collect()
}

fn render(a: &dyn Accel, rays: &[Ray]) -> usize {
    rays.par_iter()
        .filter(|r| a.intersect(r, f32::INFINITY).is_some())
        .count()
}

#[test]
#[ignore = "timing, not a check"]
fn lazy_vs_eager_timing() {
    let tris = icosphere(8).triangles();
    let params = qbvh_params();
    let opts = WideOptions::default();
    println!(
        "icosphere(8): {} triangles, {} rayon threads, group size {}",
        tris.len(),
        rayon::current_num_threads(),
        rt_accel::on_demand::default_group_size(tris.len())
    );
    let views = [
        (
            "whole sphere, 512^2",
            camera(Vec3::new(0.1, 0.2, 3.0), 22.5, 512),
        ),
        (
            "close-up, 512^2",
            camera(Vec3::new(0.1, 0.2, 1.3), 5.0, 512),
        ),
    ];

    let start = Instant::now();
    let full = Qbvh::build_with(&tris, &params, &opts);
    let t_full = start.elapsed().as_secs_f64();
    println!(
        "eager build: {:8.1} ms, {:.1} MB",
        t_full * 1e3,
        full.memory_bytes() as f64 / 1e6
    );
    for (name, rays) in &views {
        let start = Instant::now();
        let hits = render(&full, rays);
        let t = start.elapsed().as_secs_f64();
        println!(
            "  {name}: render {:7.1} ms ({:.2} Mrays/s, {hits} hits); build + render {:7.1} ms",
            t * 1e3,
            rays.len() as f64 / t / 1e6,
            (t_full + t) * 1e3
        );
    }

    for (name, rays) in &views {
        let start = Instant::now();
        let q = OnDemandQbvh::new(&tris, &params, &opts);
        let t_new = start.elapsed().as_secs_f64();
        let top = q.memory_bytes();
        let start = Instant::now();
        let hits = render(&q, rays);
        let t_first = start.elapsed().as_secs_f64();
        let start = Instant::now();
        render(&q, rays);
        let t_second = start.elapsed().as_secs_f64();
        println!(
            "lazy, {name}: new {:6.1} ms ({} groups, {:.1} MB); first image {:7.1} ms \
             ({hits} hits, {} groups built, {:.1} MB) -> new + first image {:7.1} ms; \
             second image {:7.1} ms ({:.2} Mrays/s)",
            t_new * 1e3,
            q.groups(),
            top as f64 / 1e6,
            t_first * 1e3,
            q.built_groups(),
            q.memory_bytes() as f64 / 1e6,
            (t_new + t_first) * 1e3,
            t_second * 1e3,
            rays.len() as f64 / t_second / 1e6
        );
        let start = Instant::now();
        q.build_all();
        println!(
            "  build_all of the rest: {:7.1} ms, {:.1} MB",
            start.elapsed().as_secs_f64() * 1e3,
            q.memory_bytes() as f64 / 1e6
        );
    }

    // Traversal work per ray once everything is built.
    let q = OnDemandQbvh::new(&tris, &params, &opts);
    q.build_all();
    for a in [&full as &dyn Accel, &q] {
        let mut c = TraversalCounters::default();
        for r in &views[0].1 {
            a.closest_hit(r, f32::INFINITY, Some(&mut c));
        }
        let n = views[0].1.len() as f64;
        println!(
            "{:>10}: {:.1} boxes/ray, {:.1} leaves/ray, {:.1} tris/ray",
            a.name(),
            c.nodes_visited as f64 / n,
            c.leaves_visited as f64 / n,
            c.prims_tested as f64 / n
        );
    }
}
