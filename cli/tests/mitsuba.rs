//! `render scene.xml`, `render -D`, and `render convert`: a Mitsuba scene renders, its TOML
//! conversion renders the same bytes, parameters reach the file, a pixel filter the light
//! tracer cannot apply is refused, and bad files are one error line.

mod common;

use common::{one_error_line, render};

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="spp" value="2"/>
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 2, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/>
            <rfilter type="gaussian"/></film>
    </sensor>
    <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform>
        <ref id="grey"/>
    </shape>
    <shape type="sphere"><point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
        <bsdf type="roughconductor"><string name="material" value="Cu"/></bsdf></shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="4, 4, 4"/></emitter>
    </shape>
</scene>
"#;

#[test]
fn xml_and_its_conversion_render_the_same_bytes() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(dir.join("s.xml"), SCENE).unwrap();
    let out = render(dir, &["s.xml", "-q", "-o", "xml.exr"]);
    assert!(out.status.success(), "{out:?}");
    let out = render(dir, &["convert", "s.xml", "-o", "s.toml"]);
    assert!(out.status.success(), "{out:?}");
    let toml = std::fs::read_to_string(dir.join("s.toml")).unwrap();
    assert!(toml.contains("pixel_filter = \"gaussian:splat\""), "{toml}");
    let out = render(dir, &["s.toml", "-q", "-o", "toml.exr"]);
    assert!(out.status.success(), "{out:?}");
    let (a, b) = (
        std::fs::read(dir.join("xml.exr")).unwrap(),
        std::fs::read(dir.join("toml.exr")).unwrap(),
    );
    assert!(
        a == b,
        "the XML and its TOML conversion render different images"
    );
    // -D reaches $spp: a different sample count is a different image.
    let out = render(dir, &["s.xml", "-D", "spp=3", "-q", "-o", "d.exr"]);
    assert!(out.status.success(), "{out:?}");
    assert!(std::fs::read(dir.join("d.exr")).unwrap() != a);
}

#[test]
fn bad_input_is_one_line() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(
        dir.join("s.xml"),
        SCENE.replace("roughconductor", "principled"),
    )
    .unwrap();
    let out = render(dir, &["s.xml", "-q", "-o", "x.exr"]);
    let line = one_error_line(&out);
    assert!(
        line.contains("s.xml:17:9:") && line.contains("bsdf \"principled\" is not supported"),
        "{line}"
    );
    std::fs::write(dir.join("s.xml"), SCENE).unwrap();
    // A malformed -D is a usage error (clap's exit code 2).
    let out = render(dir, &["s.xml", "-D", "=3", "-o", "x.exr"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`=3` is not NAME=VALUE"));
    // The light tracer splats: it cannot place samples by a Gaussian filter.
    let line = one_error_line(&render(
        dir,
        &["s.xml", "--integrator", "light", "-q", "-o", "x.exr"],
    ));
    assert!(
        line.contains("pixel filter gaussian:stddev=0.5:splat"),
        "{line}"
    );
    // Its Gaussian is splatted, as Mitsuba does: the film keeps no per-pixel AOVs.
    let line = one_error_line(&render(
        dir,
        &["s.xml", "--aov", "albedo", "-q", "-o", "x.exr"],
    ));
    assert!(
        line.contains("splats its pixel filter (gaussian:stddev=0.5:splat)")
            && line.contains("--aov albedo"),
        "{line}"
    );
    let line = one_error_line(&render(dir, &["convert", "s.toml", "-o", "x.toml"]));
    assert!(line.contains("not a Mitsuba scene file"), "{line}");
}
