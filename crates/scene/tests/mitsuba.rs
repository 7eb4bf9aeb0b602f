//! Mitsuba scene files (`rt_scene::mitsuba`): the reader (dialects, parameters, includes,
//! references, transforms), the translation of each element, the errors, and the peer scenes
//! in ../shared/data/mitsuba.

use std::path::{Path, PathBuf};

use glam::Vec3;
use rt_scene::{mitsuba, FileAccess, LoadedScene, SceneError};

fn data(rel: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/mitsuba")
        .join(rel);
    if p.exists() {
        return Some(p);
    }
    assert!(
        std::env::var_os("RT_REQUIRE_DATA").is_none(),
        "{} is missing (RT_REQUIRE_DATA is set)",
        p.display()
    );
    eprintln!("skipped: {} is missing", p.display());
    None
}

/// Writes `files` (name, text) into a fresh directory and loads the first as a scene.
fn load_files(files: &[(&str, &str)], defines: &[(&str, &str)]) -> Result<LoadedScene, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let path = dir.path().join(files[0].0);
    let r = rt_scene::load_defined(&path, &FileAccess::open(), &defines);
    // Error lines name the file: keep only its name so that tests can compare them.
    r.map_err(|e| match e {
        SceneError::Scene { file, at, message } => SceneError::Scene {
            file: PathBuf::from(file.file_name().unwrap()),
            at,
            message,
        },
        other => other,
    })
}

/// A scene around `body`: a camera, and a lit quad unless `body` has shapes of its own.
fn scene(version: &str, body: &str) -> String {
    format!(
        r#"<scene version="{version}">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/>
            <rfilter type="box"/></film>
    </sensor>
{body}
</scene>"#
    )
}

const LAMP: &str = r#"<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>"#;

fn err(r: Result<LoadedScene, SceneError>) -> String {
    r.expect_err("should fail").to_string()
}

