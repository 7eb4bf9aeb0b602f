//! Mesh loaders end to end, through scene files: glTF (a small document built here, with an
//! embedded base64 buffer), OBJ with an .mtl, and .ra2 round trips.

mod common;

use common::{base64, load_in, tris};
use glam::{Vec2, Vec3};
use rt_core::{Material, Rgb};
use serde_json::{json, Value};

/// Builds a glTF document with one buffer (embedded as a base64 data URI).
#[derive(Default)]
struct Gltf {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Gltf {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn accessor(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let n = match ty {
            "VEC3" => 3,
            "VEC2" => 2,
            _ => 1,
        };
        let mut a =
            json!({ "bufferView": view, "componentType": 5126, "count": v.len() / n, "type": ty });
        if ty == "VEC3" {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in v.chunks(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessor(a)
    }

    /// Indices with component type 5121 (u8), 5123 (u16) or 5125 (u32).
    fn indices(&mut self, ix: &[u32], component: u32) -> usize {
        let bytes: Vec<u8> = match component {
            5121 => ix.iter().map(|&i| i as u8).collect(),
            5123 => ix.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
            _ => ix.iter().flat_map(|&i| i.to_le_bytes()).collect(),
        };
        let view = self.view(&bytes);
        self.accessor(json!({ "bufferView": view, "componentType": component, "count": ix.len(), "type": "SCALAR" }))
    }

    fn document(&self, rest: Value) -> String {
        let mut doc = json!({
            "asset": { "version": "2.0" },
            "buffers": [{ "byteLength": self.bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin)) }],
            "bufferViews": self.views,
            "accessors": self.accessors,
        });
        for (k, v) in rest.as_object().unwrap() {
            doc[k] = v.clone();
        }
        serde_json::to_string_pretty(&doc).unwrap()
    }
}

/// A unit right triangle in the xy plane (front +z) with normals and uvs.
const TRI: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

fn png_bytes() -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 0, 0]))
        .write_to(&mut out, image::ImageFormat::Png)
        .unwrap();
    out.into_inner()
}

