//! `[[instance]]` and `[[animation]]` from TOML: placement, the world copies over time, and one
//! clear error line for every bad input.

use rt_core::glam::Vec3;
use rt_scene::load_str;
use std::path::Path;

const BASE: &str = r#"
[[camera]]
name = "cam"
position = [0, 0, 5]
look_at = [0, 0, 0]

[[material]]
name = "white"

[[geometry]]
name = "floor"
shape = "quad"
vertices = [[-5, -1, 5], [5, -1, 5], [5, -1, -5], [-5, -1, -5]]
material = "white"

[[geometry]]
name = "tri"
positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
indices = [[0, 1, 2]]
normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1]]
material = "white"
transform = { translate = [0, 0, 1] }
"#;

fn load(extra: &str) -> rt_core::Scene {
    load_str(
        &format!("{BASE}{extra}"),
        Path::new("."),
        Path::new("t.toml"),
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .scene
}

fn error(extra: &str) -> String {
    let e = load_str(
        &format!("{BASE}{extra}"),
        Path::new("."),
        Path::new("t.toml"),
    )
    .expect_err("loads, but should not");
    let s = e.to_string();
    assert!(s.starts_with("t.toml:"), "names the file: {s}");
    assert_eq!(s.lines().count(), 1, "one line: {s}");
    s
}

#[test]
fn instances_place_the_geometry_and_it_is_not_rendered_itself() {
    let s = load(
        r#"
[[instance]]
name = "a"
geometry = "tri"

[[instance]]
name = "b"
geometry = "tri"
transform = { translate = [3, 0, 0], scale = [1, 2, 1] }
"#,
    );
    // The floor (2 triangles) stays static; "tri" is a prototype placed twice.
    assert_eq!(s.triangles.len(), 4);
    assert_eq!(s.prototypes.len(), 1);
    assert_eq!(s.instances.len(), 2);
    let names: Vec<_> = s.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["floor", "a", "b"]);
    // The prototype carries the geometry's own transform; b's is applied after it.
    let b = &s.triangles[s.instances[1].first as usize];
    assert_eq!(b[0], Vec3::new(3.0, 0.0, 1.0));
    assert_eq!(b[2], Vec3::new(3.0, 2.0, 1.0));
    assert_eq!(s.instance_of(0), None);
    assert_eq!(s.instance_of(2), Some(0));
    assert_eq!(s.instance_of(3), Some(1));
    // Normals follow (inverse transpose, unit).
    let n = s.normals_of(3).unwrap();
    assert!((n[0] - Vec3::Z).length() < 1e-6);
}

#[test]
fn a_mirroring_instance_keeps_its_front_face() {
    let s = load(
        r#"
[[instance]]
name = "m"
geometry = "tri"
transform = { scale = [-1, 1, 1] }
"#,
    );
    let v = s.triangles[2];
    let ng = (v[1] - v[0]).cross(v[2] - v[0]);
    assert!(ng.z > 0.0, "front face still towards +z: {ng}");
}

