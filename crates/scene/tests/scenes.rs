//! The shipped scenes (`scenes/*.toml`) and the shared test meshes (`../shared/data`: a visible
//! skip when absent, a failure under `RT_REQUIRE_DATA=1`).

mod common;

use glam::Vec3;
use rt_core::{Material, Rgb};
use std::path::{Path, PathBuf};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn load_scene(name: &str) -> rt_scene::LoadedScene {
    let p = scenes_dir().join(name);
    rt_scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_shipped_scene_loads_without_warnings() {
    let mut names: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    let expected = [
        "cornell-box.toml",
        "depth-of-field.toml",
        "environment.toml",
        "meshes.toml",
        "showcase.toml",
        "sky.toml",
    ];
    for e in expected {
        assert!(
            names.iter().any(|p| p.ends_with(e)),
            "scenes/{e} is missing"
        );
    }
    for p in &names {
        let s = rt_scene::load(p).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.warnings.is_empty(), "{}: {:?}", p.display(), s.warnings);
        assert!(!s.scene.cameras.is_empty() && s.scene.triangle_count() > 0);
        assert!(!s.scene.lights().is_empty(), "{} has no light", p.display());
        for c in &s.scene.cameras {
            assert!(
                c.width <= 512 && c.height <= 512,
                "{}: keep shipped scenes cheap",
                p.display()
            );
        }
        for m in &s.scene.materials {
            assert_eq!(m.validate(), Ok(()), "{}: {}", p.display(), m.name);
        }
    }
}

/// Unit normal of a triangle's front (counter-clockwise) face.
fn normal(t: &[Vec3; 3]) -> Vec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize()
}

#[test]
fn cornell_box_matches_the_published_data() {
    let s = load_scene("cornell-box.toml");
    let sc = &s.scene;
    // Camera: (278, 273, -800) along +z, up +y, 35 mm lens on 25 mm film, 512².
    let c = &sc.cameras[0];
    assert_eq!(c.position, Vec3::new(278.0, 273.0, -800.0));
    assert_eq!(c.forward, Vec3::Z);
    assert_eq!(c.up, Vec3::Y);
    assert!((c.fov_y_deg - 2.0 * (12.5f32 / 35.0).atan().to_degrees()).abs() < 1e-3);
    assert_eq!((c.width, c.height, c.aperture), (512, 512, 0.0));
    assert_eq!(c.right, -Vec3::X, "the green wall at x = 0 is on the right");
    // Inline geometry only: 16 quads.
    assert_eq!(sc.triangle_count(), 32);
    assert_eq!(sc.objects.len(), 16);
    assert!(sc.textures.is_empty());
    let mat = |name: &str| sc.materials.iter().find(|m| m.name == name).unwrap();
    assert_eq!(
        mat("white"),
        &Material::diffuse("white", Rgb::new(0.725, 0.71, 0.68))
    );
    assert_eq!(
        mat("red"),
        &Material::diffuse("red", Rgb::new(0.63, 0.065, 0.05))
    );
    assert_eq!(
        mat("green"),
        &Material::diffuse("green", Rgb::new(0.14, 0.45, 0.091))
    );
    let light = mat("light");
    assert_eq!(light.emission, Rgb::new(17.0, 12.0, 4.0));
    assert_eq!(light.layers[0].color, Rgb::splat(0.78));
    assert!(!light.two_sided);
    assert!(
        matches!(sc.environment, rt_core::environment::Environment::Constant(c) if c == Rgb::ZERO)
    );
    // Every front face faces into the room, or out of its block; the light faces down,
    // 0.1 mm below the ceiling.
    let room = Vec3::new(278.0, 274.4, 279.6);
    let short = Vec3::new(185.5, 82.5, 169.0);
    let tall = Vec3::new(368.5, 165.0, 351.25);
    for o in &sc.objects {
        for t in &sc.triangles[o.first as usize..(o.first + o.count) as usize] {
            let n = normal(t);
            let centroid = (t[0] + t[1] + t[2]) / 3.0;
            let ok = if o.name == "light" {
                assert!(t.iter().all(|p| p.y == 548.7));
                n.dot(-Vec3::Y) > 0.999
            } else if o.name.starts_with("short-block") {
                n.dot(centroid - short) > 0.0
            } else if o.name.starts_with("tall-block") {
                n.dot(centroid - tall) > 0.0
            } else {
                n.dot(room - centroid) > 0.0
            };
            assert!(ok, "{} faces the wrong way: {t:?}", o.name);
        }
    }
    assert_eq!(sc.lights().emitter_count(), 2);
    assert_eq!(s.render.spp, Some(32));
    assert_eq!(s.render.denoiser.as_deref(), Some("nlm"));
    assert_eq!(s.render.max_depth, Some(16));
    assert_eq!(s.render.integrator.as_deref(), Some("wavefront"));
}

