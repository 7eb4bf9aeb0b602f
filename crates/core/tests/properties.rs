//! Fixed-seed property tests (proptest) of the intersection, ray-offset and sampling code on
//! random inputs. The seed is fixed and failures are not persisted to files, so CI sees the
//! same inputs every run; a failure prints the minimal input that proptest shrank it to.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use rt_core::{
    distribution::{Distribution1D, Distribution2D},
    environment::{EnvMap, Environment},
    glam::{DVec3, Quat, Vec2, Vec3},
    ray::{offset_ray_origin, shadow_segment},
    sampling::{
        blinn_phong_half, blinn_phong_half_pdf, concentric_disk, cosine_hemisphere,
        power_heuristic, uniform_sphere, uniform_triangle,
    },
    triangle::{geometric_normal, intersect_triangle, point_with_error, RayPrecomp},
    Ray, Rgb,
};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x5eed_2026),
        failure_persistence: None,
        max_global_rejects: cases * 4,
        ..Config::default()
    }
}

/// A point in [0, 1)².
fn unit2() -> impl Strategy<Value = Vec2> {
    (0.0f32..1.0, 0.0f32..1.0).prop_map(|(x, y)| Vec2::new(x, y))
}

fn unit_vector() -> impl Strategy<Value = Vec3> {
    unit2().prop_map(uniform_sphere)
}

fn rotation() -> impl Strategy<Value = Quat> {
    (unit_vector(), 0.0f32..std::f32::consts::TAU).prop_map(|(a, t)| Quat::from_axis_angle(a, t))
}

/// A random rotation, or (half the time) one that keeps the triangle axis-aligned: floors and
/// walls have exact coordinates along their normal, the case where an offset that ignores the
/// triangle's size fails most.
fn orientation() -> impl Strategy<Value = Quat> {
    prop_oneof![
        rotation(),
        Just(Quat::IDENTITY),
        Just(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
        Just(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)),
    ]
}

/// A triangle of size `10^e` (e in [-3, 5]) with its centroid up to 10^5 from the origin (half
/// the time within 10⁻³ of its size, so that points near the world origin lie on a triangle far
/// larger than their coordinates), with an aspect ratio of at most 1:100 (the offset's bound
/// covers slivers up to 1:10⁴, but "never re-hit" is meant for surfaces, not needles).
fn triangle() -> impl Strategy<Value = [Vec3; 3]> {
    (
        -3.0f32..5.0,
        orientation(),
        unit_vector(),
        prop_oneof![0.0f32..1.0, Just(0.0f32)],
        0.01f32..1.0,
        -1.0f32..1.0,
    )
        .prop_map(|(e, q, dir, dist, height, apex)| {
            let size = 10f32.powf(e);
            let centre = dir * (1e5 * dist * dist + 1e-3 * size * (1.0 - dist));
            let local = [
                Vec3::new(-0.5, 0.0, 0.0),
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(apex, 0.0, height),
            ];
            let centroid = (local[0] + local[1] + local[2]) / 3.0;
            local.map(|v| centre + q * ((v - centroid) * size))
        })
}

/// A direction about +z with `cos θ` log-uniform in [10⁻³, 1]: grazing directions as often as
/// steep ones (below 10⁻³ the side of the plane is ambiguous at f32 normal precision).
fn leaving_direction() -> impl Strategy<Value = Vec3> {
    (-3.0f32..0.0, 0.0f32..std::f32::consts::TAU).prop_map(|(c, phi)| {
        let c = 10f32.powf(c);
        let s = (1.0 - c * c).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    })
}

fn barycentrics() -> impl Strategy<Value = (f32, f32)> {
    unit2().prop_map(uniform_triangle)
}

fn plane_distance(v: &[Vec3; 3], p: Vec3) -> f64 {
    let d = |a: Vec3| a.as_dvec3();
    let n: DVec3 = (d(v[1]) - d(v[0])).cross(d(v[2]) - d(v[0])).normalize();
    n.dot(d(p) - d(v[0]))
}