#[test]
fn animations_move_geometries_instances_and_cameras() {
    let mut s = load(
        r#"
[[instance]]
name = "a"
geometry = "tri"

[[animation]]
target = "a"
keys = [ { time = 0.0 }, { time = 2.0, translate = [0, 0, -4], rotate = [0, 90, 0] } ]

[[animation]]
target = "floor"
keys = [ { time = 1.0, translate = [0, 0, 0] }, { time = 3.0, translate = [0, 2, 0] } ]

[[animation]]
target = "cam"
keys = [ { time = 0.0 }, { time = 1.0, position = [0, 0, 9] } ]
"#,
    );
    // An animated geometry becomes an instance of its own name.
    assert_eq!(s.instances.len(), 2);
    assert_eq!(s.instances[1].name, "floor");
    let at = |s: &rt_core::Scene, k: usize| s.triangles[s.instances[k].first as usize][0];
    assert_eq!(at(&s, 0), Vec3::new(0.0, 0.0, 1.0));
    let floor0 = at(&s, 1);
    let moved = s.set_time(2.0);
    assert_eq!(moved, [0, 1]);
    // At t = 2 the instance's key: rotate 90° about y ((0,0,1) -> (1,0,0)), then translate.
    assert!(
        (at(&s, 0) - Vec3::new(1.0, 0.0, -4.0)).length() < 1e-5,
        "{}",
        at(&s, 0)
    );
    // The floor halfway through its keys (t = 2 of 1..3).
    assert!((at(&s, 1) - (floor0 + Vec3::Y)).length() < 1e-6);
    assert_eq!(s.cameras[0].position, Vec3::new(0.0, 0.0, 9.0));
    // Past the last key the end keys hold; nothing moves between t = 3 and t = 9.
    s.set_time(3.0);
    assert!(s.set_time(9.0).is_empty());
    // Back to 0: the same bits as at load.
    s.set_time(0.0);
    assert_eq!(at(&s, 0), Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(at(&s, 1), floor0);
}

#[test]
fn bad_instances_and_animations_are_one_clear_line() {
    let cases = [
        (
            "[[instance]]\nname = \"a\"\ngeometry = \"nope\"\n",
            "geometry \"nope\" placed by instance \"a\" is not defined",
        ),
        (
            "[[instance]]\nname = \"floor\"\ngeometry = \"tri\"\n",
            "has the name of a geometry or camera",
        ),
        (
            "[[instance]]\nname = \"a\"\ngeometry = \"tri\"\n[[instance]]\nname = \"a\"\ngeometry = \"tri\"\n",
            "instance \"a\" is defined twice",
        ),
        (
            "[[animation]]\ntarget = \"ghost\"\nkeys = [ { time = 0.0 } ]\n",
            "animation target \"ghost\" is not a geometry, instance, camera or material",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 1.0 }, { time = 0.5 } ]\n",
            "not after the key before it",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = nan } ]\n",
            "not finite",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0, translate = [nan, 0, 0] } ]\n",
            "not finite",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = []\n",
            "at least one key",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0, scale = 0 } ]\n",
            "scale that is not positive",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0, fov = 30 } ]\n",
            "are camera keys",
        ),
        (
            "[[animation]]\ntarget = \"cam\"\nkeys = [ { time = 0.0, translate = [1, 0, 0] } ]\n",
            "are geometry keys",
        ),
        (
            "[[animation]]\ntarget = \"cam\"\nkeys = [ { time = 0.0, look_at = [0, 0, 5] } ]\n",
            "position and look_at are the same point",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0 } ]\n[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0 } ]\n",
            "animated twice",
        ),
        (
            "[[instance]]\nname = \"a\"\ngeometry = \"tri\"\n[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0 } ]\n",
            "animate its instances instead",
        ),
        (
            "[[instance]]\nname = \"a\"\ngeometry = \"tri\"\ntransform = { scale = [1e30, 1e30, 1e30] }\n[[animation]]\ntarget = \"a\"\nkeys = [ { time = 0.0, scale = 1e30 } ]\n",
            "not finite after the transform",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0, spin = 1 } ]\n",
            "spin",
        ),
    ];
    for (extra, want) in cases {
        let e = error(extra);
        assert!(e.contains(want), "{extra}\n  gave: {e}\n  want: {want}");
    }
}

/// A lamp material for the material-animation tests, on a quad of its own.
const LAMP: &str = r#"
[[material]]
name = "lamp"
emission = [4, 4, 4]

[[geometry]]
name = "panel"
shape = "quad"
vertices = [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]]
material = "lamp"
"#;

