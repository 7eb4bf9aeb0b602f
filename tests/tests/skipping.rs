//! A render builds only what its outputs and its scene need: no AOV, variance or half-buffers
//! nobody asked for, no emitter table without emitters, no importance map without an
//! environment map, no lens samples for a pinhole. And skipping changes no image: the beauty
//! image is the same bit for bit whichever optional buffers the film keeps.

use rt_core::lights::Emitter;
use rt_core::{Camera, Rgb, Sampler, Scene};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{AoIntegrator, Integrator, PathIntegrator, RayCounters, SampleAux};
use rt_testkit::{shipped_scene, Renderer};

fn shipped(name: &str) -> Scene {
    shipped_scene(name)
}

/// `scene`'s first camera at 16×12 pixels, keeping its lens.
fn small_camera(scene: &Scene) -> Camera {
    let c = &scene.cameras[0];
    Camera::look_at(
        "small",
        c.position,
        c.position + c.forward,
        c.up,
        c.fov_y_deg,
        16,
        12,
        c.aperture,
        c.focus_distance,
    )
}

/// Renders into a film that keeps `buffers`.
fn render(scene: &Scene, integrator: &dyn Integrator, buffers: FilmBuffers) -> Film {
    let renderer = Renderer::new(scene).with_camera(small_camera(scene));
    renderer.render(integrator, buffers, 8, 3).0
}

