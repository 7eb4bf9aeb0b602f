//! Rays with a NaN or infinite component hit nothing and return at once, in every structure,
//! for closest hits, occlusion and shadow-cached occlusion. In the wide BVHs a NaN direction
//! made every slab test pass, empty slots included, and the descent overflowed the traversal
//! stack (a panic found by the scene-mutation test: a camera moved to 4·10⁹).

use rt_accel::{AccelKind, AccelSpec};
use rt_core::glam::Vec3;
use rt_core::ray::Ray;

#[test]
fn non_finite_rays_hit_nothing() {
    // A few hundred triangles so that the trees have several levels.
    let mut tris = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let o = Vec3::new(i as f32, j as f32, (i * j % 7) as f32);
            tris.push([o, o + Vec3::X, o + Vec3::Y]);
        }
    }
    let bad = [
        Ray::new(Vec3::new(0.5, 0.5, 10.0), Vec3::splat(f32::NAN)),
        Ray::new(Vec3::splat(f32::NAN), -Vec3::Z),
        Ray::new(
            Vec3::new(0.5, 0.5, 10.0),
            Vec3::new(0.0, f32::INFINITY, -1.0),
        ),
    ];
    for kind in AccelKind::ALL {
        let accel = AccelSpec::new(kind)
            .build(&tris)
            .expect("the structure builds");
        for r in &bad {
            assert!(
                accel.intersect(r, f32::INFINITY).is_none(),
                "{}",
                kind.name()
            );
            assert!(!accel.occluded(r, f32::INFINITY), "{}", kind.name());
            assert!(!accel.occluded_toward(r, 1.0, Vec3::ONE), "{}", kind.name());
        }
        // And a good ray still hits.
        let good = Ray::new(Vec3::new(0.25, 0.25, 10.0), -Vec3::Z);
        assert!(
            accel.intersect(&good, f32::INFINITY).is_some(),
            "{}",
            kind.name()
        );
    }
}
