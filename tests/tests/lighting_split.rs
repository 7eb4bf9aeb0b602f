//! The lighting-split AOVs: the parts add up to the pixel, sample by sample, and the `direct`
//! part is what the direct-lighting integrator renders, which a deliberately mislabelled split
//! fails.

use rt_core::Rgb;
use rt_film::{AovSet, Film, FilmBuffers, LightSplit};
use rt_integrators::PathIntegrator;
use rt_testkit::{shipped_scene, Renderer, SceneExt};

fn render(scene: &rt_core::Scene, integrator: &PathIntegrator, spp: u32, seed: u32) -> Film {
    let buffers = FilmBuffers::for_outputs(AovSet::denoise());
    Renderer::new(scene)
        .threads(2)
        .render(integrator, buffers, spp, seed)
        .0
}

fn close(a: Rgb, b: Rgb) -> bool {
    (a - b).abs().max_element() <= 1e-4 * (1.0 + b.abs().max_element())
}

#[test]
fn parts_add_up_to_the_pixel_and_both_lobes_show() {
    // The showcase has plastic, metal, glass, a two-layer material and a texture.
    let scene = shipped_scene("showcase.toml").with_resolution(40, 30);
    let film = render(&scene, &PathIntegrator::new(6), 8, 1);
    let colour = film.mean_image();
    let split = film.split_images().unwrap();
    for (c, s) in colour.iter().zip(&split) {
        assert!(
            close(s.emission + s.direct + s.indirect, *c),
            "{s:?} vs {c}"
        );
        assert!(close(s.emission + s.diffuse + s.glossy, *c), "{s:?} vs {c}");
    }
    let total = |f: fn(&LightSplit) -> Rgb| split.iter().map(f).sum::<Rgb>().element_sum();
    for (name, v) in [
        ("direct", total(|s| s.direct)),
        ("indirect", total(|s| s.indirect)),
        ("diffuse", total(|s| s.diffuse)),
        ("glossy", total(|s| s.glossy)),
        ("irradiance", total(|s| s.irradiance)),
    ] {
        assert!(v > 0.0, "{name} is never written");
    }

    // One bounce has no indirect light.
    let direct = render(&scene, &PathIntegrator::direct(), 4, 1);
    assert!(direct
        .split_images()
        .unwrap()
        .iter()
        .all(|s| s.indirect == Rgb::ZERO));

    // A diffuse-only box has no glossy light; where every sample saw the same white wall the
    // irradiance times the albedo is the reflected light.
    let cornell = shipped_scene("cornell-box.toml").with_resolution(24, 24);
    let film = render(&cornell, &PathIntegrator::new(4), 4, 2);
    let split = film.split_images().unwrap();
    assert!(split.iter().all(|s| s.glossy == Rgb::ZERO));
    let albedo = film.albedo_image().unwrap();
    let remodulated = split
        .iter()
        .zip(&albedo)
        .filter(|(s, a)| close(s.irradiance * **a, s.direct + s.indirect))
        .count();
    assert!(
        remodulated > split.len() / 2,
        "{remodulated} of {}",
        split.len()
    );
}

#[test]
fn the_direct_part_is_what_direct_lighting_renders() {
    // The path tracer and the direct-lighting integrator draw the first vertex's random
    // numbers alike, so with one seed the path's `emission + direct` is the direct image,
    // sample by sample (up to the order of additions), not just in expectation.
    let scene = shipped_scene("showcase.toml").with_resolution(24, 18);
    let one_bounce = render(&scene, &PathIntegrator::direct(), 4, 9).mean_image();
    let split = render(&scene, &PathIntegrator::new(6), 4, 9)
        .split_images()
        .unwrap();
    let mismatches = |indirect_share: f32| {
        split
            .iter()
            .zip(&one_bounce)
            .filter(|(s, d)| !close(s.emission + s.direct + s.indirect * indirect_share, **d))
            .count()
    };
    assert_eq!(mismatches(0.0), 0);
    // Control: a split that files a tenth of the indirect light as direct is caught.
    assert!(mismatches(0.1) > split.len() / 4, "{}", mismatches(0.1));
}

#[test]
fn each_lobe_class_gets_only_its_own_light() {
    // Furnace scenes of one material: a glossy one reflects nothing diffusely, a diffuse one
    // nothing specularly, whichever lobe found the light (sampled or light-sampled).
    for (material, glossy_only) in [
        (
            "type = \"glossy\"\ncolor = [0.8, 0.8, 0.8]\nhardness = 0.5",
            true,
        ),
        ("type = \"diffuse\"\ncolor = [0.8, 0.8, 0.8]", false),
    ] {
        let scene = rt_testkit::scene_from_toml(&rt_testkit::furnace::scene_toml(material));
        let film = render(&scene, &PathIntegrator::new(5), 4, 3);
        let split = film.split_images().unwrap();
        let (own, other) = split.iter().fold((0.0, 0.0), |(o, x), s| {
            let (own, other) = if glossy_only {
                (s.glossy, s.diffuse)
            } else {
                (s.diffuse, s.glossy)
            };
            (o + own.element_sum(), x + other.element_sum())
        });
        assert!(own > 0.0 && other == 0.0, "{material}: {own} vs {other}");
    }
}