#[test]
fn a_lit_rectangle_with_a_camera() {
    let s = load_files(&[("s.xml", &scene("3.0.0", LAMP))], &[]).unwrap();
    let sc = &s.scene;
    assert_eq!(sc.triangle_count(), 2);
    let cam = &sc.cameras[0];
    assert_eq!((cam.width, cam.height), (64, 32));
    // fov_axis x (Mitsuba's default): 45° across the 64 pixels, so tan(v/2) = tan(22.5°)/2.
    let v = 2.0 * ((22.5f32).to_radians().tan() / 2.0).atan().to_degrees();
    assert!((cam.fov_y_deg - v).abs() < 1e-4, "{} vs {v}", cam.fov_y_deg);
    assert!((cam.position - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-6);
    assert!((cam.forward - Vec3::NEG_Z).length() < 1e-6);
    // Mitsuba's rectangle: [-1, 1]² in z = 0, facing +z (towards the camera).
    let t = sc.triangles[0];
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    assert!(n.z > 0.0, "{n}");
    assert!(t
        .iter()
        .all(|p| p.x.abs() == 1.0 && p.y.abs() == 1.0 && p.z == 0.0));
    let m = sc.material_of(0);
    assert_eq!(m.emission.to_array(), [1.0, 2.0, 3.0]);
}

#[test]
fn defaults_and_defines_fill_parameters() {
    let body = format!(
        r#"<default name="spp" value="16"/><default name="depth" value="5"/>
        <integrator type="path"><integer name="max_depth" value="$depth"/></integrator>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>{LAMP}"#
    );
    // The sampler belongs in the sensor; put it there.
    let text = scene("3.0.0", &body).replace(
        "<rfilter type=\"box\"/></film>",
        "<rfilter type=\"box\"/></film><sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spp\"/></sampler>",
    );
    let text = text.replace(
        r#"<sampler type="independent"><integer name="sample_count" value="$spp"/></sampler><shape"#,
        "<shape",
    );
    let s = load_files(&[("s.xml", &text)], &[]).unwrap();
    assert_eq!(s.render.spp, Some(16));
    // Mitsuba counts path segments, we count bounces.
    assert_eq!(s.render.max_depth, Some(4));
    let s = load_files(&[("s.xml", &text)], &[("spp", "4"), ("depth", "-1")]).unwrap();
    assert_eq!(s.render.spp, Some(4));
    assert_eq!(s.render.max_depth, Some(10_000));
    let e = err(load_files(
        &[(
            "s.xml",
            &text.replace("<default name=\"spp\" value=\"16\"/>", ""),
        )],
        &[],
    ));
    assert!(
        e.starts_with("s.xml:") && e.contains("$spp has no value"),
        "{e}"
    );
    // A TOML scene takes no parameters.
    let e = err(load_files(&[("s.toml", "")], &[("spp", "4")]));
    assert!(
        e.contains("only Mitsuba scene files (.xml) take parameters"),
        "{e}"
    );
}

#[test]
fn includes_refs_and_the_old_dialect() {
    let inc = r#"<scene version="0.6.0"><bsdf type="roughconductor" id="metal">
        <string name="distribution" value="ggx"/><float name="alphaU" value="0.1"/>
        <float name="alphaV" value="0.3"/><string name="material" value="Au"/></bsdf></scene>"#;
    let body = r#"<include filename="materials.xml"/>
        <shape type="cube"><ref id="metal"/></shape>"#;
    let text = scene("0.6.0", body)
        .replace("lookat", "lookAt")
        .replace("to_world", "toWorld");
    let s = load_files(&[("s.xml", &text), ("materials.xml", inc)], &[]).unwrap();
    assert_eq!(s.scene.triangle_count(), 12);
    let m = s.scene.material_of(0);
    let micro = m.microfacet.as_ref().expect("a microfacet material");
    assert!(format!("{micro:?}").contains("Ggx"), "{micro:?}");
    // A reference to nothing is an error at the reference.
    let e = err(load_files(
        &[(
            "s.xml",
            &scene("3.0.0", r#"<shape type="cube"><ref id="nope"/></shape>"#),
        )],
        &[],
    ));
    assert_eq!(e.split(": ").nth(1).unwrap(), "<ref id=\"nope\">");
    assert!(e.starts_with("s.xml:8:20:"), "{e}");
}

#[test]
fn transforms_apply_in_order() {
    // translate then scale: the scale also moves the translated points.
    let body = r#"<shape type="rectangle"><transform name="to_world">
        <translate x="1"/><scale value="2"/><rotate z="1" angle="90"/></transform></shape>"#;
    let s = load_files(&[("s.xml", &scene("3.0.0", body))], &[]).unwrap();
    let t = s.scene.triangles[0];
    // Corner (-1, -1, 0): translate → (0, -1), scale → (0, -2), rotate 90° about z → (2, 0).
    assert!((t[0] - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5, "{t:?}");
}

#[test]
fn unsupported_elements_and_parameters_are_one_line_at_their_position() {
    let cases = [
        (
            r#"<shape type="cube"><bsdf type="principled"/></shape>"#,
            "s.xml:8:20: bsdf \"principled\" is not supported",
        ),
        (
            r#"<shape type="cube"><bsdf type="diffuse"><float name="roughness" value="1"/></bsdf></shape>"#,
            "s.xml:8:41: bsdf \"diffuse\": parameter `roughness` is not supported",
        ),
        (
            r#"<emitter type="projector"/>"#,
            "s.xml:8:1: emitter \"projector\" is not supported",
        ),
        (
            r#"<shape type="bsplinecurve"><string name="filename" value="a.txt"/></shape>"#,
            "s.xml:8:1: shape \"bsplinecurve\" is not supported",
        ),
        (
            r#"<shape type="cube"><bsdf type="diffuse"><rgb name="reflectance" value="1, 2"/></bsdf></shape>"#,
            "s.xml:8:41: <rgb>: `1, 2` is not 3 numbers",
        ),
        (r#"<shape type="cube">"#, "s.xml:9:1: malformed XML"),
    ];
    for (body, want) in cases {
        let e = err(load_files(&[("s.xml", &scene("3.0.0", body))], &[]));
        assert!(e.starts_with(want), "{body}:\n  got  {e}\n  want {want}...");
        assert!(!e.contains('\n'), "{e}");
    }
}

#[test]
fn ignored_parameters_are_warnings() {
    let text = scene("3.0.0", LAMP).replace(
        r#"<rfilter type="box"/>"#,
        r#"<rfilter type="box"/><string name="pixel_format" value="rgba"/>"#,
    );
    let s = load_files(&[("s.xml", &text)], &[]).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("`pixel_format` ignored")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn near_and_far_clip_are_mitsubas() {
    let with = |clips: &str| {
        scene("3.0.0", LAMP).replace(
            r#"<float name="fov" value="45"/>"#,
            &format!(r#"<float name="fov" value="45"/>{clips}"#),
        )
    };
    // Mitsuba's default near clip, and one given.
    let s = load_files(&[("s.xml", &with(""))], &[]).unwrap();
    assert_eq!(s.scene.cameras[0].near_clip, 0.01);
    let s = load_files(
        &[("s.xml", &with(r#"<float name="near_clip" value="0.5"/>"#))],
        &[],
    )
    .unwrap();
    assert_eq!(s.scene.cameras[0].near_clip, 0.5);
    assert!(
        s.warnings.iter().all(|w| !w.contains("clip")),
        "{:?}",
        s.warnings
    );
    // The lamp is 5 away: a far clip beyond it cuts nothing, one before it is refused.
    let far = |f: f64| format!(r#"<float name="far_clip" value="{f}"/>"#);
    assert!(load_files(&[("s.xml", &with(&far(6.0)))], &[]).is_ok());
    let e = err(load_files(&[("s.xml", &with(&far(4.0)))], &[]));
    assert!(e.contains("far_clip 4 would hide geometry"), "{e}");
    assert!(!e.contains('\n'), "{e}");
    let e = err(load_files(
        &[(
            "s.xml",
            &with(r#"<float name="near_clip" value="2"/><float name="far_clip" value="1"/>"#),
        )],
        &[],
    ));
    assert!(e.contains("need 0 < near_clip < far_clip"), "{e}");
}

#[test]
fn spectra_become_mitsubas_rgb() {
    let body = r#"<shape type="cube"><bsdf type="diffuse">
        <spectrum name="reflectance" value="400:0.04, 500:0.3, 600:0.6, 700:0.642"/></bsdf>
        <emitter type="area"><spectrum name="radiance" value="400:0, 500:8, 600:15.6, 700:18.4"/></emitter></shape>"#;
    let s = load_files(&[("s.xml", &scene("3.0.0", body))], &[]).unwrap();
    let m = s.scene.material_of(0);
    // What Mitsuba 3.9.1's llvm_ad_rgb gives for these spectra (tools/reference/mitsuba_cie.py).
    let (refl, emit) = ([0.670764, 0.43135, 0.143637], [20.7108, 10.8546, 2.77115]);
    let c = m.layers[0].color.to_array();
    for i in 0..3 {
        assert!((c[i] - refl[i]).abs() < 1e-4 * refl[i], "{c:?}");
        assert!(
            (m.emission.to_array()[i] - emit[i]).abs() < 1e-4 * emit[i],
            "{:?}",
            m.emission
        );
    }
}

#[test]
fn the_cornell_box_from_the_shared_data_loads_and_converts_to_the_same_scene() {
    let Some(p) = data("cbox/scene.xml") else {
        return;
    };
    let xml = rt_scene::load(&p).unwrap();
    assert_eq!(xml.scene.triangle_count(), 38);
    assert_eq!(xml.render.spp, Some(256));
    assert_eq!(xml.render.max_depth, Some(9));
    assert_eq!(
        xml.scene.cameras[0].filter.to_string(),
        "gaussian:stddev=0.5:splat"
    );
    let dir = tempfile::tempdir().unwrap();
    let c = mitsuba::to_toml(&p, Some(dir.path()), &FileAccess::open(), &[]).unwrap();
    // Mesh files are named relative to where the TOML goes, so a converted scene can be
    // shipped beside the data it names.
    assert!(c.toml.contains("file = \"../"), "{}", c.toml);
    let toml_path = dir.path().join("cbox.toml");
    std::fs::write(&toml_path, &c.toml).unwrap();
    let toml = rt_scene::load(&toml_path).unwrap();
    assert_eq!(xml.scene.triangles, toml.scene.triangles);
    assert_eq!(xml.scene.material_ids, toml.scene.material_ids);
    assert_eq!(
        format!("{:?}", xml.scene.materials),
        format!("{:?}", toml.scene.materials)
    );
    assert_eq!(
        format!("{:?}", xml.scene.cameras),
        format!("{:?}", toml.scene.cameras)
    );
}

#[test]
fn rough_plastic_with_a_texture_on_its_base() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 0]))
        .save(dir.path().join("t.png"))
        .unwrap();
    // The texture declared once and referenced by name, as Mitsuba scenes often do.
    let body = r#"<texture type="bitmap" id="wood"><string name="filename" value="t.png"/></texture>
        <shape type="cube"><bsdf type="twosided"><bsdf type="roughplastic">
        <string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>
        <ref name="diffuse_reflectance" id="wood"/></bsdf></bsdf></shape>"#;
    std::fs::write(dir.path().join("s.xml"), scene("3.0.0", body)).unwrap();
    let s = rt_scene::load(&dir.path().join("s.xml")).unwrap();
    let m = s.scene.material_of(0);
    assert_eq!(m.texture, Some(0));
    match m.microfacet {
        Some(rt_core::microfacet::Microfacet::RoughPlastic(p)) => {
            assert_eq!(
                p.diffuse.to_array(),
                [1.0; 3],
                "the texture is the base colour"
            );
        }
        other => panic!("{other:?}"),
    }
}

/// A textured plastic renders as the untextured one whose base is the texture's colour: the
/// tint reaches the BSDF (a tint that did not would leave the textured one white).
#[test]
fn a_texture_on_a_plastic_base_is_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 255]))
        .save(dir.path().join("t.png"))
        .unwrap();
    let render = |base: &str, extra: &str| {
        let body = format!(
            r#"<shape type="rectangle"><bsdf type="{base}"><string name="distribution" value="ggx"/>
            {extra}</bsdf></shape>
            <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>"#
        );
        let text = scene("3.0.0", &body);
        let text = if base == "plastic" {
            text.replace(r#"<string name="distribution" value="ggx"/>"#, "")
        } else {
            text
        };
        std::fs::write(dir.path().join("s.xml"), text).unwrap();
        let s = rt_scene::load(&dir.path().join("s.xml")).unwrap();
        let film = rt_testkit::render(&s.scene, &rt_integrators::PathIntegrator::new(3), 4, 1);
        film.mean_image()
    };
    for base in ["plastic", "roughplastic"] {
        let textured = render(
            base,
            r#"<texture name="diffuse_reflectance" type="bitmap"><string name="filename" value="t.png"/></texture>"#,
        );
        let plain = render(base, r#"<rgb name="diffuse_reflectance" value="1, 0, 1"/>"#);
        let white = render(base, r#"<rgb name="diffuse_reflectance" value="1, 1, 1"/>"#);
        assert!(
            textured == plain,
            "{base}: the textured plastic differs from its colour"
        );
        assert!(textured != white, "{base}: the control must differ");
    }
}

#[test]
fn ply_shapes_load() {
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    std::fs::write(dir.path().join("t.ply"), ply).unwrap();
    let body = r#"<shape type="ply"><string name="filename" value="t.ply"/>
        <transform name="to_world"><translate z="-1"/></transform></shape>"#;
    std::fs::write(dir.path().join("s.xml"), scene("3.0.0", body)).unwrap();
    let s = rt_scene::load(&dir.path().join("s.xml")).unwrap();
    assert_eq!(
        s.scene.triangles,
        vec![[
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0)
        ]]
    );
}

/// Mitsuba's envmap is ours turned half a turn about +y: with `to_world` M the map's frame is
/// S·M⁻¹, S = diag(−1, 1, −1) (checked against Mitsuba 3 by tools/reference/mitsuba_scene_check.py).
#[test]
fn envmaps_become_rotated_environment_maps() {
    let dir = tempfile::tempdir().unwrap();
    // A map whose every texel differs, so that any wrong turn reads another texel.
    let exr = dir.path().join("m.exr");
    exr::prelude::write_rgb_file(&exr, 16, 8, |x, y| {
        (1.0 + x as f32, 1.0 + y as f32, 1.0 + (x * 8 + y) as f32)
    })
    .unwrap();
    let body = format!(
        r#"<emitter type="envmap"><string name="filename" value="{}"/><float name="scale" value="2"/>
        <transform name="to_world"><rotate y="1" angle="90"/><rotate x="1" angle="30"/></transform></emitter>"#,
        exr.display()
    );
    let xml = dir.path().join("s.xml");
    std::fs::write(&xml, scene("3.0.0", &body)).unwrap();
    let c = mitsuba::to_toml(&xml, None, &FileAccess::open(), &[]).unwrap();
    let env = c.toml.split("[environment]").nth(1).unwrap();
    assert!(env.contains("strength = 2.0"), "{env}");
    let s = rt_scene::load(&xml).unwrap();
    let plain = rt_scene::load_str(
        &format!(
            "[environment]\nmap = \"{}\"\nstrength = 2.0\n[[camera]]\nname = \"c\"\nposition = [0, 0, 0]\nlook_at = [0, 0, -1]\n",
            exr.display()
        ),
        dir.path(),
        Path::new("p.toml"),
    )
    .unwrap();
    // World direction d looks up the plain map at S·M⁻¹·d, M = R_x(30°)·R_y(90°).
    let m = glam::Mat3::from_rotation_x(30f32.to_radians())
        * glam::Mat3::from_rotation_y(90f32.to_radians());
    let to_map = glam::Mat3::from_diagonal(Vec3::new(-1.0, 1.0, -1.0)) * m.transpose();
    let mut differs = 0;
    for i in 0..64 {
        let d = Vec3::new(
            (i as f32 * 0.37).sin(),
            (i as f32 * 0.23).cos(),
            (i as f32 * 0.61).sin(),
        )
        .normalize();
        // The map is interpolated: rounding in the two rotations moves the bits, not the value.
        let near = |a: rt_core::Rgb, b: rt_core::Rgb| {
            (a - b).abs().max_element() <= 1e-3 * b.max_element()
        };
        let want = plain.scene.environment.radiance(to_map * d);
        assert!(near(s.scene.environment.radiance(d), want), "{d}");
        differs += usize::from(!near(plain.scene.environment.radiance(d), want));
    }
    assert!(
        differs > 32,
        "the rotation must matter for this test to see it ({differs})"
    );
    let e = err(load_files(
        &[(
            "s.xml",
            &scene(
                "3.0.0",
                r#"<emitter type="envmap"><string name="filename" value="a.png"/></emitter>"#,
            ),
        )],
        &[],
    ));
    assert!(
        e.contains("only OpenEXR and Radiance .hdr maps are supported"),
        "{e}"
    );
}

#[test]
fn cylinders_flipped_normals_and_instanced_shape_groups() {
    let body = r#"
    <shape type="shapegroup" id="pair">
        <shape type="rectangle" id="a"/>
        <shape type="cylinder"><float name="radius" value="0.5"/></shape>
    </shape>
    <shape type="shapegroup" id="never-placed"><shape type="cube"/></shape>
    <shape type="instance" id="left"><ref id="pair"/>
        <transform name="to_world"><translate x="-3"/></transform></shape>
    <shape type="instance"><ref id="pair"/></shape>
    <shape type="rectangle" id="back"><boolean name="flip_normals" value="true"/>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#;
    let s = load_files(&[("s.xml", &scene("3.0.0", body))], &[]).unwrap();
    let sc = &s.scene;
    let names: Vec<&str> = sc.objects.iter().map(|o| o.name.as_str()).collect();
    // The static rectangle first, then each instance's copy of each group member; the group
    // nothing places is not rendered.
    assert_eq!(
        names,
        [
            "back",
            "left/pair/a",
            "left/pair/shape1",
            "instance1/pair/a",
            "instance1/pair/shape1"
        ]
    );
    let range = |name: &str| {
        let o = sc.objects.iter().find(|o| o.name == name).unwrap();
        o.first as usize..(o.first + o.count) as usize
    };
    // flip_normals: the rectangle faces -z (Mitsuba's rectangle faces +z).
    for t in range("back") {
        let v = sc.triangles[t];
        assert!((v[1] - v[0]).cross(v[2] - v[0]).z < 0.0);
    }
    // The instanced cylinder: radius 0.5 around the z axis moved by -3 in x, from z=0 to 1.
    for t in range("left/pair/shape1") {
        for p in sc.triangles[t] {
            let r = (p.x + 3.0).hypot(p.y);
            assert!(
                (r - 0.5).abs() < 1e-5 && (-1e-6..=1.0 + 1e-6).contains(&p.z),
                "{p}"
            );
        }
    }
    let e = err(load_files(
        &[(
            "s.xml",
            &scene(
                "3.0.0",
                r#"<shape type="instance"><ref id="x"/></shape><bsdf type="diffuse" id="x"/>"#,
            ),
        )],
        &[],
    ));
    assert!(e.contains("must name a shapegroup"), "{e}");
    let e = err(load_files(
        &[(
            "s.xml",
            &scene(
                "3.0.0",
                &format!(
                    r#"<shape type="shapegroup" id="g">{LAMP}</shape><shape type="instance"><ref id="g"/></shape>"#
                ),
            ),
        )],
        &[],
    ));
    assert!(e.contains("emitter inside a shapegroup"), "{e}");
}

#[test]
fn a_film_crop_window_renders_its_part_of_the_film() {
    let film = |extra: &str| {
        format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="45"/>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/>{extra}</film>
    </sensor>
    {LAMP}
</scene>"#
        )
    };
    let s = load_files(
        &[(
            "s.xml",
            &film(
                r#"<integer name="crop_offset_x" value="16"/><integer name="crop_offset_y" value="8"/>
                <integer name="crop_width" value="32"/><integer name="crop_height" value="16"/>"#,
            ),
        )],
        &[],
    )
    .unwrap();
    let cam = &s.scene.cameras[0];
    assert_eq!((cam.width, cam.height), (32, 16));
    assert_eq!(
        cam.crop,
        rt_core::camera::Crop::from_pixels(16, 8, 32, 16, 64, 32)
    );
    // The field of view is the whole film's: the crop's centre ray is the film's centre ray.
    let full = load_files(&[("s.xml", &film(""))], &[]).unwrap();
    assert!(
        (cam.generate_ray(glam::Vec2::new(16.0, 8.0), glam::Vec2::ZERO)
            .dir
            - full.scene.cameras[0]
                .generate_ray(glam::Vec2::new(32.0, 16.0), glam::Vec2::ZERO)
                .dir)
            .length()
            < 1e-6
    );
    let e = err(load_files(
        &[(
            "s.xml",
            &film(
                r#"<integer name="crop_offset_x" value="40"/><integer name="crop_width" value="32"/>"#,
            ),
        )],
        &[],
    ));
    assert!(
        e.contains("crop window 32x32 at (40, 0) does not fit the 64x32 film"),
        "{e}"
    );
}

/// `bumpmap` and `normalmap` wrap any BSDF (here around a `twosided`, as the staircase has
/// them) and become the wrapped material with its map; the bitmap options reach the texture.
#[test]
fn bump_and_normal_maps_wrap_a_bsdf_and_bitmap_options_reach_the_texture() {
    use rt_core::bump::NormalPerturbation;
    use rt_core::texture::{Filter, Wrap};
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([128, 128, 255]))
        .save(dir.path().join("t.png"))
        .unwrap();
    let load = |body: &str| {
        std::fs::write(dir.path().join("s.xml"), scene("3.0.0", body)).unwrap();
        rt_scene::load(&dir.path().join("s.xml"))
    };
    let bump = r#"<shape type="rectangle"><bsdf type="bumpmap"><float name="scale" value="0.25"/>
        <texture type="bitmap"><string name="filename" value="t.png"/>
        <string name="filter_type" value="nearest"/><string name="wrap_mode" value="mirror"/></texture>
        <bsdf type="twosided"><bsdf type="roughconductor"/></bsdf></bsdf></shape>"#;
    let s = load(bump).unwrap();
    let m = s.scene.material_of(0);
    let Some(NormalPerturbation::Bump { texture, scale }) = m.perturbation else {
        panic!("{:?}", m.perturbation)
    };
    assert_eq!(scale, 0.25);
    let t = &s.scene.textures[texture as usize];
    assert_eq!((t.filter, t.wrap), (Filter::Nearest, Wrap::Mirror));
    // sRGB 128 decodes to 0.2158.
    assert!((t.texels[0].x - 0.2158).abs() < 1e-3, "{:?}", t.texels[0]);
    match m.microfacet {
        Some(rt_core::microfacet::Microfacet::Conductor(c)) => assert!(c.two_sided),
        other => panic!("{other:?}"),
    }
    let normal = r#"<shape type="rectangle"><bsdf type="twosided"><bsdf type="normalmap">
        <texture name="normalmap" type="bitmap"><string name="filename" value="t.png"/>
        <boolean name="raw" value="true"/></texture>
        <bsdf type="diffuse"/></bsdf></bsdf></shape>"#;
    let s = load(normal).unwrap();
    let m = s.scene.material_of(0);
    let Some(NormalPerturbation::NormalMap { texture }) = m.perturbation else {
        panic!("{:?}", m.perturbation)
    };
    // Raw: 128 / 255.
    let t = &s.scene.textures[texture as usize];
    assert!(
        (t.texels[0].x - 128.0 / 255.0).abs() < 1e-6,
        "{:?}",
        t.texels[0]
    );
    // A BSDF no shape can name (the staircase's top-level bumpmap) is checked and reported.
    let unused = format!(
        "{}{LAMP}",
        bump.replace(r#"<shape type="rectangle">"#, "")
            .replace("</bsdf></shape>", "</bsdf>")
    );
    let s = load(&unused).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.ends_with(
            "<bsdf type=\"bumpmap\"> has no id, so no shape uses it (Mitsuba ignores it too)"
        )),
        "{:?}",
        s.warnings
    );
    let cases = [
        (
            bump.replace("mirror", "border"),
            "wrap_mode \"border\" is not supported (repeat, mirror and clamp are)",
        ),
        (
            bump.replace("nearest", "bicubic"),
            "filter_type \"bicubic\" is not supported (bilinear and nearest are)",
        ),
        (
            bump.replace("<bsdf type=\"twosided\">", "<texture type=\"bitmap\"><string name=\"filename\" value=\"t.png\"/></texture><bsdf type=\"twosided\">"),
            "has 2 textures, expected one height map",
        ),
        (
            normal.replace("name=\"normalmap\" ", ""),
            "needs a texture named `normalmap`",
        ),
        (
            bump.replace("<bsdf type=\"twosided\"><bsdf type=\"roughconductor\"/></bsdf>", ""),
            "wraps 0 BSDFs, expected one",
        ),
    ];
    for (body, want) in cases {
        let e = load(&body).expect_err(want).to_string();
        assert!(e.contains(want), "got {e}\nwant {want}");
        assert!(!e.contains('\n'), "{e}");
    }
}

/// The Wooden Staircase (0.5 dialect) loads: its unnamed top-level `bumpmap` is reported and
/// unused, as in Mitsuba 3, whose shapes name the nested `twosided` conductor; the wood is a
/// two-sided rough plastic (black from behind otherwise).
#[test]
fn the_staircase_from_the_shared_data_loads_as_mitsuba_reads_it() {
    let Some(p) = data("staircase/scene.xml") else {
        return;
    };
    let s = rt_scene::load(&p).unwrap();
    assert!(s.scene.triangle_count() > 200_000);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("<bsdf type=\"bumpmap\"> has no id")),
        "{:?}",
        s.warnings
    );
    let by_name = |n: &str| s.scene.materials.iter().find(|m| m.name == n).unwrap();
    let aluminium = by_name("BrushedAluminium");
    assert_eq!(aluminium.perturbation, None);
    match by_name("WoodStairs").microfacet {
        Some(rt_core::microfacet::Microfacet::RoughPlastic(p)) => assert!(p.two_sided),
        other => panic!("{other:?}"),
    }
}