#[test]
fn showcase_has_every_preset_and_a_texture() {
    let s = load_scene("showcase.toml");
    let sc = &s.scene;
    let mat = |name: &str| sc.materials.iter().find(|m| m.name == name).unwrap();
    assert_eq!(mat("frosted-glass").layers[0].hardness, 0.7);
    assert!(mat("frosted-glass").layers[0].transmission);
    assert_eq!(mat("glass").layers[0].hardness, 1.0);
    assert_eq!(mat("two-layer").layers.len(), 2);
    assert!(mat("plastic").layers[0].coat);
    assert_eq!(mat("gold").layers[0].color90, Rgb::ONE);
    let t = mat("checker").texture.unwrap() as usize;
    assert_eq!((sc.textures[t].width, sc.textures[t].height), (64, 64));
    let png = std::fs::metadata(scenes_dir().join("textures/checker.png")).unwrap();
    assert!(png.len() < 50_000);
}

#[test]
fn environment_scene_is_lit_by_the_generated_sky() {
    let s = load_scene("environment.toml");
    let env = &s.scene.environment;
    assert!(matches!(env, rt_core::environment::Environment::Map(_)));
    assert_eq!(
        s.scene.lights().emitter_count(),
        0,
        "the map is the only light"
    );
    // The sun is towards +x, +z at 35° elevation, much brighter than the zenith.
    let sun = Vec3::new(
        35f32.to_radians().cos() * std::f32::consts::FRAC_1_SQRT_2,
        35f32.to_radians().sin(),
        35f32.to_radians().cos() * std::f32::consts::FRAC_1_SQRT_2,
    );
    assert!(env.radiance(sun).x > 100.0, "{}", env.radiance(sun));
    assert!(
        env.radiance(Vec3::Y).z > env.radiance(Vec3::Y).x,
        "blue zenith"
    );
    assert!(env.radiance(Vec3::Y).x < 1.0);
    let exr = std::fs::metadata(scenes_dir().join("sky.exr")).unwrap();
    assert!(exr.len() < 400_000);
}

#[test]
fn sky_scene_is_lit_by_the_preetham_sky_at_the_time_it_says() {
    let s = load_scene("sky.toml");
    let map = s.scene.environment.map().expect("a sky is a map");
    assert_eq!(map.size(), (512, 256));
    let sun = map.sun().expect("with a sun");
    let d = sun.dir();
    // The file's comment: 21° high, a little north of west (west −x, north −z).
    let elevation = d.y.asin().to_degrees();
    assert!((elevation - 21.0).abs() < 1.0, "{elevation}");
    assert!(d.x < -0.9 && d.z < 0.0 && d.z > -0.3, "{d}");
    // Only the sky lights it, and the sun outshines the sky by far.
    assert!(s.scene.lights().emitter_count() == 0 && !s.scene.environment.is_black());
    let zenith = s.scene.environment.radiance(Vec3::Y);
    assert!(
        sun.radiance().y > 1e4 * zenith.y,
        "{} vs {zenith}",
        sun.radiance()
    );
    assert_eq!(
        s.scene.environment.radiance(-Vec3::Y),
        Rgb::ZERO,
        "black below the horizon"
    );
}

#[test]
fn depth_of_field_focuses_on_the_middle_sphere() {
    let s = load_scene("depth-of-field.toml");
    let c = &s.scene.cameras[0];
    assert!(c.aperture > 0.0);
    let middle = Vec3::new(0.0, 0.4, -1.0);
    assert!(((middle - c.position).length() - c.focus_distance).abs() < 1e-3);
    assert_eq!(s.scene.cameras[1].aperture, 0.0);
}

