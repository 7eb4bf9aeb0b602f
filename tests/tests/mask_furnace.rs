//! Mitsuba's `mask` (`opacity`, `rt_core::material::Bsdf`) end to end, through the TOML
//! loader, `Bsdf` and both path tracers, in the white furnace (`rt_testkit::furnace`): a mask
//! over a lossless material is lossless (the pass-through carries weight one), so the image is
//! the environment within 4 standard errors. Shadow rays stop at masked surfaces while BSDF
//! sampling passes through them (as in Mitsuba 3): a tracer that let shadow rays through as
//! well would count the light behind a mask twice and render the furnace too bright. Control:
//! a mask over a conductor reflecting 94 % (3 % of the light lost at opacity ½) is seen.

use rt_integrators::{PathIntegrator, Wavefront, DEFAULT_LANES};
use rt_testkit::furnace::{scene_toml as furnace, L};
use rt_testkit::stats::image_mean;
use rt_testkit::{render, scene_from_toml, Renderer};

/// The furnace image's mean and its standard error, from the path tracer with light sampling,
/// without it, and from the wavefront tracer.
fn means(material: &str, spp: u32) -> Vec<(f64, f64)> {
    let scene = scene_from_toml(&furnace(material));
    let mut out = vec![
        image_mean(&render(&scene, &PathIntegrator::new(1000), spp, 1)),
        image_mean(&render(&scene, &PathIntegrator::bsdf_only(1000), spp, 2)),
    ];
    let wavefront = Wavefront::new(PathIntegrator::new(1000), DEFAULT_LANES);
    let buffers = rt_film::FilmBuffers::for_outputs(rt_film::AovSet::default()).with_variance();
    let (film, _) = Renderer::new(&scene)
        .threads(2)
        .render_technique(&wavefront, buffers, spp, 3);
    out.push(image_mean(&film));
    out
}

fn lossless(material: &str) -> bool {
    means(material, 64)
        .iter()
        .all(|&(mean, se)| (mean - L as f64).abs() <= 4.0 * se + 1e-4)
}

#[test]
fn a_mask_over_a_lossless_material_is_lossless() {
    let checker = "{ type = \"checkerboard\", color0 = 0.2, color1 = 0.9, \
                   to_uv = [[7, 0, 0], [0, 7, 0]] }";
    for m in [
        // Two-sided: light through a mask meets the objects' back faces, where a one-sided
        // conductor is black (in Mitsuba too).
        "type = \"conductor\"\ntwo_sided = true\nopacity = 0.3".to_string(),
        "type = \"diffuse\"\ncolor = [1, 1, 1]\nopacity = 0.6".to_string(),
        // (Not a dielectric: light entering through the mask and leaving by refraction
        // gains the η² it did not lose on the way in, in Mitsuba's radiance mode too.)
        format!("type = \"diffuse\"\ncolor = [1, 1, 1]\nopacity = {checker}"),
    ] {
        assert!(lossless(&m), "{m}: {:?}", means(&m, 64));
    }
    let lossy = "type = \"conductor\"\ntwo_sided = true\n\
                 specular_reflectance = [0.94, 0.94, 0.94]\nopacity = 0.5";
    assert!(!lossless(lossy), "the furnace missed 3 % of lost energy");
}
