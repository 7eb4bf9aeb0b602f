//! Wavefront OBJ meshes (via `tobj`) and their `.mtl` materials.
//!
//! Polygons are triangulated as fans around their first vertex, `(0,1,2), (0,2,3), ...`, and
//! triangles keep the order of the faces in the file, so `[[assign]]` ranges count triangles
//! in file order. Vertex normals and texture coordinates are used when the faces reference
//! them. When `tobj` rejects a file, the file is scanned again to name the offending line.
//!
//! `.mtl` mapping onto the layered model (documented in `docs/scene-format.md`):
//!
//! | MTL | material |
//! |---|---|
//! | `d < 1` or `illum` 4, 6, 7, 9 | glass: colour `Tf` (default white), ior `Ni` (default 1.5), smooth |
//! | `illum` 3 or 5 (Blender writes 3 for metallic materials) | metal: colour `Kd`, hardness from `Ns` |
//! | `Ks` > 0 and `illum` not 0 or 1 | plastic: base `Kd` under a white clear coat with hardness from `Ns`, ior `Ni` |
//! | otherwise | diffuse `Kd` |
//!
//! `Kd` defaults to 0.8 grey; colours are clamped to [0, 1]. Hardness from `Ns`: the Blinn–Phong
//! exponent of the layered model, `1024κ + 1`, is set equal to `Ns`, so `κ = (Ns − 1)/1024`
//! clamped to [0, 1]. `Ke` is the emission, `map_Kd` the texture (path relative to the `.mtl`).
//! A clear coat rather than a `Ks`-weighted glossy layer, because exporters write `Ks` as a
//! specular *level* (Blender writes 0.5 for an ordinary dielectric), not as a reflectance.

