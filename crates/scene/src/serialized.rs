//! Mitsuba's `.serialized` meshes: one file holds several zlib-compressed triangle meshes
//! (format versions 3 and 4, as Mitsuba 0.6 writes them and Mitsuba 3 reads them).
//!
//! Layout (little-endian): each mesh starts with the `u16` tag `0x041C` and a `u16` version,
//! followed by a zlib stream of `u32` flags, (version 4) a NUL-terminated name, `u64` vertex
//! and triangle counts, positions, then normals, texture coordinates and colours if the flags
//! say so (`f32` or `f64`), then the triangles' vertex indices (`u32`, or `u64` past 2³² − 1
//! vertices). The file ends with one offset per mesh (`u64`; `u32` in version 3) and the
//! `u32` mesh count, which is how `shape_index` finds its mesh.
//!
//! Deviations: texture coordinates are stored with `v = 0` at the top of the image (Mitsuba's
//! convention for this format); they are turned to ours (`v = 0` at the bottom) on load.
//! Vertex colours are read past and dropped (nothing renders them).

use crate::error::SceneError;
use crate::geometry::Mesh;
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

const TAG: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;
/// Longest mesh name read before the file is called broken.
const MAX_NAME: usize = 1 << 16;

/// Loads mesh `shape_index` of the file at `path`.
pub(crate) fn load(
    access: &crate::FileAccess,
    path: &Path,
    shape_index: u32,
) -> Result<Mesh, SceneError> {
    let data = access.read(path, "serialized mesh")?;
    parse(&data, shape_index).map_err(|m| SceneError::file(path, m))
}

fn parse(data: &[u8], shape_index: u32) -> Result<Mesh, String> {
    let start = mesh_offset(data, shape_index)?;
    let head = data
        .get(start..start + 4)
        .ok_or("truncated: no mesh header")?;
    let tag = u16::from_le_bytes([head[0], head[1]]);
    let version = u16::from_le_bytes([head[2], head[3]]);
    if tag != TAG {
        return Err(format!(
            "not a Mitsuba serialized mesh (tag {tag:#06x}, expected {TAG:#06x})"
        ));
    }
    if version != 3 && version != 4 {
        return Err(format!("format version {version} (3 and 4 are read)"));
    }
    let mut z = Stream(ZlibDecoder::new(&data[start + 4..]));
    let flags = z.u32()?;
    if version == 4 {
        z.name()?;
    }
    let vertices = z.u64()?;
    let triangles = z.u64()?;
    if vertices == 0 || triangles == 0 {
        return Err("the mesh has no vertices or no triangles".into());
    }
    if triangles > u32::MAX as u64 {
        return Err(format!("{triangles} triangles (at most 2^32 - 1)"));
    }
    let double = match (flags & SINGLE != 0, flags & DOUBLE != 0) {
        (true, false) => false,
        (false, true) => true,
        _ => {
            return Err(format!(
                "flags {flags:#x}: neither or both of single and double precision"
            ))
        }
    };
    let positions = z.vectors(vertices, 3, double, "positions")?;
    let normals = if flags & HAS_NORMALS != 0 {
        Some(z.vectors(vertices, 3, double, "normals")?)
    } else {
        None
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(z.vectors(vertices, 2, double, "texture coordinates")?)
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        z.vectors(vertices, 3, double, "colors")?;
    }
    let wide = vertices > u32::MAX as u64;
    let indices = z.indices(triangles, wide)?;
    let normals = normals.filter(|_| flags & FACE_NORMALS == 0);
    let mut m = Mesh::default();
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i >= vertices) {
            return Err(format!(
                "triangle {t} references vertex {bad} of {vertices}"
            ));
        }
        let ix = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
        let v3 = |a: &[f64], i: usize| {
            Vec3::new(a[3 * i] as f32, a[3 * i + 1] as f32, a[3 * i + 2] as f32)
        };
        m.push(
            ix.map(|i| v3(&positions, i)),
            normals.as_ref().map(|n| ix.map(|i| v3(n, i))),
            uvs.as_ref()
                .map(|u| ix.map(|i| Vec2::new(u[2 * i] as f32, 1.0 - u[2 * i + 1] as f32))),
            None,
        );
    }
    Ok(m)
}

