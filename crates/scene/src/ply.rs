//! Stanford PLY meshes (`.ply`): ASCII and binary (little- and big-endian) files with a
//! `vertex` element (`x`, `y`, `z`; optional `nx`, `ny`, `nz` and `u`, `v` — also named `s`,
//! `t` or `texture_u`, `texture_v`) and a `face` element whose `vertex_indices` (or
//! `vertex_index`) list is triangulated as a fan. Other elements and properties are skipped.
//! Texture coordinates are taken as stored (`v = 0` is the bottom of the image, as in OBJ).

use crate::error::SceneError;
use crate::geometry::Mesh;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Most vertices per face (a polygon is a fan of `n − 2` triangles).
const MAX_FACE_VERTICES: usize = 256;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Format {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    kind: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

/// Reads values one at a time from the body, whatever its format.
struct Body<'a> {
    format: Format,
    bytes: &'a [u8],
    pos: usize,
    words: std::str::SplitAsciiWhitespace<'a>,
}

impl Body<'_> {
    fn value(&mut self, kind: Scalar) -> Option<f64> {
        if self.format == Format::Ascii {
            return self.words.next()?.parse().ok();
        }
        let n = kind.size();
        let b = self.bytes.get(self.pos..self.pos + n)?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.format == Format::Big {
            a[..n].reverse();
        }
        Some(match kind {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
}

/// Loads the PLY file at `path`.
pub(crate) fn load(access: &crate::FileAccess, path: &Path) -> Result<Mesh, SceneError> {
    let data = access.read(path, "PLY mesh")?;
    parse(&data).map_err(|m| SceneError::file(path, m))
}

fn parse(data: &[u8]) -> Result<Mesh, String> {
    let end = find(data, b"end_header").ok_or("not a PLY file: no end_header")?;
    let header = std::str::from_utf8(&data[..end]).map_err(|_| "the header is not text")?;
    let mut body_start = end + "end_header".len();
    // The header ends with its line break (\n or \r\n).
    if data.get(body_start) == Some(&b'\r') {
        body_start += 1;
    }
    if data.get(body_start) == Some(&b'\n') {
        body_start += 1;
    }
    let mut lines = header.lines().map(str::trim);
    if lines.next() != Some("ply") {
        return Err("not a PLY file: it does not start with `ply`".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["format", f, _version] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    other => return Err(format!("unknown format `{other}`")),
                })
            }
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("bad element count `{count}`"))?,
                props: Vec::new(),
            }),
            ["property", "list", count, kind, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let bad = || format!("unknown property type in `{line}`");
                e.props.push(Property {
                    name: name.to_string(),
                    list: Some(Scalar::parse(count).ok_or_else(bad)?),
                    kind: Scalar::parse(kind).ok_or_else(bad)?,
                });
            }
            ["property", kind, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                e.props.push(Property {
                    name: name.to_string(),
                    list: None,
                    kind: Scalar::parse(kind)
                        .ok_or_else(|| format!("unknown property type in `{line}`"))?,
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(format!("unexpected header line `{line}`")),
        }
    }
    let format = format.ok_or("the header has no format line")?;
    let text = if format == Format::Ascii {
        std::str::from_utf8(&data[body_start..]).map_err(|_| "the ASCII body is not text")?
    } else {
        ""
    };
    let mut body = Body {
        format,
        bytes: &data[body_start..],
        pos: 0,
        words: text.split_ascii_whitespace(),
    };
    let truncated = |what: &str| format!("the file ends inside the {what} data");
    let (mut pos, mut nrm, mut uv) = (Vec::new(), Vec::new(), Vec::new());
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for e in &elements {
        let index = |names: &[&str]| {
            e.props
                .iter()
                .position(|p| names.contains(&p.name.as_str()))
        };
        let xyz = [index(&["x"]), index(&["y"]), index(&["z"])];
        let n = [index(&["nx"]), index(&["ny"]), index(&["nz"])];
        let st = [
            index(&["u", "s", "texture_u", "texture_s"]),
            index(&["v", "t", "texture_v", "texture_t"]),
        ];
        let list = index(&["vertex_indices", "vertex_index"]);
        if e.props.is_empty() {
            // Nothing to read: a huge count must not spin.
            continue;
        }
        let mut row = vec![0.0f64; e.props.len()];
        for _ in 0..e.count {
            let mut face = Vec::new();
            for (k, p) in e.props.iter().enumerate() {
                match p.list {
                    None => row[k] = body.value(p.kind).ok_or_else(|| truncated(&e.name))?,
                    Some(ck) => {
                        let count = body.value(ck).ok_or_else(|| truncated(&e.name))? as usize;
                        if Some(k) == list && count > MAX_FACE_VERTICES {
                            return Err(format!(
                                "a face of {count} vertices (at most {MAX_FACE_VERTICES})"
                            ));
                        }
                        for _ in 0..count {
                            let v = body.value(p.kind).ok_or_else(|| truncated(&e.name))?;
                            if Some(k) == list {
                                face.push(v as u32);
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                let [Some(x), Some(y), Some(z)] = xyz else {
                    return Err("the vertex element has no x, y and z".into());
                };
                pos.push(Vec3::new(row[x] as f32, row[y] as f32, row[z] as f32));
                if let [Some(a), Some(b), Some(c)] = n {
                    nrm.push(Vec3::new(row[a] as f32, row[b] as f32, row[c] as f32));
                }
                if let [Some(a), Some(b)] = st {
                    uv.push(Vec2::new(row[a] as f32, row[b] as f32));
                }
            } else if e.name == "face" {
                if list.is_none() {
                    return Err("the face element has no vertex_indices list".into());
                }
                faces.push(face);
            }
        }
    }
    let mut m = Mesh::default();
    for f in &faces {
        for i in 1..f.len().saturating_sub(1) {
            let idx = [f[0], f[i], f[i + 1]];
            if let Some(&bad) = idx.iter().find(|&&j| j as usize >= pos.len()) {
                return Err(format!("a face refers to vertex {bad} of {}", pos.len()));
            }
            let get = |j: u32| pos[j as usize];
            let normals = (!nrm.is_empty()).then(|| idx.map(|j| nrm[j as usize]));
            let uvs = (!uv.is_empty()).then(|| idx.map(|j| uv[j as usize]));
            m.push(idx.map(get), normals, uvs, None);
        }
    }
    Ok(m)
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_quads_become_fans_with_uvs() {
        let m = parse(ASCII.as_bytes()).unwrap();
        assert_eq!(m.tris.len(), 2);
        assert_eq!(
            m.tris[1],
            [
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0)
            ]
        );
        assert_eq!(m.uvs[0].unwrap()[2], Vec2::new(1.0, 1.0));
        assert!(m.normals[0].is_none());
    }

    #[test]
    fn binary_files_of_both_byte_orders_read_the_same() {
        for (fmt, be) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut d = format!(
                "ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            )
            .into_bytes();
            let f = |v: f32| if be { v.to_be_bytes() } else { v.to_le_bytes() };
            for p in [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]] {
                for c in p.iter().chain(&[0.0, 0.0, 1.0]) {
                    d.extend(f(*c));
                }
            }
            d.push(3);
            for i in 0u32..3 {
                d.extend(if be { i.to_be_bytes() } else { i.to_le_bytes() });
            }
            let m = parse(&d).unwrap();
            assert_eq!(
                m.tris,
                vec![[
                    Vec3::ZERO,
                    Vec3::new(2.0, 0.0, 0.0),
                    Vec3::new(0.0, 3.0, 0.0)
                ]]
            );
            assert_eq!(m.normals[0].unwrap()[1], Vec3::Z);
        }
    }

    #[test]
    fn broken_files_are_errors() {
        let cut = &ASCII[..ASCII.len() - 4];
        assert_eq!(
            parse(cut.as_bytes()).unwrap_err(),
            "the file ends inside the face data"
        );
        let bad = ASCII.replace("4 0 1 2 3", "3 0 1 9");
        assert_eq!(
            parse(bad.as_bytes()).unwrap_err(),
            "a face refers to vertex 9 of 4"
        );
        assert!(parse(b"solid x\nend_header\n")
            .unwrap_err()
            .contains("does not start with `ply`"));
        assert!(parse(b"ply\nformat ascii 1.0\n")
            .unwrap_err()
            .contains("no end_header"));
        // An element of no properties and an absurd count is skipped, not looped over.
        let empty = ASCII.replace(
            "element face 1",
            "element junk 18446744073709551615\nelement face 1",
        );
        assert_eq!(parse(empty.as_bytes()).unwrap().tris.len(), 2);
    }
}