/// The one delta light of a scene around `emitter`, with the lit quad beside it.
fn delta_light(emitter: &str) -> rt_core::delta_light::DeltaLight {
    let s = load_files(
        &[("s.xml", &scene("3.0.0", &format!("{LAMP}{emitter}")))],
        &[],
    )
    .unwrap();
    assert_eq!(s.scene.delta_lights.len(), 1, "{emitter}");
    s.scene.delta_lights[0]
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5 * b.length().max(1.0)
}

#[test]
fn point_lights_by_position_or_to_world_with_spectral_intensity() {
    use rt_core::delta_light::DeltaLight;
    // The spectrum of `spectra_become_mitsubas_rgb`, as emission, times 1e5 (the
    // cbox-point-light scene's): Mitsuba's RGB of it, scaled.
    let DeltaLight::Point {
        position,
        intensity,
    } = delta_light(
        r#"<emitter type="point"><spectrum name="intensity" value="400:0, 500:800000, 600:1560000.0, 700:1840000.0"/>
           <point name="position" x="278" y="500" z="-800"/></emitter>"#,
    )
    else {
        panic!("not a point light")
    };
    assert_eq!(position, Vec3::new(278.0, 500.0, -800.0));
    let want = Vec3::new(20.7108, 10.8546, 2.77115) * 1e5;
    assert!(
        (intensity - want).abs().max_element() < 1e-4 * want.x,
        "{intensity}"
    );
    // The translation of to_world; intensity defaults to 1.
    let l = delta_light(
        r#"<emitter type="point"><transform name="to_world"><translate x="1" y="2" z="3"/></transform></emitter>"#,
    );
    assert_eq!(
        l,
        DeltaLight::Point {
            position: Vec3::new(1.0, 2.0, 3.0),
            intensity: Vec3::ONE
        }
    );
}

