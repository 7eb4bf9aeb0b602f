//! IOSP through the renderer: the structures that live in the triangle order reorder the
//! scene (triangles, normals, uvs, materials; the light table follows) and store nothing else,
//! and the image is the flat BVH's within noise (block z-test, independent seeds). Control:
//! the same structure over a scene left in the old order shades hits with the wrong
//! triangles' materials, and the test sees it.

use rt_accel::{AccelKind, AccelSpec};
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::PathIntegrator;
use rt_testkit::stats::{compare, ALPHA};
use rt_testkit::{shipped_scene, Renderer, SceneExt};

fn render(scene: &rt_core::Scene, accel: &dyn rt_core::Accel, seed: u32) -> rt_film::Film {
    Renderer::new(scene)
        .with_accel(accel)
        .threads(2)
        .render(
            &PathIntegrator::new(4),
            FilmBuffers::from(AovSet::default()).with_variance(),
            32,
            seed,
        )
        .0
}

#[test]
fn iosp_renders_the_flat_bvh_image_from_a_reordered_scene() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(32, 32);
    let flat = AccelSpec::new(AccelKind::Bvh8)
        .build(&scene)
        .expect("the structure builds over the scene");
    let reference = render(&scene, flat.as_ref(), 1);
    for kind in [AccelKind::Iosp0, AccelKind::Iosp4, AccelKind::Iosp2] {
        let mut permuted = scene.clone();
        let accel = AccelSpec::new(kind)
            .build(rt_accel::BuildInput::SceneToReorder(&mut permuted))
            .unwrap();
        assert_ne!(
            permuted.triangles, scene.triangles,
            "{kind:?} kept the order"
        );
        let c = compare(&render(&permuted, accel.as_ref(), 2), &reference, 4, ALPHA);
        assert!(c.same_within_noise(), "{kind:?}: {c:?}");
        if kind == AccelKind::Iosp0 {
            // The control: the structure's hits index the reordered triangles.
            let wrong = compare(&render(&scene, accel.as_ref(), 2), &reference, 4, ALPHA);
            assert!(!wrong.same_within_noise(), "control passes: {wrong:?}");
        }
    }
}

/// An animated, instanced scene (the car, frame at 1 s) keeps its order, since every frame
/// rewrites each instance's world copy in its range: IOSP answers through its index map and
/// renders the flat BVH's image.
#[test]
fn an_instanced_scene_keeps_its_order_and_renders_through_the_index_map() {
    let mut scene = rt_scene::procedural::generate("car")
        .unwrap()
        .with_resolution(24, 16);
    scene.set_time(1.0);
    let flat = AccelSpec::new(AccelKind::Bvh8)
        .build(&scene)
        .expect("the structure builds over the scene");
    let reference = render(&scene, flat.as_ref(), 1);
    assert!(
        rt_testkit::stats::image_mean(&reference).0 > 0.01,
        "a black car"
    );
    let mut kept = scene.clone();
    let accel = AccelSpec::new(AccelKind::Iosp0)
        .build(rt_accel::BuildInput::SceneToReorder(&mut kept))
        .unwrap();
    assert_eq!(
        kept.triangles, scene.triangles,
        "the instanced scene was reordered"
    );
    assert!(
        accel.memory_bytes() >= 4 * scene.triangles.len(),
        "no index map counted"
    );
    let c = compare(&render(&kept, accel.as_ref(), 2), &reference, 4, ALPHA);
    assert!(c.same_within_noise(), "{c:?}");
}
