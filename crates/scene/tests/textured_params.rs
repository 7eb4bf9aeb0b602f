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
        // A blend's weight (the control: another weight).
        (
            "blendbsdf",
            format!(r#"<bsdf type="diffuse"/><bsdf type="roughconductor">{gold}</bsdf>"#),
            constant_checkerboard("weight", a),
            format!(r#"<float name="weight" value="{la:?}"/>"#),
        ),
        // A rough plastic's roughness (its coating's tables follow it).
        (
            "roughplastic",
            ggx.to_string(),
            constant_checkerboard("alpha", a),
            format!(r#"<float name="alpha" value="{la:?}"/>"#),
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
        } else if textured.contains("weight") {
            r#"<float name="weight" value="0.9"/>"#
        } else {
            ""
        };
        let default = render(dir.path(), &bsdf(control));
        assert!(t == c, "{ty} {textured}: differs from its constant");
        assert!(c != default, "{ty} {constant}: the control must differ");
    }
}

/// A conductor's `eta` and `k` take textures read unclamped: a checkerboard of values above
/// 1, and a float (EXR) bitmap; also inside a blend. The control: the default index (a perfect
/// mirror) renders differently.
#[test]
fn a_textured_index_of_refraction_renders_as_its_constant() {
    let dir = tempfile::tempdir().unwrap();
    exr::prelude::write_rgb_file(dir.path().join("eta.exr"), 2, 2, |_, _| {
        (0.2f32, 0.9f32, 1.1f32)
    })
    .unwrap();
    let ggx = r#"<string name="distribution" value="ggx"/>"#;
    let exr = r#"<texture type="bitmap" name="eta"><string name="filename" value="eta.exr"/>
        <string name="filter_type" value="nearest"/>
        </texture>"#;
    let k3 = r#"<rgb name="k" value="3"/>"#;
    let eta02 = r#"<rgb name="eta" value="0.2"/>"#;
    let eta_exr = r#"<rgb name="eta" value="0.2, 0.9, 1.1"/>"#;
    let blend = |inner: &str| {
        format!(
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/>
                <bsdf type="roughconductor">{ggx}{inner}</bsdf></bsdf>"#
        )
    };
    // (the BSDF with textures, with their constants, with the default index)
    let cases = [
        (
            format!(
                r#"<bsdf type="conductor">{}{k3}</bsdf>"#,
                constant_checkerboard("eta", 2.5)
            ),
            format!(r#"<bsdf type="conductor"><rgb name="eta" value="2.5"/>{k3}</bsdf>"#),
            r#"<bsdf type="conductor"/>"#.to_string(),
        ),
        (
            format!(
                r#"<bsdf type="roughconductor">{ggx}{eta02}{}</bsdf>"#,
                constant_checkerboard("k", 3.7)
            ),
            format!(
                r#"<bsdf type="roughconductor">{ggx}{eta02}<rgb name="k" value="3.7"/></bsdf>"#
            ),
            // `eta` 0 reflects everything whatever `k` is: the control keeps 0.2.
            format!(r#"<bsdf type="roughconductor">{ggx}{eta02}</bsdf>"#),
        ),
        (
            format!(r#"<bsdf type="conductor">{exr}{k3}</bsdf>"#),
            format!(r#"<bsdf type="conductor">{eta_exr}{k3}</bsdf>"#),
            r#"<bsdf type="conductor"/>"#.to_string(),
        ),
        (
            blend(&format!("{exr}{k3}")),
            blend(&format!("{eta_exr}{k3}")),
            blend(""),
        ),
    ];
    for (textured, constant, default) in &cases {
        let t = render(dir.path(), textured);
        let c = render(dir.path(), constant);
        let d = render(dir.path(), default);
        assert!(t == c, "{textured}: differs from its constant");
        assert!(c != d, "{constant}: the control must differ");
    }
}

#[test]
fn bad_textures_are_one_error_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            r#"<bsdf type="blendbsdf"><float name="weight" value="1.5"/>
                <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>"#,
            "weight must be in [0, 1], got 1.5",
        ),
        (
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/>
                <bsdf type="blendbsdf"><float name="weight" value="0.5"/>
                <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf></bsdf>"#,
            "a blendbsdf inside a blendbsdf is not supported",
        ),
        (
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/>
                </bsdf>"#,
            "blends 1 BSDFs, expected two",
        ),
        (
            r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>"#,
            "needs a `weight`",
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

/// Mitsuba's `blendbsdf`: its two BSDFs (nested, or `<ref>`, in the order they appear) become
/// the blend's parts with their own parameters and textures; a textured weight is the
/// material's.
#[test]
fn a_blend_loads_with_its_two_bsdfs() {
    use rt_core::microfacet::Microfacet;
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 255]))
        .save(dir.path().join("magenta.png"))
        .unwrap();
    let bsdf = r#"<bsdf type="twosided"><bsdf type="blendbsdf">
        <float name="weight" value="0.3"/>
        <bsdf type="roughconductor"><string name="material" value="Au"/>
            <ref name="specular_reflectance" id="magenta"/></bsdf>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>
    </bsdf></bsdf>"#;
    let s = load(dir.path(), bsdf).unwrap();
    let m = s
        .scene
        .materials
        .iter()
        .find(|m| m.blend.is_some())
        .expect("a blend");
    let b = m.blend.as_ref().unwrap();
    assert_eq!(b.weight, 0.3);
    let Microfacet::Conductor(c) = b.parts[0].bsdf else {
        panic!("{:?}", b.parts[0].bsdf);
    };
    assert!(
        c.two_sided,
        "the twosided around the blend reaches its conductor"
    );
    assert!(b.parts[0].textures.specular_reflectance.is_some());
    assert_eq!(
        b.parts[1].bsdf,
        Microfacet::Diffuse(rt_core::microfacet::Diffuse {
            reflectance: Rgb::new(0.2, 0.4, 0.6)
        })
    );
    assert!(m.microfacet.is_none() && m.layers.is_empty());
    // A textured weight.
    let textured = bsdf.replace(
        r#"<float name="weight" value="0.3"/>"#,
        r#"<texture type="checkerboard" name="weight"/>"#,
    );
    let s = load(dir.path(), &textured).unwrap();
    let m = s
        .scene
        .materials
        .iter()
        .find(|m| m.blend.is_some())
        .unwrap();
    assert!(m.blend.as_ref().unwrap().weight_texture.is_some());
    // Weights 0 and 1 render as the BSDF they keep, bit for bit; 0.5 as neither.
    let gold = r#"<bsdf type="roughconductor"><string name="material" value="Au"/></bsdf>"#;
    let white = r#"<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.8, 0.8, 0.8"/></bsdf>"#;
    let blend = |w: f32| {
        format!(
            r#"<bsdf type="blendbsdf"><float name="weight" value="{w:?}"/>{gold}{white}</bsdf>"#
        )
    };
    let (g, p) = (render(dir.path(), gold), render(dir.path(), white));
    assert!(render(dir.path(), &blend(0.0)) == g);
    assert!(render(dir.path(), &blend(1.0)) == p);
    let half = render(dir.path(), &blend(0.5));
    assert!(half != g && half != p && g != p);
}

/// A checkerboard roughness on `roughplastic` (which Mitsuba 3 refuses): every pixel whose
/// footprint lies in one square renders the bits of the constant roughness of that square
/// (the two values are the ends of the texture's range, where the coating's tables are
/// computed exactly); only pixels on the squares' edges are neither. Control: the two
/// constants render differently.
#[test]
fn a_checkerboard_roughness_on_rough_plastic_renders_each_square_as_its_constant() {
    let dir = tempfile::tempdir().unwrap();
    let (a0, a1) = (0.05f32, 0.6f32);
    let (l0, l1) = (luminance(Rgb::splat(a0)), luminance(Rgb::splat(a1)));
    let plastic = |alpha: &str| {
        format!(
            r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
            <rgb name="diffuse_reflectance" value="0.2, 0.5, 0.3"/>{alpha}</bsdf>"#
        )
    };
    let textured = render(
        dir.path(),
        &plastic(&format!(
            r#"<texture type="checkerboard" name="alpha"><rgb name="color0" value="{a0:?}"/>
            <rgb name="color1" value="{a1:?}"/></texture>"#
        )),
    );
    let constant = |l: f32| {
        render(
            dir.path(),
            &plastic(&format!(r#"<float name="alpha" value="{l:?}"/>"#)),
        )
    };
    let (c0, c1) = (constant(l0), constant(l1));
    assert!(c0 != c1, "the control must differ");
    let (mut n0, mut n1, mut neither, mut seen) = (0, 0, 0, 0);
    for ((t, x), y) in textured.chunks(3).zip(c0.chunks(3)).zip(c1.chunks(3)) {
        // Pixels that miss the rectangle see the sky in all three renders.
        if x == y {
            continue;
        }
        seen += 1;
        match (t == x, t == y) {
            (true, _) => n0 += 1,
            (_, true) => n1 += 1,
            _ => neither += 1,
        }
    }
    assert!(n0 > seen / 5 && n1 > seen / 5, "{n0} and {n1} of {seen}");
    assert!(
        neither * 5 < seen,
        "{neither} of {seen} pixels match no constant"
    );
}

/// Mitsuba reads a bitmap with v = 0 at its top row and evaluates a checkerboard on its own
/// uvs, whose v is 1 − ours on every shape: seen face-on, the bottom of a rectangle (local
/// y = −1, Mitsuba's v = 0) shows the bitmap's top row and the checkerboard's colour at
/// Mitsuba's v. Control: each texture's two colours differ between the bottom and the top, so
/// a texture read in the wrong v shows the wrong colour at both.
#[test]
fn textures_on_a_rectangle_and_a_mesh_read_mitsubas_v() {
    let dir = tempfile::tempdir().unwrap();
    // Top row red, bottom row blue.
    image::RgbImage::from_fn(1, 2, |_, y| {
        image::Rgb(if y == 0 { [255, 0, 0] } else { [0, 0, 255] })
    })
    .save(dir.path().join("rows.png"))
    .unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/reference/bump-plane.obj"),
        dir.path().join("plane.obj"),
    )
    .unwrap();
    let bitmap = r#"<texture type="bitmap" name="reflectance"><string name="filename" value="rows.png"/>
        <string name="filter_type" value="nearest"/></texture>"#;
    // Mitsuba's v + 0.1: red for v < 0.4 and v > 0.9, blue between (u < ½).
    let checker = r#"<texture type="checkerboard" name="reflectance"><rgb name="color0" value="1, 0, 0"/>
        <rgb name="color1" value="0, 0, 1"/><transform name="to_uv"><translate y="0.1"/></transform></texture>"#;
    // The plane mesh (x-z in [-2, 2]², uvs 0..2 with v = 0 at z = 2, the file's convention)
    // stood up and halved: its file v runs 0..2 from the bottom up, Mitsuba's (1 − v) 1..−1.
    // The left column's bottom pixel (file v ≈ 0.28, Mitsuba's ≈ 0.72) is blue, its top
    // pixel (≈ 1.72, ≈ −0.72) red.
    let cases = [
        ("rectangle", "", bitmap, [1.0, 0.0], "the bitmap's top row"),
        (
            "rectangle",
            "",
            checker,
            [1.0, 0.0],
            "the checkerboard at Mitsuba's v",
        ),
        (
            "obj",
            r#"<string name="filename" value="plane.obj"/>"#,
            checker,
            [0.0, 1.0],
            "the checkerboard at Mitsuba's v on a mesh",
        ),
    ];
    for (shape, file, texture, [bottom_red, top_red], what) in cases {
        let to_world = if shape == "obj" {
            r#"<scale value="0.5"/><rotate x="1" angle="90"/>"#
        } else {
            ""
        };
        let xml = format!(
            r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective"><float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
            <rfilter type="box"/></film>
    </sensor>
    <shape type="{shape}">{file}<transform name="to_world">{to_world}</transform>
        <bsdf type="diffuse">{texture}</bsdf></shape>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
</scene>"#
        );
        std::fs::write(dir.path().join("v.xml"), xml).unwrap();
        let s = rt_scene::load(&dir.path().join("v.xml")).unwrap_or_else(|e| panic!("{e}"));
        let film = rt_testkit::render(&s.scene, &rt_integrators::PathIntegrator::new(2), 4, 1);
        let image = film.mean_image();
        // The left column's top and bottom pixels (u < ½ on both shapes).
        let red = |row: usize| {
            let p = image[row * 8];
            (p.x > 0.5 && p.z < 0.1) as u8 as f32
        };
        assert_eq!(
            [red(7), red(0)],
            [bottom_red, top_red],
            "{shape}: {what} (bottom, top: {}, {})",
            image[56],
            image[0]
        );
    }
}

/// A texture on a shape whose uvs are not Mitsuba's (sphere, cube, disk) is a warning naming
/// the shape, nested or by reference; the same shape without a texture, or a rectangle with
/// one, is not.
#[test]
fn textures_on_shapes_without_mitsubas_uvs_are_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 255]))
        .save(dir.path().join("magenta.png"))
        .unwrap();
    let textured = r#"<bsdf type="diffuse"><ref name="reflectance" id="magenta"/></bsdf>"#;
    let blended = r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/>
        <bsdf type="diffuse"><ref name="reflectance" id="magenta"/></bsdf></bsdf>"#;
    let plain = r#"<bsdf type="diffuse"/>"#;
    for (shape, bsdf, warned) in [
        ("sphere", textured, true),
        ("cube", blended, true),
        ("disk", textured, true),
        ("sphere", plain, false),
        ("rectangle", textured, false),
    ] {
        let xml = scene(bsdf).replace(
            r#"<shape type="rectangle">"#,
            &format!(r#"<shape type="{shape}">"#),
        );
        std::fs::write(dir.path().join("w.xml"), xml).unwrap();
        let s = rt_scene::load(&dir.path().join("w.xml")).unwrap_or_else(|e| panic!("{e}"));
        let said = s.warnings.iter().any(|w| {
            w.contains(&format!(
                "shape \"{shape}\": its texture coordinates are not Mitsuba's"
            ))
        });
        assert_eq!(said, warned, "{shape} {bsdf}: {:?}", s.warnings);
    }
}