#[test]
fn spot_lights_shine_along_to_worlds_z_with_mitsubas_angles() {
    use rt_core::delta_light::DeltaLight;
    // Mitsuba's documentation example: from (1, 1, 1) towards (1, 2, 1); defaults 20° and 15°.
    let DeltaLight::Spot {
        position,
        axis,
        intensity,
        cutoff,
        beam_width,
    } = delta_light(
        r#"<emitter type="spot"><rgb name="intensity" value="1, 2, 3"/><transform name="to_world">
           <lookat origin="1, 1, 1" target="1, 2, 1" up="0, 0, 1"/></transform></emitter>"#,
    )
    else {
        panic!("not a spot")
    };
    assert!(close(position, Vec3::ONE), "{position}");
    assert!(close(axis, Vec3::Y), "{axis}");
    assert_eq!(intensity, Vec3::new(1.0, 2.0, 3.0));
    assert!((cutoff - 20f32.to_radians()).abs() < 1e-6);
    assert!((beam_width - 15f32.to_radians()).abs() < 1e-6);
    // Given angles, and a beam_width that defaults to ¾ of a given cutoff.
    let DeltaLight::Spot {
        cutoff, beam_width, ..
    } = delta_light(r#"<emitter type="spot"><float name="cutoff_angle" value="40"/></emitter>"#)
    else {
        panic!("not a spot")
    };
    assert!((cutoff - 40f32.to_radians()).abs() < 1e-6);
    assert!((beam_width - 30f32.to_radians()).abs() < 1e-6);
}

#[test]
fn directional_lights_travel_along_direction_or_to_worlds_z() {
    use rt_core::delta_light::DeltaLight;
    let l = delta_light(
        r#"<emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/>
           <rgb name="irradiance" value="3, 2, 1"/></emitter>"#,
    );
    assert_eq!(
        l,
        DeltaLight::Directional {
            direction: Vec3::NEG_Y,
            irradiance: Vec3::new(3.0, 2.0, 1.0)
        }
    );
    // Mitsuba's default is +z; to_world turns it.
    let DeltaLight::Directional { direction, .. } = delta_light(r#"<emitter type="directional"/>"#)
    else {
        panic!("not directional")
    };
    assert_eq!(direction, Vec3::Z);
    let DeltaLight::Directional { direction, .. } = delta_light(
        r#"<emitter type="directional"><transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>"#,
    ) else {
        panic!("not directional")
    };
    assert!(close(direction, Vec3::NEG_Y), "{direction}");
}

#[test]
fn bad_delta_emitters_are_one_line() {
    let cases = [
        (
            r#"<emitter type="point"><point name="position" x="0" y="0" z="0"/><transform name="to_world"><translate x="1"/></transform></emitter>"#,
            "give `position` or `to_world`, not both",
        ),
        (
            r#"<emitter type="spot"><float name="cutoff_angle" value="10"/><float name="beam_width" value="20"/></emitter>"#,
            "need 0 < cutoff_angle ≤ 180 and 0 ≤ beam_width ≤ cutoff_angle",
        ),
        (
            r#"<emitter type="spot"><transform name="to_world"><scale x="1" y="2" z="1"/></transform></emitter>"#,
            "to_world must be a rotation, translation and uniform scale",
        ),
        (
            r#"<emitter type="directional"><vector name="direction" x="0" y="0" z="0"/></emitter>"#,
            "direction must be a non-zero vector",
        ),
        (
            r#"<emitter type="point"><texture name="intensity" type="bitmap"/></emitter>"#,
            "a texture on `intensity` is not supported",
        ),
        (
            r#"<emitter type="point"><float name="radius" value="1"/></emitter>"#,
            "`radius` is not supported",
        ),
    ];
    for (body, want) in cases {
        let e = err(load_files(&[("s.xml", &scene("3.0.0", body))], &[]));
        assert!(
            e.starts_with("s.xml:8:") && e.contains(want),
            "{body}:\n  {e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
}