/// Byte offset of mesh `index`: 0 for the first, else from the table at the end of the file.
fn mesh_offset(data: &[u8], index: u32) -> Result<usize, String> {
    if index == 0 {
        return Ok(0);
    }
    let n = data.len();
    let count = n
        .checked_sub(4)
        .map(|at| u32::from_le_bytes(data[at..].try_into().expect("4 bytes")))
        .ok_or("truncated: no mesh count")?;
    if index >= count {
        return Err(format!(
            "shape_index {index}: the file holds {count} meshes"
        ));
    }
    let version = data
        .get(2..4)
        .map(|v| u16::from_le_bytes([v[0], v[1]]))
        .ok_or("truncated: no header")?;
    let width = if version == 3 { 4 } else { 8 };
    let at = (count - index) as usize * width + 4;
    let entry = n
        .checked_sub(at)
        .and_then(|a| data.get(a..a + width))
        .ok_or("truncated: the mesh offset table is cut short")?;
    let offset = if width == 4 {
        u32::from_le_bytes(entry.try_into().expect("4 bytes")) as u64
    } else {
        u64::from_le_bytes(entry.try_into().expect("8 bytes"))
    };
    if offset >= n as u64 {
        return Err(format!(
            "mesh {index} starts at byte {offset}, past the end of the file ({n} bytes)"
        ));
    }
    Ok(offset as usize)
}

/// The decompressed stream, read in pieces whose size the header gives: memory grows with
/// the data actually present, not with what a broken header claims.
struct Stream<'a>(ZlibDecoder<&'a [u8]>);