/// A document exercising the loader: a node hierarchy with TRS and matrix transforms, a
/// mirrored instance, u8/u16/u32/no indices, a strip, a point primitive, four materials
/// (metal, glass, emissive, textured plastic) and a sparse accessor.
fn test_document() -> String {
    let mut g = Gltf::default();
    let pos = g.floats(&TRI, "VEC3");
    let nrm = g.floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC3");
    let uv = g.floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 0.25], "VEC2");
    let i16 = g.indices(&[0, 1, 2], 5123);
    let i8 = g.indices(&[0, 1, 2], 5121);
    let i32 = g.indices(&[0, 1, 2], 5125);
    // A strip of 4 vertices: a unit square in the xy plane, front +z.
    let strip = g.floats(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0],
        "VEC3",
    );
    // Sparse: vertex 1 of TRI moved to (5, 0, 0).
    let sp_idx = g.view(&[1u8]);
    let sp_val = g.view(
        &[5.0f32, 0.0, 0.0]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect::<Vec<u8>>(),
    );
    let sparse = g.accessor(json!({
        "bufferView": g.accessors[pos]["bufferView"], "componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0.0, 0.0, 0.0], "max": [5.0, 1.0, 0.0],
        "sparse": { "count": 1, "indices": { "bufferView": sp_idx, "componentType": 5121 }, "values": { "bufferView": sp_val } }
    }));
    let png = png_bytes();
    let img_view = g.view(&png);
    g.document(json!({
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{ "nodes": [0, 3, 4] }],
        "nodes": [
            { "translation": [0.0, 0.0, -2.0], "children": [1, 2] },
            // 90° about +y, scale 2: (1,0,0) -> (0,0,-2), then the parent moves it to z = -4.
            { "rotation": [0.0, std::f32::consts::FRAC_1_SQRT_2, 0.0, std::f32::consts::FRAC_1_SQRT_2], "scale": [2.0, 2.0, 2.0], "mesh": 0 },
            { "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1], "mesh": 1 },
            { "scale": [-1.0, 1.0, 1.0], "mesh": 2 },
            { "mesh": 3 },
        ],
        "meshes": [
            { "name": "indexed", "primitives": [
                { "attributes": { "POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv }, "indices": i16, "material": 0 },
                { "attributes": { "POSITION": pos }, "indices": i8, "material": 1 },
                { "attributes": { "POSITION": pos }, "indices": i32, "material": 2 },
                { "attributes": { "POSITION": pos }, "material": 3 },
            ]},
            { "name": "strip", "primitives": [
                { "attributes": { "POSITION": strip }, "mode": 5, "material": 0 },
                { "attributes": { "POSITION": pos }, "mode": 0, "material": 0 },
            ]},
            { "name": "mirrored", "primitives": [
                { "attributes": { "POSITION": pos, "NORMAL": nrm }, "material": 0 },
            ]},
            { "name": "sparse", "primitives": [
                { "attributes": { "POSITION": sparse }, "material": 0 },
            ]},
        ],
        "materials": [
            { "name": "steel", "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.6, 0.7, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.2 } },
            { "name": "glass", "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.0 },
              "extensions": { "KHR_materials_transmission": { "transmissionFactor": 1.0 }, "KHR_materials_ior": { "ior": 1.33 } } },
            { "pbrMetallicRoughness": { "metallicFactor": 0.0, "roughnessFactor": 1.0 }, "emissiveFactor": [1.0, 0.5, 0.25],
              "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } }, "doubleSided": true },
            { "name": "painted", "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.3, "roughnessFactor": 0.5,
              "baseColorTexture": { "index": 0 } } },
        ],
        "textures": [{ "source": 0 }],
        "images": [{ "bufferView": img_view, "mimeType": "image/png" }],
    }))
}

#[test]
fn gltf_hierarchy_indices_modes_and_sparse_accessors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.gltf"), test_document()).unwrap();
    let s = load_in(
        dir.path(),
        "[[geometry]]\nname = \"t\"\nfile = \"t.gltf\"\n",
    )
    .unwrap();
    let t = tris(&s, "t");
    // 4 indexed triangles + 2 strip triangles (the point primitive is skipped) + 1 mirrored
    // + 1 sparse.
    assert_eq!(t.len(), 8, "{t:?}");
    let near = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
    // Node 1: scale 2, rotate 90° about y, then the parent's translation.
    assert!(near(t[0][0], Vec3::new(0.0, 0.0, -2.0)), "{:?}", t[0]);
    assert!(near(t[0][1], Vec3::new(0.0, 0.0, -4.0)), "{:?}", t[0]);
    assert!(near(t[0][2], Vec3::new(0.0, 2.0, -2.0)), "{:?}", t[0]);
    for k in 1..4 {
        assert_eq!(
            t[k], t[0],
            "u8, u32 and missing indices give the same triangle"
        );
    }
    // Normals follow the rotation: +z becomes +x. uvs are flipped to v-up.
    let n0 = s.scene.normals[2].unwrap();
    assert!(near(n0[0], Vec3::X), "{n0:?}");
    assert_eq!(
        s.scene.uvs[2].unwrap(),
        [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 0.75)
        ]
    );
    // The strip under the matrix node (translation x + 10): both triangles face +z.
    for tri in &t[4..6] {
        assert!(tri.iter().all(|p| p.x >= 10.0 - 1e-6), "{tri:?}");
        let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        assert!(n.z > 0.0, "strip winding: {tri:?}");
    }
    // The mirrored instance keeps facing +z.
    let m = t[6];
    assert!((m[1] - m[0]).cross(m[2] - m[0]).z > 0.0, "{m:?}");
    assert!(m.iter().all(|p| p.x <= 0.0));
    // The sparse accessor moved vertex 1.
    assert!(near(t[7][1], Vec3::new(5.0, 0.0, 0.0)), "{:?}", t[7]);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("skipped 1 point or line primitives")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn gltf_materials_map_onto_ggx() {
    use rt_core::microfacet::{Microfacet, RoughConductor, RoughPlastic};
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.gltf"), test_document()).unwrap();
    let s = load_in(
        dir.path(),
        "[[geometry]]\nname = \"t\"\nfile = \"t.gltf\"\n",
    )
    .unwrap();
    let by_name = |n: &str| {
        s.scene
            .materials
            .iter()
            .find(|m| m.name == n)
            .unwrap_or_else(|| {
                panic!(
                    "no material {n}: {:?}",
                    s.scene
                        .materials
                        .iter()
                        .map(|m| &m.name)
                        .collect::<Vec<_>>()
                )
            })
    };
    // GGX with α = roughness², the metal reflecting everything tinted by the base colour.
    let conductor = |m: &Microfacet| -> RoughConductor {
        match m {
            Microfacet::Conductor(c) => *c,
            other => panic!("{other:?}"),
        }
    };
    let plastic = |m: &Microfacet| -> RoughPlastic {
        match m {
            Microfacet::RoughPlastic(p) => *p,
            other => panic!("{other:?}"),
        }
    };
    let ggx = |d: Option<rt_core::microfacet::Distribution>, alpha: f32| {
        let d = d.expect("rough");
        assert_eq!(d.kind, rt_core::microfacet::DistributionKind::Ggx);
        assert!(
            (d.alpha_x - alpha).abs() < 1e-6 && d.alpha_x == d.alpha_y,
            "{d:?}"
        );
    };
    let steel = by_name("t/steel");
    let c = conductor(
        steel
            .microfacet
            .as_ref()
            .expect("metallic 1: the conductor alone"),
    );
    ggx(c.distribution, 0.04);
    assert_eq!((c.eta, c.k), (Rgb::ZERO, Rgb::ONE), "F = 1");
    assert_eq!(c.specular_reflectance, Rgb::new(0.5, 0.6, 0.7));
    assert!(c.two_sided && steel.blend.is_none() && steel.layers.is_empty());
    assert_eq!(
        by_name("t/glass"),
        &Material::glass("t/glass", Rgb::ONE, 1.33, 1.0)
    );
    let lamp = by_name("t/material2");
    assert_eq!(lamp.emission, Rgb::new(4.0, 2.0, 1.0));
    assert!(lamp.two_sided);
    let p = plastic(
        lamp.microfacet
            .as_ref()
            .expect("metallic 0: the plastic alone"),
    );
    ggx(Some(p.distribution), 1.0);
    assert_eq!((p.diffuse, p.specular, p.eta), (Rgb::ONE, Rgb::ONE, 1.5));
    // Metallic 0.3: a blend of weight 0.3 of the plastic and the metal, both textured.
    let painted = by_name("t/painted");
    let b = painted.blend.as_ref().expect("a blend");
    assert_eq!(b.weight, 0.3);
    let (p, c) = (plastic(&b.parts[0].bsdf), conductor(&b.parts[1].bsdf));
    ggx(Some(p.distribution), 0.25);
    ggx(c.distribution, 0.25);
    assert_eq!((p.diffuse, p.eta), (Rgb::splat(0.8), 1.5));
    assert_eq!(c.specular_reflectance, Rgb::splat(0.8));
    assert_eq!(b.parts[0].texture, b.parts[1].texture);
    let tex = b.parts[0].texture.unwrap() as usize;
    assert_eq!(s.scene.textures[tex].texels[0], Rgb::new(1.0, 0.0, 0.0));
    // The texture multiplies the metal's colour as the plastic's base.
    let tint = s.scene.tint(painted, rt_core::glam::Vec2::splat(0.5));
    let wo = rt_core::glam::Vec3::new(0.3, 0.0, 0.9).normalize();
    let bsdf = rt_core::material::Bsdf::new(
        painted,
        tint,
        rt_core::glam::Vec3::Z,
        rt_core::glam::Vec3::Z,
        wo,
    );
    let a = bsdf.albedo();
    assert!(a.y == 0.0 && a.z == 0.0 && a.x > 0.0, "red texture: {a:?}");
    // Triangle materials in order: steel, glass, emissive, painted, steel...
    let names: Vec<&str> = s.scene.material_ids[2..7]
        .iter()
        .map(|&i| s.scene.materials[i as usize].name.as_str())
        .collect();
    assert_eq!(
        names,
        ["t/steel", "t/glass", "t/material2", "t/painted", "t/steel"]
    );
    assert!(s.scene.lights().emitter_count() >= 3);
    for m in &s.scene.materials {
        assert_eq!(m.validate(), Ok(()), "{}", m.name);
    }
}

#[test]
fn gltf_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let geometry = |f: &str| format!("[[geometry]]\nname = \"t\"\nfile = \"{f}\"\n");
    std::fs::write(dir.path().join("bad.gltf"), "{ not json").unwrap();
    let e = load_in(dir.path(), &geometry("bad.gltf")).unwrap_err();
    assert!(e.contains("bad.gltf: malformed glTF"), "{e}");

    // Index out of range.
    let mut g = Gltf::default();
    let pos = g.floats(&TRI, "VEC3");
    let ix = g.indices(&[0, 1, 7], 5123);
    let doc = g.document(json!({
        "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos }, "indices": ix }] }],
    }));
    std::fs::write(dir.path().join("range.gltf"), &doc).unwrap();
    let e = load_in(
        dir.path(),
        &format!("{}material = \"white\"\n", geometry("range.gltf")),
    )
    .unwrap_err();
    assert!(e.contains("range.gltf: mesh 0 (\"\") primitive 0: index 7 is out of range (the primitive has 3 vertices)"), "{e}");

    // No material in the file and none in the scene.
    let mut g = Gltf::default();
    let pos = g.floats(&TRI, "VEC3");
    let ok_doc = g.document(json!({
        "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos } }] }],
    }));
    std::fs::write(dir.path().join("plain.gltf"), &ok_doc).unwrap();
    let e = load_in(dir.path(), &geometry("plain.gltf")).unwrap_err();
    assert!(e.contains("geometry \"t\" has no material"), "{e}");
    let s = load_in(
        dir.path(),
        &format!("{}material = \"white\"\n", geometry("plain.gltf")),
    )
    .unwrap();
    assert_eq!(tris(&s, "t").len(), 1);

    // An external buffer that is missing.
    let ext = ok_doc.replace(
        &format!("data:application/octet-stream;base64,{}", base64(&g.bin)),
        "gone.bin",
    );
    std::fs::write(dir.path().join("ext.gltf"), ext).unwrap();
    let e = load_in(
        dir.path(),
        &format!("{}material = \"white\"\n", geometry("ext.gltf")),
    )
    .unwrap_err();
    assert!(e.contains("ext.gltf: cannot load buffer data"), "{e}");
}