#[test]
fn a_material_animation_keys_the_emission_and_resets_the_lights() {
    let mut s = load(&format!(
        r#"{LAMP}
[[animation]]
target = "lamp"
interpolate = "step"
keys = [ {{ time = 0.0, emission = [4, 4, 4] }}, {{ time = 1.0, emission = [0, 0, 0] }}, {{ time = 2.0, emission = [1, 2, 3] }} ]
"#
    ));
    let lamp = s.materials.iter().position(|m| m.name == "lamp").unwrap();
    assert_eq!(s.material_motions.len(), 1);
    assert_eq!(s.material_motions[0].material, lamp);
    assert_eq!(s.lights().emitter_count(), 2);
    s.set_time(0.999);
    assert_eq!(s.materials[lamp].emission, Vec3::splat(4.0), "a step holds");
    s.set_time(1.0);
    assert_eq!(s.materials[lamp].emission, Vec3::ZERO);
    // Switched off: the table is rebuilt without the lamp, and is empty (black environment).
    assert_eq!(s.lights().emitter_count(), 0);
    assert!(s.lights().is_empty());
    s.set_time(5.0);
    assert_eq!(s.materials[lamp].emission, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.lights().emitter_count(), 2);
}

#[test]
fn a_lamp_off_at_time_zero_is_still_a_light_source() {
    let loaded = load_str(
        &format!(
            r#"{BASE}{LAMP}
[[animation]]
target = "lamp"
interpolate = "step"
keys = [ {{ time = 0.0, emission = [0, 0, 0] }}, {{ time = 1.0, emission = [3, 3, 3] }} ]
"#
        ),
        Path::new("."),
        Path::new("t.toml"),
    )
    .unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(
        loaded
            .scene
            .materials
            .iter()
            .find(|m| m.name == "lamp")
            .unwrap()
            .emission,
        Vec3::ZERO
    );
}

#[test]
fn bad_material_animations_are_one_clear_line() {
    let anim = |keys: &str, extra: &str| {
        format!("{LAMP}\n[[animation]]\ntarget = \"lamp\"\n{extra}keys = [ {keys} ]\n")
    };
    let cases = [
        (
            anim("{ time = 0.0, emission = [1, -1, 1] }", ""),
            "animation of \"lamp\": key 0 has emission [1.0, -1.0, 1.0]",
        ),
        (
            anim("{ time = 0.0, emission = [1, 1, 1] }, { time = 1.0, emission = [inf, 0, 0] }", ""),
            "animation of \"lamp\": key 1 has a value that is not finite (emission)",
        ),
        (
            anim("{ time = 0.0, emission = [nan, 0, 0] }", ""),
            "not finite (emission)",
        ),
        (
            anim("{ time = 0.0, emission = [1, 1, 1], translate = [0, 1, 0] }", ""),
            "animation of material \"lamp\": `translate` is not a material key",
        ),
        (
            anim("{ time = 0.0, emission = [1, 1, 1] }, { time = 1.0, fov = 30 }", ""),
            "`fov` is not a material key",
        ),
        (
            anim("{ time = 0.0, emission = [1, 1, 1] }, { time = 1.0 }", ""),
            "a key at time 1 has no emission",
        ),
        (
            anim("{ time = 0.0, emission = [1, 1, 1] }", "interpolate = \"cubic\"\n"),
            "interpolate = \"cubic\" is not \"linear\" or \"step\"",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\ninterpolate = \"step\"\nkeys = [ { time = 0.0 } ]\n".to_string(),
            "applies to material (emission) animations only",
        ),
        (
            "[[animation]]\ntarget = \"tri\"\nkeys = [ { time = 0.0, emission = [1, 1, 1] } ]\n".to_string(),
            "animation target \"tri\" has emission keys but is not a [[material]]",
        ),
        (
            "[[animation]]\ntarget = \"cam\"\nkeys = [ { time = 0.0, emission = [1, 1, 1] } ]\n".to_string(),
            "is not a [[material]]",
        ),
        (
            format!("{}[[animation]]\ntarget = \"lamp\"\nkeys = [ {{ time = 0.0, emission = [1, 1, 1] }} ]\n", anim("{ time = 0.0, emission = [1, 1, 1] }", "")),
            "\"lamp\" is animated twice",
        ),
    ];
    for (extra, want) in cases {
        let e = error(&extra);
        assert!(e.contains(want), "{extra}\n  gave: {e}\n  want: {want}");
    }
}
