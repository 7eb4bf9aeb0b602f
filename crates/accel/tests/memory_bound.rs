//! `AccelKind::memory_bound` against what every structure holds once built, on the shipped
//! scenes and on two real meshes from `../shared/data` (a visible skip when absent, a failure
//! under `RT_REQUIRE_DATA=1`): the bound must hold with room for the builder's temporaries
//! (held ≤ half the bound).

mod common;

use common::shared_mesh;
use rt_accel::{AccelKind, AccelSpec};

fn check(what: &str, triangles: usize, kind: AccelKind, held: usize) {
    let bound = kind.memory_bound(triangles);
    assert!(
        2 * held as u64 <= bound,
        "{what}, {}: holds {held} B over {triangles} triangles, bound {bound} B",
        kind.name()
    );
}

#[test]
fn every_structure_holds_at_most_half_its_bound() {
    for name in [
        "cornell-box.toml",
        "interior.toml",
        "meshes.toml",
        "hall-mirror.toml",
        "dynamic-small.toml",
        "animated.toml",
    ] {
        let scene = rt_testkit::shipped_scene(name);
        for kind in AccelKind::ALL {
            let accel = AccelSpec::new(kind)
                .build(&scene)
                .expect("the structure builds over the scene");
            check(name, scene.triangle_count(), kind, accel.memory_bytes());
        }
    }
    for mesh in [
        "models/stanford-bunny.obj",
        "scenes/sponza-dabrovic/sponza.obj",
    ] {
        let Some(tris) = shared_mesh(mesh) else {
            continue;
        };
        for kind in AccelKind::ALL.into_iter().filter(|k| !k.is_two_level()) {
            let accel = AccelSpec::new(kind)
                .build(&tris)
                .expect("the structure builds");
            check(mesh, tris.len(), kind, accel.memory_bytes());
        }
    }
}

#[test]
fn the_bound_grows_with_the_triangles_and_does_not_overflow() {
    for kind in AccelKind::ALL {
        assert!(kind.memory_bound(1_000_000) > kind.memory_bound(1_000));
        assert!(kind.memory_bound(usize::MAX) >= kind.memory_bound(1 << 40));
    }
}