proptest! {
    #![proptest_config(config(100_000))]

    /// A ray leaving a triangle from the offset origin is on the side it leaves to and never
    /// hits the triangle again (fails with the previous offset, ULPs of the point).
    #[test]
    fn offset_origins_are_on_the_right_side_and_never_re_hit(
        v in triangle(),
        (b1, b2) in prop_oneof![barycentrics(), Just((1.0f32 / 3.0, 1.0f32 / 3.0))],
        local in leaving_direction(),
        back in any::<bool>(),
    ) {
        let n = geometric_normal(&v).normalize();
        prop_assume!(n.is_finite());
        let (p, err) = point_with_error(&v, b1, b2);
        let side = if back { -n } else { n };
        let w = rt_core::frame::Frame::from_normal(side).to_world(local).normalize();
        prop_assume!(w.dot(side) > 5e-4);
        let o = offset_ray_origin(p, err, n, w);
        let h = plane_distance(&v, o) * if back { -1.0 } else { 1.0 };
        prop_assert!(h > 0.0, "origin {o} is {h} on the wrong side");
        let hit = intersect_triangle(&RayPrecomp::new(&Ray::new(o, w)), &v, f32::INFINITY);
        prop_assert!(hit.is_none(), "re-hit at {hit:?} from {o} along {w}");
    }

    /// Watertight: a ray through a point of the edge two coplanar triangles share (not its
    /// ends: two triangles do not cover a vertex's surroundings) hits at least one of them, at
    /// t > 0, and the hit point reconstructed from barycentrics lies on the plane within its
    /// error bound. The triangles lie within 10³ of their size from the origin, so that their
    /// vertices are distinct floats at all.
    #[test]
    fn rays_through_a_shared_edge_hit_one_triangle_on_its_plane(
        q in rotation(),
        e in -3.0f32..5.0,
        centre in unit_vector(),
        dist in 0.0f32..1.0,
        s in 0.001f32..0.999,
        (ax, ay) in (-1.0f32..1.0, 0.05f32..1.0),
        (bx, by) in (-1.0f32..1.0, 0.05f32..1.0),
        dir in unit_vector(),
        back in 0.1f32..10.0,
    ) {
        let size = 10f32.powf(e);
        let t = centre * 1e3 * size * dist * dist;
        let m = |x: f32, y: f32| t + q * (Vec3::new(x, y, 0.0) * size);
        let (v0, v1) = (m(-0.5, 0.0), m(0.5, 0.0));
        let tris = [[v0, v1, m(ax, ay)], [v1, v0, m(bx, -by)]];
        let n = q * Vec3::Z;
        prop_assume!(dir.dot(n).abs() > 0.05);
        let point = v0 + (v1 - v0) * s;
        let ray = Ray::new(point - dir * (back * size), dir);
        let pre = RayPrecomp::new(&ray);
        let hits: Vec<_> = tris
            .iter()
            .filter_map(|v| intersect_triangle(&pre, v, f32::INFINITY).map(|h| (v, h)))
            .collect();
        prop_assert!(!hits.is_empty(), "no hit through the shared edge at s = {s}");
        for (v, h) in hits {
            prop_assert!(h.t > 0.0 && h.t.is_finite());
            let (p, err) = point_with_error(v, h.b1, h.b2);
            let dist = plane_distance(v, p).abs();
            let bound = n.abs().dot(err) as f64;
            prop_assert!(dist <= bound, "hit point {dist} off the plane, bound {bound}");
        }
    }

    /// Shadow segments between two points of one plane stay on one side of it.
    #[test]
    fn shadow_segments_along_a_plane_stay_off_it(
        v in triangle(),
        a in barycentrics(),
        b in barycentrics(),
        flip in any::<(bool, bool)>(),
    ) {
        let n = geometric_normal(&v).normalize();
        prop_assume!(n.is_finite());
        let (p, pe) = point_with_error(&v, a.0, a.1);
        let (q, qe) = point_with_error(&v, b.0, b.1);
        prop_assume!(p != q);
        let sign = |f: bool| if f { -1.0 } else { 1.0 };
        let (ray, t_max) = shadow_segment(p, pe, n * sign(flip.0), q, qe, n * sign(flip.1));
        let hit = intersect_triangle(&RayPrecomp::new(&ray), &v, t_max);
        prop_assert!(hit.is_none(), "segment from {} hits its own plane: {hit:?}", ray.origin);
    }
}

