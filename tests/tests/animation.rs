//! Frame f of an animation is the static scene with every object at its interpolated
//! transform: an animated geometry and an animated, scaled instance at t = 1 (halfway between
//! keys at 0 and 2: translation halfway, rotation halfway by slerp) against a scene that places
//! them there by plain `transform`s, path traced with independent seeds and compared by the
//! block z-test; with every structure that can render the animated scene (flat ones over the
//! world copies, `two-level` and `clusters` over the prototypes). Control: the objects placed
//! where they are at t = 0.8 instead, a change the test must see.

use rt_accel::{AccelKind, AccelSpec};
use rt_film::FilmBuffers;
use rt_integrators::PathIntegrator;
use rt_testkit::stats::{compare, ALPHA};
use rt_testkit::{scene_from_toml, Renderer};

use rt_testkit::scenes::LIT_FLOOR as COMMON;

/// The animated scene: a box moved and turned, and an instance of a red box scaled, then
/// moved and turned by its keys.
fn animated() -> rt_core::Scene {
    scene_from_toml(&format!(
        r#"{COMMON}
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
transform = {{ scale = [1.6, 0.8, 1.0] }}

[[animation]]
target = "box"
keys = [ {{ time = 0.0, translate = [-1.4, 0, 0] }}, {{ time = 2.0, translate = [-0.2, 0, -1], rotate = [0, 90, 0] }} ]

[[animation]]
target = "moving"
keys = [ {{ time = 0.0, translate = [1.5, 0, 0.5] }}, {{ time = 2.0, translate = [0.5, 0, -0.5], rotate = [0, 80, 0] }} ]
"#
    ))
}

/// The same objects placed statically where they are at time `t` (between the keys).
fn placed(t: f32) -> rt_core::Scene {
    let w = t / 2.0;
    let lerp = |a: f32, b: f32| a + (b - a) * w;
    scene_from_toml(&format!(
        r#"{COMMON}
[[geometry]]
name = "box"
shape = "box"
min = [-0.3, 0, -0.3]
max = [0.3, 0.8, 0.3]
material = "white"
transform = {{ translate = [{}, 0, {}], rotate = [0, {}, 0] }}

[[geometry]]
name = "moving"
shape = "box"
min = [-0.25, 0, -0.25]
max = [0.25, 0.5, 0.25]
material = "red"
transform = {{ translate = [{}, 0, {}], rotate = [0, {}, 0], scale = [1.6, 0.8, 1.0] }}
"#,
        lerp(-1.4, -0.2),
        lerp(0.0, -1.0),
        90.0 * w,
        lerp(1.5, 0.5),
        lerp(0.5, -0.5),
        80.0 * w,
    ))
}

fn render(scene: &rt_core::Scene, kind: AccelKind, seed: u32) -> rt_film::Film {
    let accel = AccelSpec::new(kind)
        .build(scene)
        .expect("the structure builds over the scene");
    Renderer::new(scene)
        .with_accel(accel.as_ref())
        .threads(2)
        .render(
            &PathIntegrator::new(4),
            FilmBuffers::from(rt_film::AovSet::default()).with_variance(),
            64,
            seed,
        )
        .0
}

#[test]
fn a_frame_is_the_static_scene_at_the_interpolated_transforms() {
    let mut anim = animated();
    anim.set_time(1.0);
    let reference = render(&placed(1.0), AccelKind::Bvh8, 1);
    for kind in [AccelKind::Bvh8, AccelKind::TwoLevel, AccelKind::Clusters] {
        let c = compare(&render(&anim, kind, 2), &reference, 4, ALPHA);
        assert!(c.same_within_noise(), "{kind:?}: {c:?}");
    }
    let control = compare(
        &render(&placed(0.8), AccelKind::Bvh8, 3),
        &reference,
        4,
        ALPHA,
    );
    assert!(!control.same_within_noise(), "control passes: {control:?}");
}
