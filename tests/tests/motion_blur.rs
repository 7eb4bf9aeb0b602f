//! Motion blur: a render whose shutter is open while things move is the average over the
//! shutter of the instants it covers. The blurred render (one shutter time per camera sample,
//! carried by every ray of the sample) is compared by the block z-test with the mean of 32
//! static renders at the midpoints of 32 equal slices of the shutter (its variance the sum of
//! theirs over 32²): for moving instances under `two-level` and `clusters` (the moving objects
//! cast shadows on the floor, so shadow rays must carry the time too), and for a moving camera
//! over a static scene. Controls: the average over the first half of the shutter only, and the
//! instant the shutter opens, must both be told apart.

use rt_accel::{AccelKind, AccelSpec};
use rt_core::{Rgb, Scene};
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::PathIntegrator;
use rt_testkit::stats::{compare_estimates, Estimate, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

use rt_testkit::scenes::LIT_FLOOR;

/// The boxes on the lit floor, the red one placed by an instance.
const OBJECTS: &str = r#"
[[geometry]]
name = "box"
shape = "box"
min = [-0.3, 0, -0.3]
max = [0.3, 0.8, 0.3]
material = "white"

[[geometry]]
name = "proto"
shape = "box"
min = [-0.25, 0, -0.25]
max = [0.25, 0.5, 0.25]
material = "red"

[[instance]]
name = "moving"
geometry = "proto"
transform = { scale = [1.6, 0.8, 1.0] }
"#;

/// Moving objects: the box slides and turns, the red instance slides and turns the other way.
const OBJECT_MOTION: &str = r#"
[[animation]]
target = "box"
keys = [ { time = 0.0, translate = [-1.4, 0, 0] }, { time = 2.0, translate = [-0.2, 0, -1], rotate = [0, 90, 0] } ]

[[animation]]
target = "moving"
keys = [ { time = 0.0, translate = [1.5, 0, 0.5] }, { time = 2.0, translate = [0.5, 0, -0.5], rotate = [0, -80, 0] } ]
"#;

/// A camera panning and closing in over the static objects.
const CAMERA_MOTION: &str = r#"
[[animation]]
target = "cam"
keys = [ { time = 0.0, position = [0, 1.5, 4], look_at = [0, 0.4, 0], up = [0, 1, 0], fov = 40 },
         { time = 2.0, position = [1.2, 1.2, 3], look_at = [0.3, 0.4, 0], up = [0, 1, 0], fov = 45 } ]
"#;

const SHUTTER: (f32, f32) = (0.3, 1.4);
const SLICES: u32 = 32;

fn estimate(film: &rt_film::Film) -> Estimate {
    Estimate {
        mean: film.mean_image(),
        variance: film.variance_image().expect("variance kept"),
        runs: None,
    }
}

fn render(scene: &Scene, kind: AccelKind, spp: u32, seed: u32) -> Estimate {
    let accel = AccelSpec::new(kind)
        .build(scene)
        .expect("the structure builds over the scene");
    let buffers = FilmBuffers::from(AovSet::default()).with_variance();
    let (film, _) = Renderer::new(scene)
        .with_accel(accel.as_ref())
        .threads(2)
        .render(&PathIntegrator::new(3), buffers, spp, seed);
    estimate(&film)
}

/// The scene with its shutter open over [`SHUTTER`], rendered blurred with `kind`.
fn blurred(motion: &str, kind: AccelKind) -> Estimate {
    let mut s = scene_from_toml(&format!("{LIT_FLOOR}{OBJECTS}{motion}"));
    s.set_time(SHUTTER.0);
    s.shutter = SHUTTER.1;
    assert!(s.is_motion_blurred("cam"));
    render(&s, kind, 512, 1)
}

/// The mean of static renders at the midpoints of `slices` equal slices of the first
/// `fraction` of the shutter (16 samples each), with the variance of that mean.
fn instants(motion: &str, fraction: f32, slices: u32) -> Estimate {
    let mut s = scene_from_toml(&format!("{LIT_FLOOR}{OBJECTS}{motion}"));
    let mut sum: Option<Estimate> = None;
    for k in 0..slices {
        s.set_time(SHUTTER.0 + SHUTTER.1 * fraction * (k as f32 + 0.5) / slices as f32);
        let e = render(&s, AccelKind::Bvh8, 16, 100 + k);
        sum = Some(match sum {
            None => e,
            Some(mut acc) => {
                for (a, b) in acc.mean.iter_mut().zip(&e.mean) {
                    *a += *b;
                }
                for (a, b) in acc.variance.iter_mut().zip(&e.variance) {
                    *a += *b;
                }
                acc
            }
        });
    }
    let mut e = sum.expect("at least one slice");
    let n = slices as f32;
    e.mean.iter_mut().for_each(|m| *m /= n);
    e.variance.iter_mut().for_each(|v| *v /= n * n);
    e
}

fn same(a: &Estimate, b: &Estimate) -> (bool, String) {
    let c = compare_estimates(a, b, 32, 4, ALPHA);
    (c.same_within_noise(), format!("{c:?}"))
}

#[test]
fn moving_objects_blur_into_the_average_of_their_instants() {
    let reference = instants(OBJECT_MOTION, 1.0, SLICES);
    for kind in [AccelKind::TwoLevel, AccelKind::Clusters] {
        let (ok, why) = same(&blurred(OBJECT_MOTION, kind), &reference);
        assert!(ok, "{kind:?}: {why}");
    }
    let image = blurred(OBJECT_MOTION, AccelKind::TwoLevel);
    assert!(image.mean.iter().all(|p: &Rgb| p.is_finite()));
    let (half, _) = same(&image, &instants(OBJECT_MOTION, 0.5, SLICES / 2));
    assert!(!half, "the first half of the shutter passes for the whole");
    let (open, _) = same(&image, &instants(OBJECT_MOTION, 0.0, 1));
    assert!(!open, "the opening instant passes for the blur");
}

#[test]
fn a_moving_camera_blurs_into_the_average_of_its_instants() {
    let reference = instants(CAMERA_MOTION, 1.0, SLICES);
    let image = blurred(CAMERA_MOTION, AccelKind::Bvh8);
    let (ok, why) = same(&image, &reference);
    assert!(ok, "{why}");
    let (half, _) = same(&image, &instants(CAMERA_MOTION, 0.5, SLICES / 2));
    assert!(!half, "the first half of the shutter passes for the whole");
}