proptest! {
    #![proptest_config(config(4_000))]

    /// Warps land in their domains with finite values, and the Blinn–Phong pdf is finite.
    #[test]
    fn warps_stay_in_their_domains(u in unit2(), k in 0.0f32..1e4) {
        let d = concentric_disk(u);
        prop_assert!(d.is_finite() && d.length() <= 1.0 + 1e-6);
        let w = cosine_hemisphere(u);
        prop_assert!(w.is_finite() && w.z >= 0.0 && (w.length() - 1.0).abs() < 1e-5);
        let s = uniform_sphere(u);
        prop_assert!(s.is_finite() && (s.length() - 1.0).abs() < 1e-5);
        let (b1, b2) = uniform_triangle(u);
        prop_assert!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 + 1e-6);
        let h = blinn_phong_half(u, k);
        prop_assert!(h.is_finite() && h.z >= 0.0 && (h.length() - 1.0).abs() < 1e-5);
        let pdf = blinn_phong_half_pdf(h.z, k);
        prop_assert!(pdf.is_finite() && pdf >= 0.0);
    }

    /// The MIS weight is a weight, whatever the pdfs (zero and infinite included).
    #[test]
    fn power_heuristic_is_in_unit_interval(
        f in prop_oneof![Just(0.0f32), Just(f32::INFINITY), 0.0f32..1e30],
        g in prop_oneof![Just(0.0f32), Just(f32::INFINITY), 0.0f32..1e30],
    ) {
        let w = power_heuristic(f, g);
        prop_assert!((0.0..=1.0).contains(&w), "{f} {g}: {w}");
    }

    /// A 1D distribution over arbitrary weights (zeros, huge, NaN, negative, infinite): the
    /// pmf sums to one, sampling never picks a zero-weight bin when another has weight, the
    /// reported probability is the bin's, and continuous samples stay in their bin.
    #[test]
    fn distribution_1d_pdfs_match_samples(
        weights in prop::collection::vec(
            prop_oneof![
                4 => 0.0f32..10.0,
                1 => Just(0.0f32),
                1 => Just(f32::NAN),
                1 => Just(f32::INFINITY),
                1 => Just(-1.0f32),
                1 => 1e30f32..3e38,
            ],
            1..40,
        ),
        u in 0.0f32..1.0,
    ) {
        let d = Distribution1D::new(&weights);
        let sum: f64 = (0..d.len()).map(|i| d.discrete_pmf(i) as f64).sum();
        prop_assert!((sum - 1.0).abs() < 1e-5, "pmf sums to {sum}");
        let (i, p, rem) = d.sample_discrete(u);
        prop_assert!(i < d.len() && (0.0..1.0).contains(&rem));
        prop_assert_eq!(p, d.discrete_pmf(i));
        let valid = |w: f32| w.is_finite() && w > 0.0;
        if weights.iter().any(|&w| valid(w)) {
            prop_assert!(p > 0.0, "picked empty bin {i} of {weights:?}");
        }
        let (x, pdf, bin) = d.sample_continuous(u);
        prop_assert!((0.0..1.0).contains(&x) && pdf.is_finite());
        prop_assert_eq!(((x * d.len() as f32) as usize).min(d.len() - 1), bin);
        prop_assert_eq!(pdf, d.pdf_bin(bin));
    }

    /// A 2D distribution: samples in [0, 1)² whose density `pdf` reproduces.
    #[test]
    fn distribution_2d_pdf_matches_sample(
        (w, h, weights) in (1usize..12, 1usize..12).prop_flat_map(|(w, h)| {
            (Just(w), Just(h), prop::collection::vec(prop_oneof![3 => 0.0f32..5.0, 1 => Just(0.0f32)], w * h))
        }),
        u in unit2(),
    ) {
        prop_assume!(weights.iter().any(|&x| x > 0.0));
        let d = Distribution2D::new(&weights, w, h);
        let (p, pdf) = d.sample(u);
        prop_assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0, "{p}");
        prop_assert!(pdf.is_finite() && pdf > 0.0);
        let again = d.pdf(p);
        prop_assert!((again - pdf).abs() <= 1e-4 * pdf, "{again} vs {pdf}");
    }

    /// Environment-map sampling: finite unit directions whose pdf the map reproduces, up to
    /// 0.1° from the poles (there `sin θ` is below 2·10⁻³ and its own rounding dominates).
    #[test]
    fn environment_samples_have_consistent_pdfs(
        texels in prop::collection::vec(0.0f32..4.0, 8 * 4),
        u in unit2(),
    ) {
        prop_assume!(texels.iter().any(|&x| x > 0.0));
        let env = Environment::Map(EnvMap::new(8, 4, texels.iter().map(|&x| Rgb::splat(x)).collect()));
        if let Some(s) = env.sample(u) {
            prop_assume!(s.dir.y.abs() < 0.999_999);
            prop_assert!(s.dir.is_finite() && (s.dir.length() - 1.0).abs() < 1e-4);
            prop_assert!(s.pdf.is_finite() && s.pdf > 0.0 && s.radiance.is_finite());
            let again = env.pdf(s.dir);
            prop_assert!((again - s.pdf).abs() <= 1e-3 * s.pdf, "{again} vs {}", s.pdf);
        }
    }
}
