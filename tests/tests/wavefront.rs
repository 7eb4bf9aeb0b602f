//! The wavefront path tracer is the scalar path tracer's estimator advanced in batches: every
//! sample draws the same numbers at the same dimensions and is shaded with the same
//! arithmetic, so the two images must be the same bits (radiance, variance and first-hit
//! AOVs), on every shipped scene, through a thin lens, under motion blur, with a pixel mask
//! and a centred first sample, in passes, for any batch size and thread count.
//!
//! Controls: the comparison must see a change of one sample's worth, so a wavefront render
//! whose shadow rays are 2 % weaker (the `DroppedShadowRays` mutant) and one with another
//! seed must both differ from the scalar image.

use rt_accel::{AccelKind, AccelSpec};
use rt_core::{SampleStream, Scene};
use rt_film::{AovSet, Film, FilmBuffers};
use rt_integrators::{CameraRays, PathIntegrator, SamplePass, Technique, Wavefront};
use rt_testkit::mutants::DroppedShadowRays;
use rt_testkit::{shipped_scene, Renderer, SceneExt};

/// Everything a film holds that the comparison looks at.
fn contents(film: &Film) -> Vec<Vec<f32>> {
    let flat = |v: Vec<rt_core::Rgb>| v.iter().flat_map(|c| c.to_array()).collect::<Vec<_>>();
    let mut out = vec![flat(film.mean_image())];
    if let Some(v) = film.variance_image() {
        out.push(flat(v));
    }
    if let Some(a) = film.albedo_image() {
        out.push(flat(a));
    }
    if let Some(n) = film.normal_image() {
        out.push(n.iter().flat_map(|c| c.to_array()).collect());
    }
    if let Some(d) = film.depth_image() {
        out.push(d);
    }
    out
}

fn buffers() -> FilmBuffers {
    let aovs = AovSet::parse_list(["albedo", "normal", "depth"]).expect("AOV list");
    FilmBuffers::for_outputs(aovs).with_variance()
}

fn pass(indices: std::ops::Range<u32>) -> SamplePass {
    SamplePass::render(indices)
}

/// Renders `passes` of `technique` one after another on `threads` threads.
fn render(
    renderer: &Renderer<'_>,
    technique: &dyn Technique,
    passes: &[SamplePass],
    seed: u32,
) -> Film {
    let mut film = renderer.film(buffers());
    for p in passes {
        renderer.technique_pass(technique, &mut film, seed, p);
    }
    film
}

fn scalar(depth: u32) -> CameraRays {
    CameraRays(Box::new(PathIntegrator::new(depth)))
}

/// Asserts the wavefront image of `scene` equals the scalar one for several batch sizes,
/// thread counts and pass splits.
fn assert_same(name: &str, scene: &Scene, depth: u32, spp: u32) {
    let two = Renderer::new(scene).threads(2);
    let want = contents(&render(&two, &scalar(depth), &[pass(0..spp)], 5));
    for (lanes, threads, split) in [(1024, 2, spp), (7, 1, spp / 2), (64, 2, 1)] {
        let r = Renderer::new(scene).threads(threads);
        let w = Wavefront::new(PathIntegrator::new(depth), lanes);
        let got = contents(&render(&r, &w, &[pass(0..split), pass(split..spp)], 5));
        assert!(
            got == want,
            "{name}: wavefront ({lanes} lanes, {threads} threads, passes split at {split}) differs from path"
        );
    }
}

#[test]
fn wavefront_images_are_the_scalar_images_on_every_shipped_scene() {
    for name in [
        "cornell-box.toml",
        "caustic.toml",
        "depth-of-field.toml",
        "environment.toml",
        "interior.toml",
        "meshes.toml",
        "penumbra.toml",
        "prism.toml",
        "showcase.toml",
        "sky.toml",
        "sun-caustic.toml",
    ] {
        let scene = shipped_scene(name).with_resolution(24, 16);
        assert_same(name, &scene, 8, 4);
    }
}

/// Point, spot and directional lights beside the box's own lamp: the delta lights' samples
/// (no MIS weight) go through the vectorised Lambertian stage and the scalar one alike.
#[test]
fn wavefront_images_are_the_scalar_images_with_point_spot_and_directional_lights() {
    let mut scene = shipped_scene("cornell-box.toml").with_resolution(24, 16);
    scene.delta_lights = rt_testkit::cornell_box_delta_lights();
    scene.build_lights();
    assert_eq!(scene.lights().delta_count(), 3);
    assert_same("delta lights", &scene, 8, 4);
}

#[test]
fn wavefront_images_are_the_scalar_images_through_a_thin_lens_at_unlimited_depth() {
    let scene = shipped_scene("cornell-box.toml")
        .with_resolution(20, 20)
        .with_lens(30.0, 800.0);
    assert_same("thin lens", &scene, 10_000, 4);
}

