//! Writes the small assets that the shipped scenes load, all made by the project itself:
//!
//! - `textures/checker.png`: a 64×64 two-tone checkerboard (8×8 squares) for `showcase.toml`;
//! - `meshes/tetra-ico.obj` + `meshes/tetra-ico.mtl`: a tetrahedron (flat, metal), an
//!   icosahedron with smooth vertex normals (plastic) and a square plate written as one quad
//!   face (matte), for `meshes.toml`;
//! - `meshes/prism.gltf`: a triangular prism with two materials (plastic sides, metal caps),
//!   its buffer embedded as base64, placed by a two-node hierarchy (translation on the parent,
//!   rotation and scale on the child), for `meshes.toml`.
//!
//! ```text
//! cargo run -p rt-scene --example make_assets -- scenes
//! ```

use glam::{Quat, Vec3};
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

fn main() {
    let root = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes".to_string());
    let root = Path::new(&root);
    std::fs::create_dir_all(root.join("textures")).unwrap();
    std::fs::create_dir_all(root.join("meshes")).unwrap();
    checker(&root.join("textures/checker.png"));
    tetra_ico(&root.join("meshes"));
    prism(&root.join("meshes/prism.gltf"));
}

fn checker(path: &Path) {
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        if (x / 8 + y / 8) % 2 == 0 {
            image::Rgb([230, 225, 210])
        } else {
            image::Rgb([40, 70, 120])
        }
    });
    img.save(path).unwrap();
    println!("wrote {}", path.display());
}

/// Orders a face's vertices so that its normal points away from `center`.
fn outward<const N: usize>(mut f: [usize; N], p: &[Vec3], center: Vec3) -> [usize; N] {
    let n = (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]);
    let c = f.iter().map(|&i| p[i]).sum::<Vec3>() / N as f32;
    if n.dot(c - center) < 0.0 {
        f.reverse();
    }
    f
}

