//! The grids rendered end to end: the same image as the default structure, bit for bit.
//!
//! The renderer uses a structure through `Accel::intersect` (closest hit: distance, triangle,
//! barycentrics) and `Accel::occluded`; everything after the hit (shading point, error bounds,
//! material, the next ray) is computed from the triangle and barycentrics alone. The accel
//! tests (`crates/accel/tests/grids.rs`) show each grid returns the brute-force oracle's hit
//! with the same `t` and barycentrics bit for bit for the same triangle, and that a different
//! triangle is returned only at a tie (two triangles hit at the same distance). These scenes
//! have no coincident surfaces, so there is no tie and the images must be equal bit for bit,
//! not only within noise; a pixel that differs is a ray the grid answered differently.

use rt_accel::AccelSpec;
use rt_film::{AovSet, FilmBuffers};
use rt_integrators::PathIntegrator;
use rt_testkit::{shipped_scene, Renderer, SceneExt};

fn image(scene: &rt_core::Scene, accel: &dyn rt_core::Accel) -> Vec<u32> {
    let (film, _) = Renderer::new(scene).with_accel(accel).threads(2).render(
        &PathIntegrator::new(8),
        FilmBuffers::for_outputs(AovSet::default()),
        4,
        11,
    );
    film.mean_image()
        .iter()
        .flat_map(|c| c.to_array())
        .map(f32::to_bits)
        .collect()
}

#[test]
fn grids_render_the_default_structures_image() {
    let t = std::time::Instant::now();
    for name in ["interior.toml", "meshes.toml", "cornell-box.toml"] {
        let scene = shipped_scene(name).with_resolution(32, 24);
        let reference = image(&scene, rt_testkit::default_accel(&scene).as_ref());
        let lit = reference
            .chunks(3)
            .filter(|c| c.iter().any(|&b| b != 0))
            .count();
        assert!(
            lit * 4 > reference.len() / 3,
            "{name}: only {lit} pixels lit"
        );
        for spec in ["grid", "irregular-grid"] {
            let accel = spec.parse::<AccelSpec>().unwrap().build(&scene).unwrap();
            let got = image(&scene, accel.as_ref());
            let differing = got
                .chunks(3)
                .zip(reference.chunks(3))
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(
                differing,
                0,
                "{name} with {spec}: {differing} of {} pixels differ from the default structure's",
                reference.len() / 3
            );
        }
    }
    eprintln!("{:.2?}", t.elapsed());
}