#[test]
fn meshes_scene_uses_file_materials_and_assignments() {
    let s = load_scene("meshes.toml");
    let sc = &s.scene;
    let names: Vec<&str> = sc.materials.iter().map(|m| m.name.as_str()).collect();
    for n in [
        "tetra-ico/copper",
        "tetra-ico/jade",
        "tetra-ico/slate",
        "prism/amber",
        "prism/steel",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    let obj = |name: &str| sc.objects.iter().find(|o| o.name == name).unwrap().clone();
    // OBJ: 4 + 20 triangles + one quad split in two.
    assert_eq!(obj("tetra-ico").count, 26);
    assert_eq!(obj("prism").count, 8);
    let small = obj("small-copy");
    let id = |n: &str| names.iter().position(|&m| m == n).unwrap() as u32;
    let ids = &sc.material_ids[small.first as usize..(small.first + small.count) as usize];
    assert!(ids[..4].iter().all(|&i| i == id("red")));
    assert!(ids[4..].iter().all(|&i| i == id("porcelain")));
    let ico = obj("tetra-ico");
    assert!(
        sc.normals[ico.first as usize + 4].is_some(),
        "the icosahedron has vertex normals"
    );
    assert!(
        sc.normals[ico.first as usize].is_none(),
        "the tetrahedron is flat"
    );
    // The prism faces outward after its node transforms and the scene transform.
    let p = obj("prism");
    let tris = &sc.triangles[p.first as usize..(p.first + p.count) as usize];
    let center = tris.iter().flatten().sum::<Vec3>() / (3 * tris.len()) as f32;
    for t in tris {
        assert!(
            normal(t).dot((t[0] + t[1] + t[2]) / 3.0 - center) > 0.0,
            "{t:?}"
        );
    }
}

// --- Meshes made by others (../shared/data), skipped when absent ---------------------------

fn load_file(file: &Path, material: Option<&str>) -> rt_scene::LoadedScene {
    let m = material.map_or(String::new(), |m| format!("material = \"{m}\"\n"));
    let text = format!(
        "{}[[geometry]]\nname = \"m\"\nfile = \"{}\"\n{m}",
        common::BASE,
        file.display()
    );
    rt_scene::load_str(&text, Path::new("."), Path::new("data.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
}

fn count(s: &rt_scene::LoadedScene) -> u32 {
    s.scene
        .objects
        .iter()
        .find(|o| o.name == "m")
        .unwrap()
        .count
}

/// Triangles of an OBJ file by fan triangulation, from the independent reader of the tests.
fn fan_triangles(path: &Path) -> u32 {
    rt_testkit::obj::read(path).expect("readable").len() as u32
}

#[test]
fn stanford_bunny_obj() {
    let Some(path) = rt_testkit::data::file("models/stanford-bunny.obj") else {
        return;
    };
    let t = std::time::Instant::now();
    let s = load_file(&path, Some("white"));
    // 69,451 is the Stanford bunny's published triangle count (a specification of the data
    // set); the independent reader must agree.
    assert_eq!(count(&s), 69_451);
    assert_eq!(count(&s), fan_triangles(&path));
    println!("bunny loaded in {:?}", t.elapsed());
}

#[test]
fn beast_obj_with_quads_and_pentagons() {
    let Some(path) = rt_testkit::data::file("models/beast.obj") else {
        return;
    };
    // Mostly quads, 10 pentagons and 2 hexagons: as many triangles as fan triangulation gives
    // (counted by the tests' independent reader).
    let s = load_file(&path, Some("white"));
    assert_eq!(count(&s), fan_triangles(&path));
}

#[test]
fn gltf_sample_models() {
    let Some(gltf) = rt_testkit::data::file("gltf") else {
        return;
    };
    // The triangle counts below are those of the Khronos sample models (a specification of
    // the data: the index counts of their primitives divided by three).
    // Duck: GLB with an embedded PNG and a node matrix; its own material.
    let s = load_file(&gltf.join("Duck/Duck.glb"), None);
    assert_eq!(count(&s), 4_212);
    assert_eq!(s.scene.textures.len(), 1);
    assert!(s
        .scene
        .materials
        .iter()
        .any(|m| m.name.starts_with("m/") && m.texture.is_some()));
    // CesiumMilkTruck: external .bin and .png, hierarchy with matrix and TRS, wheels instanced
    // twice.
    let s = load_file(&gltf.join("CesiumMilkTruck/CesiumMilkTruck.gltf"), None);
    assert_eq!(count(&s), 3_624);
    // SimpleSparseAccessor: no materials of its own.
    let dir = gltf.join("SimpleSparseAccessor");
    let file = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "gltf"))
        .unwrap();
    let s = load_file(&file, Some("white"));
    assert_eq!(count(&s), 12);
    // The sparse accessor lifts some vertices to y = 4 (the base grid is flat at y = 0..2).
    let top = s
        .scene
        .triangles
        .iter()
        .flatten()
        .map(|p| p.y)
        .fold(f32::MIN, f32::max);
    assert!(top > 3.9, "sparse values not applied: max y = {top}");
}

#[test]
fn gree_scenes_load_from_the_shared_data() {
    // scenes/shared-data/*.toml read their meshes from ../shared/data: with the data there,
    // each loads whole, with its lamp.
    for (scene, mesh, triangles) in [
        ("sibenik.toml", "scenes/sibenik/sibenik.obj", 75_284),
        (
            "conference.toml",
            "scenes/conference/conference.obj",
            331_179,
        ),
    ] {
        let Some(mesh) = rt_testkit::data::file(mesh) else {
            return;
        };
        let path = rt_testkit::workspace_root()
            .join("scenes/shared-data")
            .join(scene);
        let s = rt_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let object = s.scene.objects.iter().max_by_key(|o| o.count).unwrap();
        assert_eq!(object.count, fan_triangles(&mesh), "{scene}");
        assert_eq!(object.count, triangles, "{scene}");
        assert!(s.scene.materials.iter().any(|m| m.is_emissive()), "{scene}");
    }
}

/// Index of the camera called `name`.
fn camera_named(s: &rt_core::Scene, name: &str) -> usize {
    s.cameras
        .iter()
        .position(|c| c.name == name)
        .unwrap_or_else(|| panic!("no camera {name}"))
}

#[test]
fn the_temporal_scenes_have_a_fixed_camera_and_move() {
    // Issue 14's animated scenes: a fly-through (or orbit) camera that moves and a `fixed` one
    // that does not (the fixed-camera temporal-error measurement).
    for name in ["hall-glossy.toml", "hall-mirror.toml", "dynamic-small.toml"] {
        let mut s = load_scene(name).scene;
        let (main, fixed) = (camera_named(&s, "main"), camera_named(&s, "fixed"));
        let before = (s.cameras[main].position, s.cameras[fixed].position);
        s.set_time(2.0);
        assert_ne!(
            s.cameras[main].position, before.0,
            "{name}: main does not move"
        );
        assert_eq!(s.cameras[fixed].position, before.1, "{name}: fixed moves");
    }
    let s = load_scene("light-toggle.toml").scene;
    assert_eq!(s.cameras[0].name, "fixed");
    assert!(s.camera_motions.is_empty());
}

#[test]
fn the_mirror_hall_has_a_mirror_floor_and_orb_and_the_glossy_hall_a_glossy_floor() {
    let floor = |name: &str| {
        let s = load_scene(name).scene;
        let o = s.objects.iter().find(|o| o.name == "floor").unwrap();
        s.material_of(o.first).clone()
    };
    let (glossy, mirror) = (floor("hall-glossy.toml"), floor("hall-mirror.toml"));
    let max_hardness = |m: &Material| m.layers.iter().map(|l| l.hardness).fold(0.0, f32::max);
    assert!(
        (0.1..1.0).contains(&max_hardness(&glossy)),
        "{:?}",
        glossy.layers
    );
    assert_eq!(mirror.layers.len(), 1);
    assert_eq!(mirror.layers[0].hardness, 1.0);
    let s = load_scene("hall-mirror.toml").scene;
    let orb = s.objects.iter().find(|o| o.name == "orb").unwrap();
    assert_eq!(s.material_of(orb.first).layers[0].hardness, 1.0);
}

#[test]
fn the_light_toggle_lamp_is_off_from_frame_30_to_59_at_24_fps() {
    let mut s = load_scene("light-toggle.toml").scene;
    let lamp = s
        .materials
        .iter()
        .position(|m| m.name == "main-lamp")
        .unwrap();
    for frame in [0, 29, 30, 45, 59, 60, 90] {
        s.set_time((f64::from(frame) / 24.0) as f32);
        let off = s.materials[lamp].emission == Rgb::ZERO;
        assert_eq!(off, (30..60).contains(&frame), "frame {frame}");
        // The dim lamp keeps the room lit.
        assert!(!s.lights().is_empty(), "frame {frame}");
    }
}

#[test]
fn the_sponza_scenes_load_from_the_shared_data_with_their_floor_overridden() {
    let Some(mesh) = rt_testkit::data::file("scenes/sponza-dabrovic/sponza.obj") else {
        return;
    };
    for (scene, hardness) in [("sponza-glossy.toml", 0.3), ("sponza-mirror.toml", 1.0)] {
        let path = rt_testkit::workspace_root()
            .join("scenes/shared-data")
            .join(scene);
        let loaded = rt_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let s = &loaded.scene;
        let sponza = s.objects.iter().find(|o| o.name == "sponza").unwrap();
        assert_eq!(sponza.count, fan_triangles(&mesh), "{scene}");
        // The assigned range is the ground floor: eight triangles at y = 0.09 facing up,
        // together 32.4 m x 14.4 m.
        let floor = sponza.first + 10686..sponza.first + 10694;
        let mut area = 0.0;
        for t in floor.clone() {
            let v = s.triangles[t as usize];
            assert!(
                v.iter().all(|p| (p.y - 0.09).abs() < 0.01),
                "{scene}: {v:?}"
            );
            assert!(normal(&v).y > 0.99, "{scene}: triangle {t} faces down");
            area += 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            let m = s.material_of(t);
            assert_eq!(m.name, "floor", "{scene}");
            let h = m.layers.iter().map(|l| l.hardness).fold(0.0, f32::max);
            assert_eq!(h, hardness, "{scene}");
        }
        // The bounds above are rounded to 0.1 m: 1 % slack.
        assert!(
            (area / (32.4 * 14.4) - 1.0).abs() < 0.01,
            "{scene}: floor area {area}"
        );
        assert_eq!(
            s.material_of(floor.end).name,
            "stone",
            "{scene}: the range spills over"
        );
        assert!(!s.lights().is_empty(), "{scene}");
        camera_named(s, "fixed");
        assert_eq!(s.camera_motions.len(), 1, "{scene}: the fly-through");
    }
}

/// scenes/shared-data/mitsuba-*.toml are `render convert` of ../shared/data/mitsuba's scenes
/// (tools/scenes/convert-mitsuba.sh): each must still be what the reader makes of its XML
/// today, so a change to the translation cannot leave a stale shipped scene behind.
#[test]
fn shipped_mitsuba_conversions_equal_a_fresh_conversion() {
    let shipped = rt_testkit::workspace_root().join("scenes/shared-data");
    let mut seen = 0;
    for entry in std::fs::read_dir(&shipped).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(folder) = name
            .strip_prefix("mitsuba-")
            .and_then(|n| n.strip_suffix(".toml"))
        else {
            continue;
        };
        seen += 1;
        let Some(xml) = rt_testkit::data::file(&format!("mitsuba/{folder}/scene.xml")) else {
            return;
        };
        let fresh =
            rt_scene::mitsuba::to_toml(&xml, Some(&shipped), &rt_scene::FileAccess::open(), &[])
                .unwrap_or_else(|e| panic!("{e}"));
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.ends_with(&fresh.toml),
            "{name} is stale: run tools/scenes/convert-mitsuba.sh"
        );
        // Its header names where the scene comes from.
        assert!(
            text.starts_with("# ") && text.contains("../shared/data/mitsuba"),
            "{name}"
        );
        rt_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    }
    assert!(seen >= 1, "no shipped conversion in {}", shipped.display());
}
