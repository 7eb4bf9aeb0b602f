//! Every structure on every frame of an animated scene against brute force (flat ones rebuilt,
//! IOSP through its index map). In detail:
//! the two-level structure and clustering (entry points at t = 1, 8 and 1000) against brute force over the scene's world copies, for every frame
//! of an animated scene, with rigid, scaled, non-uniformly scaled and mirroring instances; the
//! top level rebuilt and refitted; rays spawned from instance hits do not hit their own
//! triangle again; and updating follows the instances without building an object BVH.
//!
//! The two-level structure intersects a prototype's triangle with an inverse-transformed ray,
//! the brute force the world copy: the same surface up to the rounding of the transform, so
//! hits agree on the triangle and on `t` to a few ULPs of the scene's size, except where two
//! triangles are hit within that tolerance of each other, a ray grazes an edge or starts on
//! a surface.

mod common;

use common::{rays, rotation, soup, Rng};
use glam::Vec3;
use rt_accel::{AccelKind, AccelSpec, BruteForce, TopLevel};
use rt_core::animation::{Key, Motion};
use rt_core::instance::Prototype;
use rt_core::ray::spawn_ray;
use rt_core::transform::Transform;
use rt_core::{Accel, Scene};

/// A scene of a static soup and a prototype soup placed by `n` instances, half of them moving.
fn scene(rng: &mut Rng, n: usize) -> Scene {
    let mut s = Scene::empty();
    s.materials
        .push(rt_core::Material::diffuse("m", rt_core::Rgb::ONE));
    for t in soup(rng, 300) {
        s.push_triangle(t, 0);
    }
    let proto = soup(rng, 200);
    let p = s.add_prototype(Prototype {
        name: "p".into(),
        material_ids: vec![0; proto.len()],
        triangles: proto,
        ..Prototype::default()
    });
    for k in 0..n {
        let scale = match k % 4 {
            0 => Vec3::ONE,
            1 => Vec3::splat(0.3),
            2 => Vec3::new(2.0, 0.25, 0.7),
            _ => Vec3::new(-0.8, 0.6, 1.1),
        };
        let (axis_angle, angle) = rotation(rng).to_axis_angle();
        let rot = rt_core::glam::Quat::from_axis_angle(axis_angle, angle);
        let base = Transform::from_mat4(rt_core::glam::Mat4::from_scale_rotation_translation(
            scale,
            rot,
            rng.vec_in(-1.5, 1.5),
        ));
        let motion = (k % 2 == 0).then(|| {
            Motion::new(vec![
                Key::from_trs(0.0, Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
                Key::from_trs(
                    1.0,
                    rng.vec_in(-1.0, 1.0),
                    Vec3::new(0.0, 120.0, 30.0),
                    Vec3::ONE,
                ),
            ])
            .unwrap()
        });
        s.add_instance(format!("i{k}"), p, base, motion);
    }
    s
}

/// Hits of `a` against brute force on `rays`: (rays compared, disagreements beyond the
/// tolerance). Rounding of the transforms makes a few grazing rays legitimately differ.
fn compare(a: &dyn Accel, s: &Scene, rays: &[(rt_core::Ray, f32)]) -> (usize, usize) {
    let bf = BruteForce::new(&s.triangles);
    let tol = 1e-4;
    let mut bad = 0;
    for (ray, t_max) in rays {
        let (x, y) = (a.intersect(ray, *t_max), bf.intersect(ray, *t_max));
        let mut counted = rt_core::TraversalCounters::default();
        assert_eq!(
            a.closest_hit(ray, *t_max, Some(&mut counted)),
            x,
            "counting changes the hit"
        );
        let scale = ray.dir.length();
        // A ray starting on a surface (no offset) may find it at t ≈ 0 on one side of the
        // rounding and not on the other.
        let at_origin = |h: Option<rt_core::Hit>| h.is_some_and(|h| h.t * scale < tol);
        let ok = at_origin(x)
            || at_origin(y)
            || match (x, y) {
                (None, None) => true,
                // The same triangle, or another within the tolerance (overlapping coplanar ones).
                (Some(x), Some(y)) => (x.t - y.t).abs() * scale < tol,
                // A hit the other misses must be grazing: within tolerance of t_max or an edge.
                (Some(h), None) | (None, Some(h)) => {
                    (h.t - t_max).abs() * scale < tol || {
                        let b0 = 1.0 - h.b1 - h.b2;
                        b0.min(h.b1).min(h.b2) < 1e-4
                    }
                }
            };
        if let (Some(x), Some(y)) = (x, y) {
            // (At the origin the two are the same point up to the placement's rounding, which
            // moves the barycentrics of a hit at t ≈ 0 by more than its distance.)
            if x.prim == y.prim && !at_origin(Some(x)) && !at_origin(Some(y)) {
                // Barycentrics are ill-conditioned on slivers; the points they give are not.
                let v = &s.triangles[x.prim as usize];
                let (px, py) = (
                    rt_core::triangle::point_at(v, x.b1, x.b2),
                    rt_core::triangle::point_at(v, y.b1, y.b2),
                );
                // Along a grazing ray the crossing moves by the placement's rounding over the
                // cosine (such hits were rejected before the test decided hits within its
                // error bound in double precision).
                let n = rt_core::triangle::geometric_normal(v).normalize();
                let cos = ray.dir.normalize().dot(n).abs();
                assert!(
                    px.distance(py) * cos < 10.0 * tol,
                    "hit points differ on {}: {x:?} vs {y:?}",
                    x.prim
                );
            }
        }
        bad += usize::from(!ok);
        assert_eq!(
            a.occluded(ray, *t_max),
            x.is_some(),
            "occluded disagrees with intersect"
        );
    }
    (rays.len(), bad)
}

#[test]
fn two_level_and_clusters_match_brute_force_on_every_frame() {
    let clusters = |t: f32| {
        let mut spec = AccelSpec::new(AccelKind::Clusters);
        spec.cluster_t = t;
        spec
    };
    let two_level = |mode| {
        let mut spec = AccelSpec::new(AccelKind::TwoLevel);
        spec.top = mode;
        spec
    };
    for spec in [
        two_level(TopLevel::Rebuild),
        two_level(TopLevel::Refit),
        clusters(1.0),
        clusters(8.0),
        clusters(1000.0),
    ] {
        let mut rng = Rng::new(7);
        let mut s = scene(&mut rng, 12);
        let mut a = spec.build(&s).expect("the structure builds over the scene");
        let mut total = (0, 0);
        for frame in 0..5 {
            if frame > 0 {
                s.set_time(frame as f32 * 0.3);
                assert!(a.update(&s), "two-level follows its own scene in place");
            }
            let rays = rays(&mut rng, &s.triangles, 4000);
            let (n, bad) = compare(a.as_ref(), &s, &rays);
            total.0 += n;
            total.1 += bad;
        }
        assert!(
            total.1 * 1000 <= total.0,
            "{spec}: {} of {} rays disagree",
            total.1,
            total.0
        );
    }
}

#[test]
fn clustering_cuts_objects_into_more_entries_as_t_grows() {
    let s = scene(&mut Rng::new(5), 6);
    let entries = |t: f32| {
        rt_accel::TwoLevel::build_clustered(&s, &Default::default(), &Default::default(), t)
            .entry_count()
    };
    let one = rt_accel::TwoLevel::build(
        &s,
        &Default::default(),
        &Default::default(),
        TopLevel::Rebuild,
    )
    .entry_count();
    assert_eq!(one, 7, "the static object and six instances");
    let (a, b, c) = (entries(1.0), entries(8.0), entries(1000.0));
    assert!(one < a && a <= b && b < c, "{one} {a} {b} {c}");
}

#[test]
fn flat_structures_do_not_update_in_place_and_a_new_scene_needs_a_build() {
    let mut rng = Rng::new(3);
    let s = scene(&mut rng, 4);
    let mut flat = AccelSpec::new(AccelKind::Bvh8)
        .build(&s)
        .expect("the structure builds over the scene");
    assert!(!flat.update(&s));
    let mut two = AccelSpec::new(AccelKind::TwoLevel)
        .build(&s)
        .expect("the structure builds over the scene");
    let other = scene(&mut Rng::new(4), 5);
    assert!(!two.update(&other), "different instances: rebuild");
}

#[test]
fn rays_spawned_from_instance_hits_leave_their_triangle() {
    let mut rng = Rng::new(11);
    let s = scene(&mut rng, 8);
    let a = AccelSpec::new(AccelKind::TwoLevel)
        .build(&s)
        .expect("the structure builds over the scene");
    let mut checked = 0;
    for (ray, t_max) in rays(&mut rng, &s.triangles, 20_000) {
        let Some(hit) = a.intersect(&ray, t_max) else {
            continue;
        };
        let si = s.surface(&hit, 0.0);
        if si.instance.is_none() {
            continue;
        }
        for side in [1.0f32, -1.0] {
            let d = (si.ng * side + rng.unit_vec() * 0.9).normalize_or_zero();
            if d == Vec3::ZERO || d.dot(si.ng) * side <= 0.0 {
                continue;
            }
            let r = spawn_ray(si.p, si.p_error, si.ng, d);
            if let Some(again) = a.intersect(&r, f32::INFINITY) {
                assert_ne!(
                    again.prim, hit.prim,
                    "a ray leaving triangle {} hit it again at t = {}",
                    hit.prim, again.t
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 1000, "only {checked} spawned rays");
}

#[test]
fn moving_instances_rebuilds_no_object_bvh() {
    let mut rng = Rng::new(9);
    let mut s = scene(&mut rng, 6);
    for clustered in [false, true] {
        let mut a = if clustered {
            rt_accel::TwoLevel::build_clustered(&s, &Default::default(), &Default::default(), 8.0)
        } else {
            rt_accel::TwoLevel::build(
                &s,
                &Default::default(),
                &Default::default(),
                TopLevel::Refit,
            )
        };
        // One object for the static soup and one for the shared prototype.
        assert_eq!(a.object_count(), 2);
        let objects = a.object_addresses();
        for frame in 1..6 {
            s.set_time(frame as f32 * 0.2);
            assert!(a.update(&s));
            assert_eq!(
                a.object_addresses(),
                objects,
                "an object BVH moved in memory"
            );
            assert_eq!(a.top_updates(), frame + 1);
        }
    }
}

/// Motion blur: with the shutter open over `[0.2, 0.8]`, rays at shutter time `u` hit what
/// brute force over the scene set to time `0.2 + 0.6 u` hits (the swept boxes hold the
/// instances between the box samples too), and shading a hit at `u` gives that scene's
/// surface point. Control: a structure built with the shutter closed answers for the opening
/// time only, which the comparison sees.
#[test]
fn motion_blurred_rays_hit_the_scene_at_their_time() {
    let (open, shutter) = (0.2f32, 0.6f32);
    let mut rng = Rng::new(21);
    let mut s = scene(&mut rng, 10);
    s.set_time(open);
    let closed = AccelSpec::new(AccelKind::TwoLevel)
        .build(&s)
        .expect("the structure builds over the scene");
    s.shutter = shutter;
    let mut clusters = AccelSpec::new(AccelKind::Clusters);
    clusters.cluster_t = 8.0;
    for spec in [AccelSpec::new(AccelKind::TwoLevel), clusters] {
        let a = spec.build(&s).expect("the structure builds over the scene");
        assert!(a.interpolates_motion());
        let (mut total, mut bad, mut control_bad, mut shaded) = (0, 0, 0, 0);
        for k in 0..12 {
            // Times off the box samples (sixteenths of the shutter) on purpose.
            let u = (k as f32 + 0.37) / 12.0;
            let mut at = s.clone();
            at.shutter = 0.0;
            at.set_time(open + u * shutter);
            let rays: Vec<_> = rays(&mut rng, &at.triangles, 1500)
                .into_iter()
                .map(|(r, t)| (r.at_time(u), t))
                .collect();
            let (n, b) = compare(a.as_ref(), &at, &rays);
            total += n;
            bad += b;
            let bf = BruteForce::new(&at.triangles);
            control_bad += rays
                .iter()
                .filter(|(r, t)| {
                    let (x, y) = (closed.intersect(r, *t), bf.intersect(r, *t));
                    x.map(|h| (h.prim, (h.t * 1e3) as i64))
                        != y.map(|h| (h.prim, (h.t * 1e3) as i64))
                })
                .count();
            for (ray, t_max) in &rays {
                let Some(hit) = a.intersect(ray, *t_max) else {
                    continue;
                };
                let (blurred, still) = (s.surface(&hit, u), at.surface(&hit, 0.0));
                assert!(
                    blurred.p.distance(still.p) < 1e-4 && blurred.ng.dot(still.ng) > 0.9999,
                    "shading at time {u}: {blurred:?} vs {still:?}"
                );
                assert_eq!(blurred.time, u);
                shaded += 1;
            }
        }
        assert!(shaded > 1000, "only {shaded} hits shaded");
        assert!(
            bad * 1000 <= total,
            "{spec}: {bad} of {total} rays disagree"
        );
        assert!(
            control_bad * 20 > total,
            "the closed-shutter control disagrees on only {control_bad} of {total} rays"
        );
    }
}

/// Every structure `render --accel` offers, over the animated scene on every frame (rebuilt
/// where it cannot update in place), against brute force on the rays of `common::rays` (axis
/// rays, zero and negative-zero components, origins on triangles and in axis planes).
#[test]
fn every_structure_matches_brute_force_on_every_frame() {
    for kind in AccelKind::ALL {
        let mut rng = Rng::new(31);
        let mut s = scene(&mut rng, 6);
        let spec = AccelSpec::new(kind);
        let mut a = spec
            .build(rt_accel::BuildInput::SceneToReorder(&mut s))
            .unwrap();
        let (mut total, mut bad) = (0, 0);
        for frame in 0..3 {
            if frame > 0 {
                s.set_time(frame as f32 * 0.4);
                if !a.update(&s) {
                    a = spec
                        .build(rt_accel::BuildInput::SceneToReorder(&mut s))
                        .unwrap();
                }
            }
            let rays = rays(&mut rng, &s.triangles, 1500);
            let (n, b) = compare(a.as_ref(), &s, &rays);
            total += n;
            bad += b;
        }
        assert!(
            bad * 1000 <= total,
            "{kind:?}: {bad} of {total} rays disagree"
        );
    }
}