#[test]
fn obj_with_mtl_through_a_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("m")).unwrap();
    std::fs::write(dir.path().join("m/a.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(
        dir.path().join("m/a.obj"),
        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\nusemtl red\nf 1 2 3 4\nf 1 2 3 4 5\n",
    )
    .unwrap();
    let s = load_in(
        dir.path(),
        "[[geometry]]\nname = \"a\"\nfile = \"m/a.obj\"\ntransform = { translate = [0, 0, 1] }\n",
    )
    .unwrap();
    let t = tris(&s, "a");
    assert_eq!(t.len(), 5, "a quad and a pentagon, fan-triangulated");
    assert_eq!(
        t[4],
        [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(-1.0, 0.5, 1.0)
        ]
    );
    assert_eq!(
        s.scene.materials.last().unwrap(),
        &Material::diffuse("a/red", Rgb::X)
    );
    std::fs::write(
        dir.path().join("m/b.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 12\n",
    )
    .unwrap();
    let e = load_in(
        dir.path(),
        "[[geometry]]\nname = \"b\"\nfile = \"m/b.obj\"\nmaterial = \"white\"\n",
    )
    .unwrap_err();
    assert!(
        e.ends_with("m/b.obj: line 5: face 2 references vertex 12 but the file has 3 vertices"),
        "{e}"
    );
    std::fs::write(dir.path().join("m/e.obj"), "# nothing\nv 0 0 0\n").unwrap();
    let e = load_in(
        dir.path(),
        "[[geometry]]\nname = \"e\"\nfile = \"m/e.obj\"\nmaterial = \"white\"\n",
    )
    .unwrap_err();
    assert!(e.ends_with("m/e.obj: the mesh has no triangles"), "{e}");
    std::fs::write(
        dir.path().join("m/d.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    )
    .unwrap();
    // A file of zero-area triangles is invisible, as in Mitsuba: loaded, with a warning.
    let s = load_in(
        dir.path(),
        "[[geometry]]\nname = \"d\"\nfile = \"m/d.obj\"\nmaterial = \"white\"\n",
    )
    .unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w
                == "geometry \"d\": 1 of 1 triangles have zero area (kept; they are never hit)"),
        "{:?}",
        s.warnings
    );
    std::fs::write(
        dir.path().join("m/n.obj"),
        "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let e = load_in(
        dir.path(),
        "[[geometry]]\nname = \"n\"\nfile = \"m/n.obj\"\nmaterial = \"white\"\n",
    )
    .unwrap_err();
    assert!(
        e.contains("m/n.obj: triangle 0 has a non-finite vertex coordinate"),
        "{e}"
    );
}

#[test]
fn ra2_round_trip_through_a_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = rt_scene::raw::RawMesh {
        triangles: vec![
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [
                Vec3::new(0.5, 0.5, 0.5),
                Vec3::new(1.5, 0.5, 0.5),
                Vec3::new(0.5, 1.5, 0.25),
            ],
        ],
        normals: Some(vec![[Vec3::Z; 3], [Vec3::Y; 3]]),
        uvs: Some(vec![[Vec2::ZERO, Vec2::X, Vec2::Y], [Vec2::ONE; 3]]),
    };
    rt_scene::raw::write(&dir.path().join("m.ra2"), &mesh).unwrap();
    let s = load_in(
        dir.path(),
        "[[geometry]]\nname = \"r\"\nfile = \"m.ra2\"\nmaterial = \"white\"\n",
    )
    .unwrap();
    assert_eq!(tris(&s, "r"), mesh.triangles);
    assert_eq!(
        s.scene.normals[2..],
        [Some([Vec3::Z; 3]), Some([Vec3::Y; 3])]
    );
    assert_eq!(s.scene.uvs[3], Some([Vec2::ONE; 3]));
    let e = load_in(dir.path(), "[[geometry]]\nname = \"r\"\nfile = \"m.ra2\"\n").unwrap_err();
    assert!(e.contains("geometry \"r\" has no material"), "{e}");
    std::fs::write(dir.path().join("bad.ra2"), [0u8; 40]).unwrap();
    let e = load_in(
        dir.path(),
        "[[geometry]]\nname = \"r\"\nfile = \"bad.ra2\"\nmaterial = \"white\"\n",
    )
    .unwrap_err();
    assert!(
        e.contains("bad.ra2: file size 40 bytes is not a multiple of 36"),
        "{e}"
    );
}