impl Stream<'_> {
    fn bytes(&mut self, len: u64, what: &str) -> Result<Vec<u8>, String> {
        let mut buf = Vec::new();
        (&mut self.0)
            .take(len)
            .read_to_end(&mut buf)
            .map_err(|e| format!("cannot decompress the {what}: {e}"))?;
        if (buf.len() as u64) < len {
            return Err(format!("truncated: the {what} are cut short"));
        }
        Ok(buf)
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.bytes(4, "header")?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    fn u64(&mut self) -> Result<u64, String> {
        let b = self.bytes(8, "header")?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    fn name(&mut self) -> Result<(), String> {
        for _ in 0..MAX_NAME {
            if self.bytes(1, "mesh name")?[0] == 0 {
                return Ok(());
            }
        }
        Err(format!("the mesh name is longer than {MAX_NAME} bytes"))
    }

    /// `count` vectors of `dim` components, as `f64`.
    fn vectors(
        &mut self,
        count: u64,
        dim: u64,
        double: bool,
        what: &str,
    ) -> Result<Vec<f64>, String> {
        let size = if double { 8 } else { 4 };
        let len = count
            .checked_mul(dim * size)
            .ok_or_else(|| format!("{count} vertices overflow the {what}' size"))?;
        let b = self.bytes(len, what)?;
        let v: Vec<f64> = if double {
            b.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        } else {
            b.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")) as f64)
                .collect()
        };
        Ok(v)
    }

    fn indices(&mut self, triangles: u64, wide: bool) -> Result<Vec<u64>, String> {
        let size = if wide { 8 } else { 4 };
        let b = self.bytes(triangles * 3 * size, "triangle indices")?;
        Ok(if wide {
            b.chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        } else {
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")) as u64)
                .collect()
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use flate2::write::ZlibEncoder;
    use std::io::Write;

    /// What a test mesh holds.
    pub(crate) struct TestMesh {
        pub positions: Vec<[f32; 3]>,
        pub normals: Option<Vec<[f32; 3]>>,
        pub uvs: Option<Vec<[f32; 2]>>,
        pub triangles: Vec<[u32; 3]>,
    }

    /// Writes `meshes` as a version-`version` file, each in single precision.
    pub(crate) fn write(meshes: &[TestMesh], version: u16) -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for (i, m) in meshes.iter().enumerate() {
            offsets.push(out.len() as u64);
            out.extend(TAG.to_le_bytes());
            out.extend(version.to_le_bytes());
            let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            let mut flags = SINGLE;
            flags |= if m.normals.is_some() { HAS_NORMALS } else { 0 };
            flags |= if m.uvs.is_some() { HAS_TEXCOORDS } else { 0 };
            z.write_all(&flags.to_le_bytes()).unwrap();
            if version == 4 {
                z.write_all(format!("mesh{i}\0").as_bytes()).unwrap();
            }
            z.write_all(&(m.positions.len() as u64).to_le_bytes())
                .unwrap();
            z.write_all(&(m.triangles.len() as u64).to_le_bytes())
                .unwrap();
            let floats = |z: &mut ZlibEncoder<Vec<u8>>, v: &[f32]| {
                v.iter()
                    .for_each(|x| z.write_all(&x.to_le_bytes()).unwrap())
            };
            floats(&mut z, m.positions.as_flattened());
            if let Some(n) = &m.normals {
                floats(&mut z, n.as_flattened());
            }
            if let Some(u) = &m.uvs {
                floats(&mut z, u.as_flattened());
            }
            for i in m.triangles.as_flattened() {
                z.write_all(&i.to_le_bytes()).unwrap();
            }
            out.extend(z.finish().unwrap());
        }
        for o in &offsets {
            if version == 3 {
                out.extend((*o as u32).to_le_bytes());
            } else {
                out.extend(o.to_le_bytes());
            }
        }
        out.extend((meshes.len() as u32).to_le_bytes());
        out
    }

    fn triangle(z: f32) -> TestMesh {
        TestMesh {
            positions: vec![[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]],
            // Not the face's normal, which the scene would drop as redundant.
            normals: Some(vec![[0.0, 0.6, 0.8]; 3]),
            uvs: Some(vec![[0.0, 0.25], [1.0, 0.0], [0.0, 1.0]]),
            triangles: vec![[0, 1, 2]],
        }
    }

    #[test]
    fn every_mesh_of_both_versions_is_found_by_its_index() {
        for version in [3, 4] {
            let file = write(&[triangle(0.0), triangle(1.0), triangle(2.0)], version);
            for i in 0..3u32 {
                let m = parse(&file, i).unwrap();
                assert_eq!(m.tris.len(), 1);
                assert_eq!(
                    m.tris[0][0],
                    Vec3::new(0.0, 0.0, i as f32),
                    "v{version} mesh {i}"
                );
                assert_eq!(m.normals[0], Some([Vec3::new(0.0, 0.6, 0.8); 3]));
                // v = 0 at the top in the file, at the bottom here.
                assert_eq!(m.uvs[0].unwrap()[0], Vec2::new(0.0, 0.75));
            }
            let e = parse(&file, 3).unwrap_err();
            assert!(e.contains("holds 3 meshes"), "{e}");
        }
    }

    #[test]
    fn broken_files_are_one_line_errors() {
        let good = write(&[triangle(0.0)], 4);
        let mut bad_tag = good.clone();
        bad_tag[0] = 0;
        let mut bad_index = triangle(0.0);
        bad_index.triangles = vec![[0, 1, 7]];
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (Vec::new(), "truncated"),
            (bad_tag, "not a Mitsuba serialized mesh"),
            (good[..good.len() / 2].to_vec(), "cannot decompress"),
            (write(&[bad_index], 4), "references vertex 7"),
        ];
        for (data, want) in cases {
            let e = parse(&data, 0).unwrap_err();
            assert!(e.contains(want), "{e:?} should say {want:?}");
            assert!(!e.contains('\n'));
        }
    }

    #[test]
    fn a_mitsuba_scene_picks_its_mesh_and_drops_normals_with_face_normals() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("m.serialized"),
            write(&[triangle(0.0), triangle(1.0)], 4),
        )
        .unwrap();
        let shape = |extra: &str| {
            format!(
                r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><rfilter type="box"/></film></sensor>
    <shape type="serialized"><string name="filename" value="m.serialized"/>{extra}</shape>
</scene>"#
            )
        };
        let load = |extra: &str| {
            let path = dir.path().join("s.xml");
            std::fs::write(&path, shape(extra)).unwrap();
            crate::load_defined(&path, &crate::FileAccess::open(), &[])
        };
        let first = load("").unwrap().scene;
        assert_eq!(first.triangles[0][0].z, 0.0);
        assert!(first.normals[0].is_some());
        let second = load(
            r#"<integer name="shape_index" value="1"/><boolean name="face_normals" value="true"/>"#,
        )
        .unwrap()
        .scene;
        assert_eq!(second.triangles[0][0].z, 1.0);
        assert!(second.normals.first().is_none_or(|n| n.is_none()));
        let e = load(r#"<integer name="shape_index" value="2"/>"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.serialized") && e.contains("holds 2 meshes"),
            "{e}"
        );
    }

    #[test]
    fn a_header_claiming_huge_counts_fails_without_allocating_them() {
        let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&SINGLE.to_le_bytes()).unwrap();
        z.write_all(&(u64::MAX / 16).to_le_bytes()).unwrap();
        z.write_all(&1u64.to_le_bytes()).unwrap();
        let mut file = Vec::from(TAG.to_le_bytes());
        file.extend(3u16.to_le_bytes());
        file.extend(z.finish().unwrap());
        let e = parse(&file, 0).unwrap_err();
        assert!(e.contains("cut short"), "{e}");
    }
}