fn bits(img: &[Rgb]) -> Vec<[u32; 3]> {
    img.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// The test: the Cornell box has no environment map and is rendered without AOVs, so
/// none of their buffers or structures exist.
#[test]
fn no_environment_map_and_no_aovs_allocate_none_of_their_buffers() {
    let scene = shipped("cornell-box.toml");
    assert!(scene.environment.map().is_none(), "no importance map");
    assert!(scene.environment.is_black());
    let film = render(&scene, &PathIntegrator::new(4), AovSet::default().into());
    let m = film.memory();
    assert_eq!(m.mean, 16 * 12 * 52);
    assert_eq!((m.variance, m.halves, m.first_hits), (None, None, None));
    assert_eq!(
        (m.albedo, m.normal, m.depth, m.position),
        (None, None, None, None)
    );
    assert_eq!(film.memory_bytes(), m.mean);
    assert!(film.variance_image().is_none() && film.half_image(0).is_none());
    assert!(film.albedo_image().is_none() && film.depth_image().is_none());
    // Its two emitting triangles are all the light sampler holds: 2 records, 2 powers, 3 cdf
    // entries.
    let lights = scene
        .lights_if_built()
        .expect("the path tracer sampled lights");
    assert_eq!(lights.emitter_count(), 2);
    assert_eq!(
        lights.memory_bytes(),
        2 * std::mem::size_of::<Emitter>() + (2 + 3) * 4
    );
    assert!(film.mean_image().iter().any(|p| p.max_element() > 0.0));
}

/// The environment scene has no emitting triangle: no emitter table, yet next-event estimation
/// still samples the sky through its importance map, which exists because the sky is a map.
#[test]
fn an_environment_map_builds_its_importance_map_and_no_emitter_table() {
    let scene = shipped("environment.toml");
    let map = scene.environment.map().expect("environment.toml has a map");
    assert_eq!(map.size(), (256, 128));
    assert!(map.importance().memory_bytes() > 256 * 128 * 4);
    assert_eq!(scene.lights().emitter_count(), 0);
    assert_eq!(
        scene.lights().memory_bytes(),
        0,
        "nothing built for emitters"
    );
    assert!(!scene.lights().is_empty(), "the sky is still sampled");
    let nee = render(&scene, &PathIntegrator::direct(), AovSet::default().into());
    assert!(nee.mean_image().iter().any(|p| p.max_element() > 0.0));
}

/// Integrators that never sample lights (`ao`, `path-bsdf`) build neither the light sampler nor
/// the importance map; the path tracer, the control, builds both.
#[test]
fn integrators_without_light_sampling_build_no_light_structures() {
    let built = |integrator: &dyn Integrator| {
        let scene = shipped("environment.toml");
        let image = render(&scene, integrator, AovSet::default().into()).mean_image();
        assert!(image.iter().any(|p| p.max_element() > 0.0));
        let map = scene.environment.map().expect("environment.toml has a map");
        (
            scene.lights_if_built().is_some(),
            map.importance_if_built().is_some(),
        )
    };
    assert_eq!(
        built(&AoIntegrator {
            max_distance: f32::INFINITY
        }),
        (false, false),
        "ao"
    );
    assert_eq!(
        built(&PathIntegrator::bsdf_only(3)),
        (false, false),
        "path-bsdf"
    );
    assert_eq!(built(&PathIntegrator::new(3)), (true, true), "path");
}

/// A constant-colour sky is sampled uniformly: no importance map.
#[test]
fn a_constant_environment_has_no_importance_map() {
    let scene = shipped("showcase.toml");
    assert!(!scene.environment.is_black());
    assert!(scene.environment.map().is_none());
}

#[test]
fn requested_buffers_are_allocated_and_filled() {
    let scene = shipped("cornell-box.toml");
    let aovs = AovSet::parse_list(["variance", "albedo"]).unwrap();
    let film = render(&scene, &PathIntegrator::new(4), aovs.into());
    let m = film.memory();
    let n = 16 * 12;
    assert_eq!(
        (m.variance, m.first_hits, m.albedo),
        (Some(n * 96), Some(n * 4), Some(n * 48))
    );
    assert_eq!(
        (m.normal, m.depth, m.position, m.halves),
        (None, None, None, None)
    );
    assert!(film
        .variance_image()
        .unwrap()
        .iter()
        .any(|v| v.max_element() > 0.0));
    let lit = film
        .albedo_image()
        .unwrap()
        .iter()
        .filter(|a| a.max_element() > 0.0)
        .count();
    assert!(lit > n / 2, "{lit} of {n} pixels have an albedo");
}

/// The beauty image does not depend on which optional buffers the film keeps, bit for bit, and
/// the variance is the same whether asked for as an output or by a consumer with everything.
#[test]
fn beauty_is_bit_identical_with_and_without_optional_buffers() {
    for (file, integrator) in [
        ("cornell-box.toml", PathIntegrator::new(4)),
        ("depth-of-field.toml", PathIntegrator::new(3)),
    ] {
        let scene = shipped(file);
        let lean = render(&scene, &integrator, AovSet::default().into());
        let variance = AovSet::parse_list(["variance"]).unwrap();
        let with_var = render(&scene, &integrator, variance.into());
        let all = AovSet::parse_list(["albedo", "normal", "depth", "position", "variance"]);
        let full = render(
            &scene,
            &integrator,
            FilmBuffers::for_outputs(all.unwrap()).with_halves(),
        );
        assert_eq!(
            bits(&lean.mean_image()),
            bits(&with_var.mean_image()),
            "{file}"
        );
        assert_eq!(bits(&lean.mean_image()), bits(&full.mean_image()), "{file}");
        assert_eq!(
            bits(&with_var.variance_image().unwrap()),
            bits(&full.variance_image().unwrap()),
            "{file}"
        );
        assert_eq!(lean.discarded(), full.discarded());
    }
}

/// The depth-of-field scene's main camera has a lens and its second camera is a pinhole; with a
/// lens the image depends on the aperture, so the blur is really there. (That a pinhole draws
/// no lens sample is checked where the draw happens: `only_thin_lens_cameras_draw_a_lens_sample`
/// in `crates/integrators/src/driver.rs`.)
#[test]
fn depth_of_field_image_depends_on_the_aperture_and_the_scene_has_a_pinhole() {
    let mut scene = shipped("depth-of-field.toml");
    assert!(!scene.cameras[0].is_pinhole());
    assert_eq!(scene.cameras[1].name, "pinhole");
    assert!(scene.cameras[1].is_pinhole());
    let blurred = render(&scene, &PathIntegrator::new(3), AovSet::default().into());
    scene.cameras[0].aperture = 0.0;
    let sharp = render(&scene, &PathIntegrator::new(3), AovSet::default().into());
    assert_ne!(bits(&blurred.mean_image()), bits(&sharp.mean_image()));
}

/// First-hit AOVs cost nothing unless asked for: with `want_first_hit` off the integrators leave
/// the first hit empty (and the path tracer sets up no BSDF for it once the path ends).
#[test]
fn integrators_compute_first_hits_only_when_wanted() {
    let scene = shipped("cornell-box.toml");
    let camera = small_camera(&scene);
    let renderer = Renderer::new(&scene).with_camera(camera.clone());
    let ctx = renderer.ctx();
    let ao = rt_integrators::AoIntegrator {
        max_distance: f32::INFINITY,
    };
    let integrators: [&dyn Integrator; 3] = [&PathIntegrator::new(0), &PathIntegrator::new(3), &ao];
    for integrator in integrators {
        for want in [false, true] {
            let mut sampler = Sampler::new(0);
            sampler.start(8, 6, 0);
            let ray = camera.generate_ray(rt_core::glam::Vec2::new(8.5, 6.5), Default::default());
            let mut aux = SampleAux {
                want_first_hit: want,
                ..Default::default()
            };
            integrator.li(
                &ctx,
                ray,
                &mut sampler,
                &mut aux,
                &mut RayCounters::default(),
            );
            assert_eq!(aux.first_hit.is_some(), want, "{}", integrator.name());
        }
    }
}
