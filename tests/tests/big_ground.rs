//! Shadows on a large ground made of slivers: a `disk` of radius 2000 split into 512 fan
//! triangles (2000 × 25 each), as sky scenes use for their ground. Hit points are reconstructed
//! with their error bound and pulled in from the edges (`rt_core::triangle::point_with_error`);
//! pulling by barycentric rescaling once moved them by up to 20 units along the slivers, so
//! the shadow of a box vanished with every accelerator. Here every ground point seen from above
//! has the shadow test the exact geometry predicts, except within a thin band around the
//! shadow's outline.

use rt_accel::{AccelKind, AccelSpec};
use rt_core::{
    glam::{DVec3, Vec3},
    ray::{shadow_segment, Ray},
};
use rt_testkit::scene_from_toml;

const SCENE: &str = r#"
[environment]
color = [0.0, 0.0, 0.0]

[[camera]]
name = "top"
position = [0.0, 20.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 40.0
resolution = [8, 8]

[[material]]
name = "white"
type = "diffuse"
color = [0.8, 0.8, 0.8]

[[geometry]]
name = "ground"
shape = "disk"
radius = 2000.0
segments = 512
material = "white"

[[geometry]]
name = "block"
shape = "box"
min = [-1.0, 1.0, -1.0]
max = [1.0, 2.0, 1.0]
material = "white"

[[geometry]]
name = "far-block"
shape = "box"
min = [5.0, 1.0, 3.0]
max = [7.0, 2.0, 5.0]
material = "white"
"#;

/// The light: a point 10 above the origin (a shadow segment's endpoint; no emitter needed).
const LIGHT: DVec3 = DVec3::new(0.0, 10.0, 0.0);

/// Blocks as (min, max), exactly as in the scene.
const BLOCKS: [(DVec3, DVec3); 2] = [
    (DVec3::new(-1.0, 1.0, -1.0), DVec3::new(1.0, 2.0, 1.0)),
    (DVec3::new(5.0, 1.0, 3.0), DVec3::new(7.0, 2.0, 5.0)),
];

/// Slab test of the segment `a → b` against a box, in f64.
fn segment_hits_box(a: DVec3, b: DVec3, (lo, hi): (DVec3, DVec3)) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (o, dk) = (a[k], d[k]);
        if dk.abs() < 1e-300 {
            if o < lo[k] || o > hi[k] {
                return false;
            }
            continue;
        }
        let (mut ta, mut tb) = ((lo[k] - o) / dk, (hi[k] - o) / dk);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
    }
    t0 <= t1
}

/// The shadow's outline on the ground, as the distance from the ground point `q` to the
/// nearest point whose exact answer differs (found along a small ring of probes).
fn near_outline(q: DVec3, band: f64) -> bool {
    let shadowed = |p: DVec3| BLOCKS.iter().any(|&b| segment_hits_box(p, LIGHT, b));
    let here = shadowed(q);
    (0..16).any(|i| {
        let a = i as f64 * std::f64::consts::TAU / 16.0;
        shadowed(q + DVec3::new(a.cos(), 0.0, a.sin()) * band) != here
    })
}

#[test]
fn shadows_on_a_sliver_fan_ground_follow_the_geometry() {
    let scene = scene_from_toml(SCENE);
    let band = 0.05;
    for kind in AccelKind::ALL {
        let accel = AccelSpec::new(kind)
            .build(&scene.triangles)
            .expect("the structure builds");
        let (mut checked, mut shadowed, mut wrong) = (0, 0, Vec::new());
        // Ground points on a grid around both blocks, seen from straight above.
        for i in 0..120 {
            for j in 0..120 {
                let x = -4.0 + 12.0 * (i as f32 + 0.5) / 120.0;
                let z = -4.0 + 10.0 * (j as f32 + 0.5) / 120.0;
                let ray = Ray::new(Vec3::new(x, 0.5, z), -Vec3::Y);
                let Some(hit) = accel.intersect(&ray, f32::INFINITY) else {
                    panic!("{}: no ground below ({x}, {z})", kind.name());
                };
                let s = scene.surface(&hit, 0.0);
                let q = s.p.as_dvec3();
                if near_outline(DVec3::new(x as f64, 0.0, z as f64), band) {
                    continue;
                }
                let expect = BLOCKS
                    .iter()
                    .any(|&b| segment_hits_box(DVec3::new(x as f64, 0.0, z as f64), LIGHT, b));
                let light = LIGHT.as_vec3();
                let (r, t_max) = shadow_segment(s.p, s.p_error, s.ng, light, Vec3::ZERO, -Vec3::Y);
                let got = accel.occluded_toward(&r, t_max, light);
                checked += 1;
                shadowed += usize::from(expect);
                if got != expect {
                    wrong.push((x, z, q, expect));
                }
            }
        }
        assert!(
            shadowed > 1000,
            "{}: only {shadowed} shadowed points",
            kind.name()
        );
        assert!(
            wrong.is_empty(),
            "{}: {} of {checked} ground points have the wrong shadow, e.g. {:?}",
            kind.name(),
            wrong.len(),
            &wrong[..wrong.len().min(3)]
        );
    }
}