fn tetra_ico(dir: &Path) {
    let mut obj = String::from(
        "# tetra-ico.obj: written by crates/scene/examples/make_assets.rs.\n\
         # A tetrahedron (flat), an icosahedron with smooth vertex normals and a square plate\n\
         # (one quad face), each with its own material from tetra-ico.mtl. Units: metres, +y up.\n\
         mtllib tetra-ico.mtl\n",
    );
    let mut base = 1; // OBJ indices are 1-based and global.

    // Tetrahedron 1 mm above the plate (y = 0.05), so that no face is coplanar with it.
    let c = Vec3::new(-0.8, 0.051, 0.0);
    let s = 0.55;
    let tp: Vec<Vec3> = [
        Vec3::new(0.0, 0.0, -0.6),
        Vec3::new(-0.52, 0.0, 0.3),
        Vec3::new(0.52, 0.0, 0.3),
        Vec3::new(0.0, 0.85, 0.0),
    ]
    .iter()
    .map(|&v| c + v * s / 0.6)
    .collect();
    let tc = tp.iter().sum::<Vec3>() / 4.0;
    obj.push_str("o tetrahedron\n");
    for p in &tp {
        writeln!(obj, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z).unwrap();
    }
    obj.push_str("usemtl copper\n");
    for f in [[0, 1, 2], [0, 1, 3], [1, 2, 3], [2, 0, 3]] {
        let f = outward(f, &tp, tc);
        writeln!(obj, "f {} {} {}", f[0] + base, f[1] + base, f[2] + base).unwrap();
    }
    base += tp.len();

    // Icosahedron of radius 0.45, smooth normals, its lowest vertex (0.45·0.8507 below the
    // centre) 1 mm above the plate.
    let ico = rt_core::shapes::icosphere(0);
    let unit = ico.positions;
    let ic = Vec3::new(0.7, 0.05 + 0.45 * 0.850_651 + 0.001, 0.0);
    let ip: Vec<Vec3> = unit.iter().map(|&u| ic + u * 0.45).collect();
    obj.push_str("o icosahedron\n");
    for p in &ip {
        writeln!(obj, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z).unwrap();
    }
    for n in &unit {
        writeln!(obj, "vn {:.6} {:.6} {:.6}", n.x, n.y, n.z).unwrap();
    }
    obj.push_str("usemtl jade\n");
    let faces = ico.faces;
    for f in faces {
        let f = outward(f.map(|i| i as usize), &ip, ic);
        // Vertex i uses normal i: position and normal indices coincide (normals are numbered
        // from 1 in this file).
        let v = |k: usize| format!("{}//{}", f[k] + base, f[k] + 1);
        writeln!(obj, "f {} {} {}", v(0), v(1), v(2)).unwrap();
    }
    base += ip.len();

    // A 2.4 × 1.4 plate at y = 0.05, one quad, counter-clockwise seen from above.
    obj.push_str("o plate\n");
    for (x, z) in [(-1.2, -0.7), (-1.2, 0.7), (1.2, 0.7), (1.2, -0.7)] {
        writeln!(obj, "v {x:.6} 0.050000 {z:.6}").unwrap();
    }
    obj.push_str("usemtl slate\n");
    writeln!(obj, "f {} {} {} {}", base, base + 1, base + 2, base + 3).unwrap();

    let mtl = "# tetra-ico.mtl: written by crates/scene/examples/make_assets.rs.\n\
               # copper: illum 3 -> metal (hardness from Ns); jade: Ks > 0 -> plastic;\n\
               # slate: illum 1 -> diffuse. See docs/scene-format.md for the mapping.\n\
               newmtl copper\nKd 0.95 0.64 0.54\nNs 900\nillum 3\n\n\
               newmtl jade\nKd 0.2 0.6 0.4\nKs 0.5 0.5 0.5\nNs 600\nNi 1.5\nillum 2\n\n\
               newmtl slate\nKd 0.3 0.3 0.33\nillum 1\n";
    std::fs::write(dir.join("tetra-ico.obj"), obj).unwrap();
    std::fs::write(dir.join("tetra-ico.mtl"), mtl).unwrap();
    println!("wrote {}/tetra-ico.obj and .mtl", dir.display());
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for i in 0..4 {
            if i <= c.len() {
                out.push(A[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn prism(path: &Path) {
    // Cross-section in the xy plane, extruded along z.
    let tri = [
        Vec3::new(-0.5, 0.0, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.8, 0.0),
    ];
    let (z0, z1) = (-0.35, 0.35);
    let center = Vec3::new(0.0, 0.8 / 3.0, 0.0);
    let mut pos: Vec<Vec3> = Vec::new();
    let mut nrm: Vec<Vec3> = Vec::new();
    let mut sides: Vec<u16> = Vec::new();
    let mut caps: Vec<u16> = Vec::new();
    // Flat shading: every face has its own vertices and normal.
    let face = |quad: &[Vec3], out: &mut Vec<u16>, pos: &mut Vec<Vec3>, nrm: &mut Vec<Vec3>| {
        let idx: Vec<usize> = (0..quad.len()).collect();
        let ordered: Vec<usize> = if quad.len() == 3 {
            outward([idx[0], idx[1], idx[2]], quad, center).to_vec()
        } else {
            outward([idx[0], idx[1], idx[2], idx[3]], quad, center).to_vec()
        };
        let p: Vec<Vec3> = ordered.iter().map(|&i| quad[i]).collect();
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let b = pos.len() as u16;
        pos.extend(&p);
        nrm.extend(std::iter::repeat_n(n, p.len()));
        out.extend([b, b + 1, b + 2]);
        if p.len() == 4 {
            out.extend([b, b + 2, b + 3]);
        }
    };
    for z in [z0, z1] {
        let cap: Vec<Vec3> = tri.iter().map(|v| Vec3::new(v.x, v.y, z)).collect();
        face(&cap, &mut caps, &mut pos, &mut nrm);
    }
    for i in 0..3 {
        let (a, b) = (tri[i], tri[(i + 1) % 3]);
        let quad = [
            Vec3::new(a.x, a.y, z0),
            Vec3::new(b.x, b.y, z0),
            Vec3::new(b.x, b.y, z1),
            Vec3::new(a.x, a.y, z1),
        ];
        face(&quad, &mut sides, &mut pos, &mut nrm);
    }
    // Buffer: positions, normals, side indices, cap indices (each view 4-byte aligned).
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut push = |bytes: Vec<u8>, bin: &mut Vec<u8>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() }));
        bin.extend(bytes);
    };
    let f32s = |v: &[Vec3]| -> Vec<u8> {
        v.iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect()
    };
    push(f32s(&pos), &mut bin);
    push(f32s(&nrm), &mut bin);
    push(
        sides.iter().flat_map(|i| i.to_le_bytes()).collect(),
        &mut bin,
    );
    push(
        caps.iter().flat_map(|i| i.to_le_bytes()).collect(),
        &mut bin,
    );
    let (lo, hi) = pos
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let rot = Quat::from_rotation_y(30f32.to_radians());
    let doc = json!({
        "asset": { "version": "2.0", "generator": "rt-scene examples/make_assets.rs" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [
            { "name": "prism-root", "translation": [0.0, 0.05, -0.9], "children": [1] },
            { "name": "prism", "rotation": rot.to_array(), "scale": [1.2, 1.2, 1.2], "mesh": 0 },
        ],
        "meshes": [{ "name": "prism", "primitives": [
            { "attributes": { "POSITION": 0, "NORMAL": 1 }, "indices": 2, "material": 0 },
            { "attributes": { "POSITION": 0, "NORMAL": 1 }, "indices": 3, "material": 1 },
        ]}],
        "materials": [
            { "name": "amber", "pbrMetallicRoughness": {
                "baseColorFactor": [0.9, 0.45, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.35 } },
            { "name": "steel", "pbrMetallicRoughness": {
                "baseColorFactor": [0.75, 0.76, 0.78, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.25 } },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": pos.len(), "type": "VEC3",
              "min": lo.to_array(), "max": hi.to_array() },
            { "bufferView": 1, "componentType": 5126, "count": nrm.len(), "type": "VEC3" },
            { "bufferView": 2, "componentType": 5123, "count": sides.len(), "type": "SCALAR" },
            { "bufferView": 3, "componentType": 5123, "count": caps.len(), "type": "SCALAR" },
        ],
        "bufferViews": views,
        "buffers": [{ "byteLength": bin.len(),
                      "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)) }],
    });
    std::fs::write(path, serde_json::to_string_pretty(&doc).unwrap() + "\n").unwrap();
    println!("wrote {}", path.display());
}