use crate::error::{Result, SceneError};
use crate::geometry::Mesh;
use crate::image_io::Textures;
use glam::{Vec2, Vec3};
use rt_core::{Material, Rgb};
use std::cell::RefCell;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Loads an OBJ file. With `want_materials`, its material libraries are loaded and mapped
/// (a missing or malformed `.mtl` is then an error); without, they are not read at all.
pub(crate) fn load(
    path: &Path,
    want_materials: bool,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Result<Mesh> {
    let bytes = textures.access().read(path, "")?;
    let text = String::from_utf8_lossy(&bytes);
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // The material loader cannot return our errors through tobj: collect them here.
    let mtl_error: RefCell<Option<SceneError>> = RefCell::new(None);
    let mtl_files: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &options, |lib| {
        if !want_materials {
            return Ok(Default::default());
        }
        let p = dir.join(lib);
        match read_mtl(textures.access(), &p) {
            Ok(r) => {
                mtl_files.borrow_mut().push(p);
                r
            }
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    let (models, materials) = match result {
        Ok(r) => r,
        Err(e) => {
            let msg = diagnose(&text).unwrap_or_else(|| format!("malformed OBJ file: {e}"));
            return Err(SceneError::file(path, msg));
        }
    };
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let mut mesh = Mesh::default();
    if want_materials {
        // All libraries' materials in one list (tobj merges them); textures are relative to the
        // library that defines them, which tobj does not record: use the first library's
        // directory (libraries normally sit beside the OBJ).
        let mtl_dir = mtl_files
            .borrow()
            .first()
            .and_then(|p| p.parent().map(Path::to_path_buf))
            .unwrap_or_else(|| dir.clone());
        let materials = materials.unwrap_or_default();
        for m in &materials {
            mesh.materials.push(convert(m, &mtl_dir, textures)?);
        }
        let ignored: Vec<&str> = materials
            .iter()
            .filter(|m| m.normal_texture.is_some() || m.specular_texture.is_some())
            .map(|m| m.name.as_str())
            .collect();
        if !ignored.is_empty() {
            warnings.push(format!(
                "{}: bump, normal and specular maps are ignored (materials {})",
                path.display(),
                ignored.join(", ")
            ));
        }
    }
    for model in &models {
        let m = &model.mesh;
        let mat = if want_materials {
            m.material_id.map(|i| i as u32)
        } else {
            None
        };
        let p = |i: u32| Vec3::from_slice(&m.positions[3 * i as usize..][..3]);
        let has_n = !m.normals.is_empty() && m.normal_indices.len() == m.indices.len();
        let has_t = !m.texcoords.is_empty() && m.texcoord_indices.len() == m.indices.len();
        for (t, ix) in m.indices.chunks_exact(3).enumerate() {
            let n = has_n.then(|| {
                let ni = &m.normal_indices[3 * t..3 * t + 3];
                [0, 1, 2].map(|k| Vec3::from_slice(&m.normals[3 * ni[k] as usize..][..3]))
            });
            let uv = has_t.then(|| {
                let ti = &m.texcoord_indices[3 * t..3 * t + 3];
                [0, 1, 2].map(|k| Vec2::from_slice(&m.texcoords[2 * ti[k] as usize..][..2]))
            });
            mesh.push([p(ix[0]), p(ix[1]), p(ix[2])], n, uv, mat);
        }
    }
    Ok(mesh)
}

/// Reads one material library, with errors that name it.
fn read_mtl(access: &crate::FileAccess, p: &Path) -> Result<tobj::MTLLoadResult> {
    let bytes = access.read(p, "material library")?;
    let r = tobj::load_mtl_buf(&mut Cursor::new(bytes));
    if let Err(e) = &r {
        return Err(SceneError::file(
            p,
            format!("malformed material library: {e}"),
        ));
    }
    Ok(r)
}

/// Maps one MTL material onto the layered model (see the module docs).
fn convert(m: &tobj::Material, mtl_dir: &Path, textures: &mut Textures) -> Result<Material> {
    let clamp = |c: [f32; 3]| Rgb::from(c).clamp(Rgb::ZERO, Rgb::ONE);
    let fix = |c: Rgb| if c.is_finite() { c } else { Rgb::ZERO };
    let kd = fix(m.diffuse.map_or(Rgb::splat(0.8), clamp));
    let ks = fix(m.specular.map_or(Rgb::ZERO, clamp));
    let hardness = m
        .shininess
        .filter(|n| n.is_finite())
        .map_or(0.0, |ns| ((ns - 1.0) / 1024.0).clamp(0.0, 1.0));
    let ior = m
        .optical_density
        .filter(|n| n.is_finite() && *n > 0.0)
        .unwrap_or(1.5);
    let illum = m.illumination_model;
    let transparent = m.dissolve.is_some_and(|d| d < 1.0) || matches!(illum, Some(4 | 6 | 7 | 9));
    let name = &m.name;
    let mut out = if transparent {
        let tf = m
            .unknown_param
            .get("Tf")
            .and_then(|s| parse3(s))
            .map_or(Rgb::ONE, |c| fix(clamp(c)));
        Material::glass(name, tf, ior, 1.0)
    } else if matches!(illum, Some(3 | 5)) {
        Material::metal(name, kd, hardness)
    } else if ks.max_element() > 0.0 && !matches!(illum, Some(0 | 1)) {
        Material::plastic(name, kd, hardness, ior)
    } else {
        Material::diffuse(name, kd)
    };
    if let Some(ke) = m.emissive {
        out.emission = fix(Rgb::from(ke).max(Rgb::ZERO));
    }
    if let Some(tex) = &m.diffuse_texture {
        // Options such as `-bm 1 file.png` come before the file name.
        let file = if tex.starts_with('-') {
            tex.split_whitespace().last().unwrap_or(tex)
        } else {
            tex.as_str()
        };
        out.texture = Some(textures.load_file(&mtl_dir.join(file))?);
    }
    Ok(out)
}

fn parse3(s: &str) -> Option<[f32; 3]> {
    let v: Vec<f32> = s
        .split_whitespace()
        .map(str::parse)
        .collect::<std::result::Result<_, _>>()
        .ok()?;
    match v.as_slice() {
        [x] => Some([*x; 3]),
        [x, y, z] => Some([*x, *y, *z]),
        _ => None,
    }
}

/// Finds the first line that makes the file invalid and says what is wrong with it. Used only
/// after `tobj` failed, whose errors do not say where.
fn diagnose(text: &str) -> Option<String> {
    let count = |tag: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(tag))
            .count()
    };
    let (nv, nt, nn) = (count("v"), count("vt"), count("vn"));
    let (mut sv, mut st, mut sn) = (0usize, 0usize, 0usize);
    let mut face = 0usize;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let mut w = line.split_whitespace();
        let tag = w.next();
        let floats = |w: std::str::SplitWhitespace, min: usize| {
            let v: Vec<&str> = w.collect();
            v.len() >= min && v.iter().take(min).all(|x| x.parse::<f32>().is_ok())
        };
        match tag {
            Some("v") => {
                sv += 1;
                if !floats(w, 3) {
                    return Some(format!(
                        "line {line_no}: cannot parse vertex position \"{}\"",
                        line.trim()
                    ));
                }
            }
            Some("vt") => {
                st += 1;
                if !floats(w, 2) {
                    return Some(format!(
                        "line {line_no}: cannot parse texture coordinate \"{}\"",
                        line.trim()
                    ));
                }
            }
            Some("vn") => {
                sn += 1;
                if !floats(w, 3) {
                    return Some(format!(
                        "line {line_no}: cannot parse vertex normal \"{}\"",
                        line.trim()
                    ));
                }
            }
            Some("f") => {
                face += 1;
                for corner in w {
                    let parts: Vec<&str> = corner.split('/').collect();
                    let kinds = [
                        ("vertex", nv, sv),
                        ("texture coordinate", nt, st),
                        ("normal", nn, sn),
                    ];
                    for (k, part) in parts.iter().enumerate().take(3) {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let (what, total, so_far) = kinds[k];
                        let Ok(idx) = part.parse::<i64>() else {
                            return Some(format!(
                                "line {line_no}: face {face} has an unparsable vertex \"{corner}\""
                            ));
                        };
                        let resolved = if idx < 0 {
                            so_far as i64 + idx + 1
                        } else {
                            idx
                        };
                        if idx == 0 || resolved < 1 || resolved > total as i64 {
                            let s = if total == 1 { "" } else { "s" };
                            let what_pl = if what == "vertex" && total != 1 {
                                "vertices".to_string()
                            } else {
                                format!("{what}{s}")
                            };
                            return Some(format!(
                                "line {line_no}: face {face} references {what} {idx} but the file \
                                 has {total} {what_pl}"
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn load_ok(p: &Path, mats: bool) -> (Mesh, Vec<rt_core::texture::Texture>) {
        let mut tex = Textures::default();
        let mut w = vec![];
        let m = load(p, mats, &mut tex, &mut w).unwrap();
        (m, tex.into_vec())
    }

    #[test]
    fn polygons_are_fan_triangulated_in_file_order() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "poly.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\n\
             f 1 2 3\n\
             f 1 2 3 4\n\
             o second\n\
             f 1 2 3 4 5\n",
        );
        let (m, _) = load_ok(&p, false);
        let v = |i: usize| {
            [
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::Y,
                Vec3::new(-1.0, 0.5, 0.0),
            ][i - 1]
        };
        let expect = vec![
            [v(1), v(2), v(3)],
            [v(1), v(2), v(3)],
            [v(1), v(3), v(4)],
            [v(1), v(2), v(3)],
            [v(1), v(3), v(4)],
            [v(1), v(4), v(5)],
        ];
        assert_eq!(m.tris, expect);
        assert!(m.normals.iter().all(Option::is_none));
    }

    #[test]
    fn normals_uvs_and_negative_indices() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "n.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
             f -3/-3/-1 -2/-2/-1 -1/-1/-1\n",
        );
        let (m, _) = load_ok(&p, false);
        assert_eq!(m.tris[0], [Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(m.normals[0], Some([Vec3::Z; 3]));
        assert_eq!(m.uvs[0], Some([Vec2::ZERO, Vec2::X, Vec2::Y]));
    }

    #[test]
    fn mtl_materials_are_mapped_and_assigned_per_face() {
        let dir = tempfile::tempdir().unwrap();
        image::RgbImage::from_pixel(1, 1, image::Rgb([255, 255, 255]))
            .save(dir.path().join("tex.png"))
            .unwrap();
        write(
            dir.path(),
            "m.mtl",
            "newmtl matte\nKd 0.5 0.25 0.125\nillum 1\n\
             newmtl shiny\nKd 0.2 0.2 0.2\nKs 0.5 0.5 0.5\nNs 513\nNi 1.4\nillum 2\n\
             newmtl glass\nd 0.5\nNi 1.33\nTf 0.9 1 0.9\n\
             newmtl steel\nKd 0.6 0.6 0.6\nNs 1025\nillum 3\n\
             newmtl lamp\nKd 0 0 0\nKe 5 4 3\n\
             newmtl wood\nmap_Kd -bm 1 tex.png\n",
        );
        let p = write(
            dir.path(),
            "m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
             usemtl shiny\nf 1 2 3\nusemtl matte\nf 1 2 3\nusemtl lamp\nf 1 2 3\n",
        );
        let (m, tex) = load_ok(&p, true);
        let names: Vec<&str> = m.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["matte", "shiny", "glass", "steel", "lamp", "wood"]);
        assert_eq!(m.mat, vec![Some(1), Some(0), Some(4)]);
        assert_eq!(
            m.materials[0],
            Material::diffuse("matte", Rgb::new(0.5, 0.25, 0.125))
        );
        assert_eq!(
            m.materials[1],
            Material::plastic("shiny", Rgb::splat(0.2), 0.5, 1.4)
        );
        assert_eq!(
            m.materials[2],
            Material::glass("glass", Rgb::new(0.9, 1.0, 0.9), 1.33, 1.0)
        );
        assert_eq!(
            m.materials[3],
            Material::metal("steel", Rgb::splat(0.6), 1.0)
        );
        assert_eq!(m.materials[4].emission, Rgb::new(5.0, 4.0, 3.0));
        assert_eq!(m.materials[5].texture, Some(0));
        assert_eq!(tex.len(), 1);
        for mat in &m.materials {
            assert_eq!(mat.validate(), Ok(()), "{}", mat.name);
        }
        // Without materials, the library is not even read.
        std::fs::remove_file(dir.path().join("m.mtl")).unwrap();
        let (m, _) = load_ok(&p, false);
        assert!(m.materials.is_empty() && m.mat.iter().all(Option::is_none));
        let mut t = Textures::default();
        let e = load(&p, true, &mut t, &mut vec![]).unwrap_err().to_string();
        assert!(e.contains("m.mtl: cannot open material library"), "{e}");
    }

    #[test]
    fn broken_files_name_the_line_and_the_problem() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 900\n",
                "line 5: face 2 references vertex 900 but the file has 3 vertices",
            ),
            (
                "v 0 0 0\nv 1 x 0\nf 1 2 1\n",
                "line 2: cannot parse vertex position \"v 1 x 0\"",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
                "line 5: face 1 references normal 2 but the file has 1 normal",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n",
                "line 4: face 1 has an unparsable vertex \"a\"",
            ),
        ];
        for (text, want) in cases {
            let p = write(dir.path(), "bad.obj", text);
            let e = load(&p, false, &mut Textures::default(), &mut vec![])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("bad.obj: ") && e.contains(want),
                "{e}\nwant {want}"
            );
        }
        let e = load(
            &dir.path().join("nope.obj"),
            false,
            &mut Textures::default(),
            &mut vec![],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("nope.obj: cannot open"), "{e}");
    }
}
