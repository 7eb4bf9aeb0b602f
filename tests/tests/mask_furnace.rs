//! Mitsuba's `mask` (`opacity`, `rt_core::material::Bsdf`) end to end, through the TOML
//! loader, `Bsdf` and both path tracers, in the white furnace (`rt_testkit::furnace`): a mask
//! over a lossless material is lossless (the pass-through carries weight one), so the image is
//! the environment within 4 standard errors. Shadow rays stop at masked surfaces while BSDF
//! sampling passes through them (as in Mitsuba 3): a tracer that let shadow rays through as
//! well would count the light behind a mask twice and render the furnace too bright. Control:
//! a mask over a conductor reflecting 94 % (3 % of the light lost at opacity ½) is seen.

use rt_testkit::furnace::{lossless, tracer_means as means};

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
