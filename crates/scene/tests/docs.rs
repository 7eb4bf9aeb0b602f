//! `docs/scene-format.md`'s examples load. (That it documents every key is checked where the
//! keys are defined, against the `*Desc` types themselves: `crates/scene/src/desc.rs`.)

mod common;

use std::path::Path;

fn doc() -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene-format.md"),
    )
    .unwrap()
}

/// The fenced ```toml blocks of the document.
fn toml_blocks(doc: &str) -> Vec<String> {
    doc.split("```toml\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap().to_string())
        .collect()
}

#[test]
fn the_complete_example_loads() {
    let doc = doc();
    let example = toml_blocks(&doc)
        .into_iter()
        .find(|b| b.contains("[[camera]]") && b.contains("[render]"))
        .expect("the complete example");
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("textures")).unwrap();
    std::fs::create_dir_all(dir.path().join("meshes")).unwrap();
    image::RgbImage::from_pixel(4, 4, image::Rgb([180, 120, 60]))
        .save(dir.path().join("textures/wood.png"))
        .unwrap();
    // A 32 × 32 grid: 2,048 triangles, enough for the [0, 1000) assignment.
    let mut obj = String::new();
    for j in 0..=32 {
        for i in 0..=32 {
            obj += &format!("v {} {} 0\n", i as f32 / 32.0, j as f32 / 32.0);
        }
    }
    for j in 0..32 {
        for i in 0..32 {
            let v = |a: usize, b: usize| b * 33 + a + 1;
            obj += &format!(
                "f {} {} {} {}\n",
                v(i, j),
                v(i + 1, j),
                v(i + 1, j + 1),
                v(i, j + 1)
            );
        }
    }
    std::fs::write(dir.path().join("meshes/bunny.obj"), obj).unwrap();
    let p = dir.path().join("example.toml");
    std::fs::write(&p, &example).unwrap();
    let s = rt_scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.scene.cameras.len(), 2);
    assert_eq!(
        s.render.aov.as_deref(),
        Some(&["albedo".to_string(), "normal".to_string()][..])
    );
    let bunny = s.scene.objects.iter().find(|o| o.name == "bunny").unwrap();
    assert_eq!(bunny.count, 2048);
    // The layered snippet is a valid material too.
    let snippet = toml_blocks(&doc)
        .into_iter()
        .find(|b| b.contains("car-paint"))
        .unwrap();
    let extra = format!(
        "{snippet}[[geometry]]\nname = \"q\"\nshape = \"disk\"\nradius = 1\nmaterial = \"car-paint\"\n"
    );
    common::load_in(dir.path(), &extra).unwrap();
}

#[test]
fn the_sky_examples_load_with_the_sun_where_they_say() {
    let doc = doc();
    let examples: Vec<String> = toml_blocks(&doc)
        .into_iter()
        .filter(|b| b.contains("sky = {"))
        .collect();
    assert_eq!(examples.len(), 2, "the two sky examples");
    let dir = tempfile::tempdir().unwrap();
    let sun_of = |text: &str| {
        let s = common::load_in(dir.path(), text).unwrap_or_else(|e| panic!("{e}"));
        s.scene.environment.map().unwrap().sun().unwrap().dir()
    };
    // "the sun low in the west": west is −x.
    let zurich = sun_of(&examples[0]);
    assert!(
        zurich.x < -0.8 && (0.1..0.35).contains(&zurich.y),
        "{zurich}"
    );
    // "30° above the horizon, towards +x".
    let direct = sun_of(&examples[1]);
    assert!((direct.y - 0.5).abs() < 1e-3 && direct.x > 0.86, "{direct}");
}

#[test]
fn the_light_example_loads() {
    let snippet = toml_blocks(&doc())
        .into_iter()
        .find(|b| b.contains("[[light]]"))
        .expect("the [[light]] example");
    let dir = tempfile::tempdir().unwrap();
    let s = common::load_in(dir.path(), &snippet).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.scene.delta_lights.len(), 2);
}