#[test]
fn wavefront_images_are_the_scalar_images_under_motion_blur() {
    let mut scene = shipped_scene("animated.toml").with_resolution(24, 16);
    scene.set_time(1.0);
    scene.shutter = 0.5;
    assert!(scene.is_motion_blurred(&scene.cameras[0].name));
    let accel = AccelSpec::new(AccelKind::TwoLevel)
        .build(&scene)
        .expect("the structure builds over the scene");
    let r = Renderer::new(&scene).with_accel(accel.as_ref()).threads(2);
    let want = contents(&render(&r, &scalar(8), &[pass(0..4)], 3));
    let w = Wavefront::new(PathIntegrator::new(8), 32);
    assert!(contents(&render(&r, &w, &[pass(0..4)], 3)) == want);
}

#[test]
fn wavefront_takes_the_pixel_mask_and_the_centred_first_sample() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(16, 12);
    let mask: Vec<bool> = (0..16 * 12).map(|i| (i * 7) % 5 < 2).collect();
    let masked = SamplePass {
        indices: 0..3,
        stream: SampleStream::Reference,
        pixels: Some(mask.into()),
        centre_first: true,
    };
    let r = Renderer::new(&scene).threads(2);
    let want = contents(&render(&r, &scalar(8), std::slice::from_ref(&masked), 9));
    let w = Wavefront::new(PathIntegrator::new(8), 16);
    assert!(contents(&render(&r, &w, &[masked], 9)) == want);
}

#[test]
fn control_a_weaker_or_reseeded_wavefront_render_is_told_apart() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(24, 16);
    let r = Renderer::new(&scene).threads(2);
    let want = contents(&render(&r, &scalar(8), &[pass(0..4)], 5));
    let w = Wavefront::new(PathIntegrator::new(8), 256);
    assert!(
        contents(&render(&r, &w, &[pass(0..4)], 6)) != want,
        "another seed"
    );
    let mutant = DroppedShadowRays {
        inner: r.accel(),
        fraction: 0.02,
    };
    let weak = Renderer::new(&scene).with_accel(&mutant).threads(2);
    assert!(
        contents(&render(&weak, &w, &[pass(0..4)], 5)) != want,
        "2 % of the shadow rays dropped"
    );
}

#[test]
fn wavefront_leaves_the_lighting_split_to_the_scalar_tracer_and_says_so() {
    let scene = shipped_scene("cornell-box.toml").with_resolution(12, 8);
    let r = Renderer::new(&scene).threads(2);
    let aovs = AovSet::parse_list(["direct", "indirect"]).expect("AOV list");
    let w = Wavefront::new(PathIntegrator::new(8), 64);
    let mut film = r.film(FilmBuffers::for_outputs(aovs));
    r.technique_pass(&w, &mut film, 1, &pass(0..2));
    let mut want = r.film(FilmBuffers::for_outputs(aovs));
    r.technique_pass(&scalar(8), &mut want, 1, &pass(0..2));
    assert!(contents(&film) == contents(&want));
    let stages = w.stages();
    assert!(
        stages
            .iter()
            .any(|s| s.name == "scalar path tracer" && s.details.contains("lighting-split")),
        "{stages:?}"
    );
}

/// Bump and normal maps bend the shading normal where the scene builds a hit, for both
/// tracers alike: the Cornell box with every material bumped or normal-mapped (half of them
/// rough plastic or rough metal of the microfacet family) gives the same bits, and an image
/// that differs from the unbent box's, so the maps are seen at all.
#[test]
fn wavefront_images_are_the_scalar_images_with_bump_and_normal_maps() {
    use rt_core::bump::NormalPerturbation;
    use rt_core::microfacet::{Distribution, DistributionKind, Microfacet, RoughConductor};
    use rt_core::texture::Texture;
    use rt_core::Rgb;
    let plain = shipped_scene("cornell-box.toml").with_resolution(24, 16);
    let mut scene = plain.clone();
    let texels = (0..64)
        .map(|i| {
            let h = ((i * 37) % 64) as f32 / 63.0;
            Rgb::new(h, ((i * 11) % 64) as f32 / 63.0, 0.6 + 0.4 * h)
        })
        .collect();
    scene.textures.push(Texture::new(8, 8, texels));
    let t = (scene.textures.len() - 1) as u32;
    for (k, m) in scene.materials.iter_mut().enumerate() {
        m.perturbation = Some(if k % 2 == 0 {
            NormalPerturbation::Bump {
                texture: t,
                scale: 0.05,
            }
        } else {
            NormalPerturbation::NormalMap { texture: t }
        });
        if k % 4 == 1 && !m.is_emissive() {
            m.layers.clear();
            m.microfacet = Some(Microfacet::Conductor(RoughConductor {
                distribution: Some(Distribution::new(DistributionKind::Ggx, 0.3, 0.3)),
                eta: Rgb::new(0.2, 0.9, 1.1),
                k: Rgb::new(3.9, 2.4, 1.6),
                specular_reflectance: Rgb::ONE,
                two_sided: true,
            }));
        }
    }
    assert_same("bump and normal maps", &scene, 8, 4);
    let image = |s: &Scene| {
        let r = Renderer::new(s).threads(2);
        contents(&render(&r, &scalar(8), &[pass(0..4)], 5))
    };
    assert!(image(&scene) != image(&plain));
}
