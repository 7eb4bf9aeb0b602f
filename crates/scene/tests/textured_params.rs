//! Textures on the microfacet family's parameters (`rt_core::microfacet::ParamTextures`) and
//! the `checkerboard` texture, read from Mitsuba XML (which goes through our TOML format): a
//! textured parameter renders the same bits as the constant that is the texture's value (a
//! texture that did not reach the BSDF would render the default, which the control shows to
//! differ), and bad textures are one error line naming the file.

use std::path::Path;

use rt_core::texture::luminance;
use rt_core::Rgb;

/// A scene of one rectangle with BSDF `bsdf` under a white sky.
fn scene(bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 1, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
            <rfilter type="box"/></film>
    </sensor>
    <texture type="bitmap" id="magenta"><string name="filename" value="magenta.png"/></texture>
    <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/></transform>
        {bsdf}</shape>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
</scene>"#
    )
}

fn load(dir: &Path, bsdf: &str) -> Result<rt_scene::LoadedScene, String> {
    std::fs::write(dir.join("s.xml"), scene(bsdf)).unwrap();
    rt_scene::load(&dir.join("s.xml")).map_err(|e| e.to_string())
}

fn render(dir: &Path, bsdf: &str) -> Vec<f32> {
    let s = load(dir, bsdf).unwrap_or_else(|e| panic!("{e}\n{bsdf}"));
    let film = rt_testkit::render(&s.scene, &rt_integrators::PathIntegrator::new(4), 4, 1);
    film.mean_image()
        .iter()
        .flat_map(|p| p.to_array())
        .collect()
}

/// A checkerboard that is `color0` everywhere (`to_uv` maps every point to the origin).
fn constant_checkerboard(name: &str, value: f32) -> String {
    format!(
        r#"<texture type="checkerboard" name="{name}"><rgb name="color0" value="{value:?}"/>
        <transform name="to_uv"><scale x="0" y="0"/></transform></texture>"#
    )
}

#[test]
fn a_textured_parameter_renders_as_its_constant() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 255]))
        .save(dir.path().join("magenta.png"))
        .unwrap();
    // A roughness read from a texture is its luminance.
    let a = 0.3f32;
    let la = luminance(Rgb::splat(a));
    let ggx = r#"<string name="distribution" value="ggx"/>"#;
    let gold = r#"<string name="material" value="Au"/>"#;
    // (type, fixed parameters, textured form, constant form); the control is the type's
    // default for the textured parameter.
    let cases = [
        (
            "roughconductor",
            format!("{ggx}{gold}"),
            constant_checkerboard("alpha", a),
            format!(r#"<float name="alpha" value="{la:?}"/>"#),
        ),
        (
            "roughconductor",
            format!(r#"{gold}<float name="alpha_v" value="0.05"/>"#),
            constant_checkerboard("alpha_u", a),
            format!(r#"<float name="alpha_u" value="{la:?}"/>"#),
        ),
        (
            "roughconductor",
            ggx.to_string(),
            r#"<ref name="specular_reflectance" id="magenta"/>"#.into(),
            r#"<rgb name="specular_reflectance" value="1, 0, 1"/>"#.into(),
        ),
        (
            "conductor",
            String::new(),
            r#"<texture type="bitmap" name="specular_reflectance">
                <string name="filename" value="magenta.png"/></texture>"#
                .into(),
            r#"<rgb name="specular_reflectance" value="1, 0, 1"/>"#.into(),
        ),
        (
            "roughdielectric",
            ggx.into(),
            constant_checkerboard("alpha", a),
            format!(r#"<float name="alpha" value="{la:?}"/>"#),
        ),
        (
            "roughdielectric",
            String::new(),
            r#"<ref name="specular_transmittance" id="magenta"/>"#.into(),
            r#"<rgb name="specular_transmittance" value="1, 0, 1"/>"#.into(),
        ),
        (
            "dielectric",
            String::new(),
            r#"<ref name="specular_reflectance" id="magenta"/>"#.into(),
            r#"<rgb name="specular_reflectance" value="1, 0, 1"/>"#.into(),
        ),
        (
            "roughplastic",
            String::new(),
            r#"<ref name="specular_reflectance" id="magenta"/>"#.into(),
            r#"<rgb name="specular_reflectance" value="1, 0, 1"/>"#.into(),
        ),
        // A mask's opacity (its default is 0.5).
        (
            "mask",
            r#"<bsdf type="diffuse"/>"#.into(),
            constant_checkerboard("opacity", a),
            format!(r#"<float name="opacity" value="{la:?}"/>"#),
        ),
    ];
    for (ty, fixed, textured, constant) in &cases {
        let bsdf = |param: &str| format!(r#"<bsdf type="{ty}">{fixed}{param}</bsdf>"#);
        let t = render(dir.path(), &bsdf(textured));
        let c = render(dir.path(), &bsdf(constant));
        let control = if textured.contains("alpha_u") {
            r#"<float name="alpha_u" value="0.1"/>"#
        } else {
            ""
        };
        let default = render(dir.path(), &bsdf(control));
        assert!(t == c, "{ty} {textured}: differs from its constant");
        assert!(c != default, "{ty} {constant}: the control must differ");
    }
}

#[test]
fn bad_textures_are_one_error_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            r#"<bsdf type="roughplastic"><texture type="checkerboard" name="alpha"/></bsdf>"#,
            "roughplastic's `alpha` takes no texture",
        ),
        (
            r#"<bsdf type="roughconductor"><texture type="wood" name="alpha"/></bsdf>"#,
            "texture \"wood\" is not supported",
        ),
        (
            r#"<bsdf type="roughconductor"><texture type="checkerboard" name="alpha">
                <rgb name="color0" value="2, 0, 0"/></texture></bsdf>"#,
            "checkerboard `color0` must be a number or [r, g, b] in [0, 1]",
        ),
        (
            r#"<bsdf type="roughconductor"><ref name="alpha" id="nothing"/></bsdf>"#,
            "no element has this id",
        ),
        (
            r#"<bsdf type="mask"><float name="opacity" value="1.5"/><bsdf type="diffuse"/></bsdf>"#,
            "opacity must be in [0, 1], got 1.5",
        ),
        (
            r#"<bsdf type="mask"><bsdf type="mask"><bsdf type="diffuse"/></bsdf></bsdf>"#,
            "a mask inside a mask is not supported",
        ),
    ];
    for (bsdf, want) in cases {
        let Err(e) = load(dir.path(), bsdf) else {
            panic!("{bsdf} loaded");
        };
        assert!(e.contains("s.xml") && e.contains(want), "{bsdf}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
