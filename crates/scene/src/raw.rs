//! The thesis' raw triangle files (Dammertz 2011, §2.3.2): `.ra2`, `.ran`, `.ruv`.
//!
//! - `NAME.ra2`: 9 little-endian `f32` per triangle (`v0.xyz v1.xyz v2.xyz`), no header; the
//!   triangle count is the file size / 36.
//! - `NAME.ran` (optional, beside it): 9 `f32` per triangle, the three vertex normals.
//! - `NAME.ruv` (optional, beside it): 6 `f32` per triangle, the three vertex uvs (`v = 0` at
//!   the bottom of the texture).
//!
//! A size that is not a multiple of the record size, or a `.ran`/`.ruv` whose record count
//! differs from the `.ra2`'s, is an error. The thesis does not spell out the layout of `.ran`
//! and `.ruv`; this is the natural reading (see `shared/research/seed004-accel.md`).

use crate::error::SceneError;
use crate::geometry::Mesh;
use glam::{Vec2, Vec3};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Bytes per `.ra2` / `.ran` record.
const TRI_BYTES: usize = 36;
/// Bytes per `.ruv` record.
const UV_BYTES: usize = 24;

/// The contents of a `.ra2` file and its optional companions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    /// Triangles, 3 vertices each.
    pub triangles: Vec<[Vec3; 3]>,
    /// Vertex normals per triangle, from the `.ran` file.
    pub normals: Option<Vec<[Vec3; 3]>>,
    /// Vertex uvs per triangle, from the `.ruv` file.
    pub uvs: Option<Vec<[Vec2; 3]>>,
}

fn floats(bytes: &[u8]) -> impl Iterator<Item = f32> + '_ {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn companion(ra2: &Path, ext: &str) -> PathBuf {
    ra2.with_extension(ext)
}

/// Reads one file of `record` bytes per triangle; `expect` is the triangle count it must have.
fn read_records(
    path: &Path,
    record: usize,
    what: &str,
    expect: Option<usize>,
) -> Result<Vec<u8>, SceneError> {
    let bytes =
        std::fs::read(path).map_err(|e| SceneError::file(path, format!("cannot open: {e}")))?;
    if bytes.len() % record != 0 {
        return Err(SceneError::file(
            path,
            format!(
                "file size {} bytes is not a multiple of {record} ({} little-endian f32 of {what} \
                 per triangle)",
                bytes.len(),
                record / 4
            ),
        ));
    }
    if let Some(n) = expect {
        if bytes.len() / record != n {
            return Err(SceneError::file(
                path,
                format!(
                    "has {what} for {} triangles but the .ra2 file has {n}",
                    bytes.len() / record
                ),
            ));
        }
    }
    Ok(bytes)
}

/// Reads `path` (a `.ra2` file) and, when they exist beside it, its `.ran` and `.ruv`.
pub fn read(path: &Path) -> Result<RawMesh, SceneError> {
    let bytes = read_records(path, TRI_BYTES, "vertex positions", None)?;
    let n = bytes.len() / TRI_BYTES;
    let v: Vec<Vec3> = floats(&bytes)
        .collect::<Vec<_>>()
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect();
    let triangles = v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let ran = companion(path, "ran");
    let normals = if ran.is_file() {
        let b = read_records(&ran, TRI_BYTES, "vertex normals", Some(n))?;
        let v: Vec<Vec3> = floats(&b)
            .collect::<Vec<_>>()
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        Some(v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
    } else {
        None
    };
    let ruv = companion(path, "ruv");
    let uvs = if ruv.is_file() {
        let b = read_records(&ruv, UV_BYTES, "vertex uvs", Some(n))?;
        let v: Vec<Vec2> = floats(&b)
            .collect::<Vec<_>>()
            .chunks_exact(2)
            .map(Vec2::from_slice)
            .collect();
        Some(v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
    } else {
        None
    };
    Ok(RawMesh {
        triangles,
        normals,
        uvs,
    })
}

/// Writes `mesh` to `path` (a `.ra2` file) and, when present, its normals and uvs to the
/// `.ran` and `.ruv` files beside it. Fails, before writing anything, if the attribute arrays'
/// lengths differ from the triangle count.
pub fn write(path: &Path, mesh: &RawMesh) -> std::io::Result<()> {
    let n = mesh.triangles.len();
    let bad_len = |what: &str| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{what} count differs from the triangle count {n}"),
        )
    };
    let put = |p: &Path, it: &mut dyn Iterator<Item = f32>| -> std::io::Result<()> {
        let mut w = std::io::BufWriter::new(std::fs::File::create(p)?);
        for x in it {
            w.write_all(&x.to_le_bytes())?;
        }
        w.flush()
    };
    if mesh.normals.as_ref().is_some_and(|v| v.len() != n) {
        return Err(bad_len("normal"));
    }
    if mesh.uvs.as_ref().is_some_and(|v| v.len() != n) {
        return Err(bad_len("uv"));
    }
    put(
        path,
        &mut mesh
            .triangles
            .iter()
            .flat_map(|t| t.iter().flat_map(|v| v.to_array())),
    )?;
    if let Some(nm) = &mesh.normals {
        put(
            &companion(path, "ran"),
            &mut nm.iter().flat_map(|t| t.iter().flat_map(|v| v.to_array())),
        )?;
    }
    if let Some(uv) = &mesh.uvs {
        put(
            &companion(path, "ruv"),
            &mut uv.iter().flat_map(|t| t.iter().flat_map(|v| v.to_array())),
        )?;
    }
    Ok(())
}

/// Loads a `.ra2` file (with companions) as a mesh without materials.
pub(crate) fn load(access: &crate::FileAccess, path: &Path) -> Result<Mesh, SceneError> {
    for p in [
        path.to_path_buf(),
        companion(path, "ran"),
        companion(path, "ruv"),
    ] {
        access.check(&p)?;
    }
    let r = read(path)?;
    let mut m = Mesh::default();
    for (i, t) in r.triangles.iter().enumerate() {
        m.push(
            *t,
            r.normals.as_ref().map(|n| n[i]),
            r.uvs.as_ref().map(|u| u[i]),
            None,
        );
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize) -> RawMesh {
        let t = |i: usize| {
            let f = i as f32;
            [
                Vec3::new(f, 0.5, -f),
                Vec3::new(f + 1.0, 0.25, 3.0),
                Vec3::new(-2.0, f * 1e-3, 7.0),
            ]
        };
        RawMesh {
            triangles: (0..n).map(t).collect(),
            normals: Some((0..n).map(|_| [Vec3::Z, Vec3::Y, Vec3::X]).collect()),
            uvs: Some(
                (0..n)
                    .map(|i| [Vec2::ZERO, Vec2::new(i as f32, 1.0), Vec2::ONE])
                    .collect(),
            ),
        }
    }

    #[test]
    fn round_trip_with_and_without_companions() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.ra2");
        let m = sample(5);
        write(&p, &m).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 5 * 36);
        assert_eq!(read(&p).unwrap(), m);
        let q = dir.path().join("plain.ra2");
        let plain = RawMesh {
            triangles: m.triangles.clone(),
            ..Default::default()
        };
        write(&q, &plain).unwrap();
        assert_eq!(read(&q).unwrap(), plain);
        let mesh = load(&crate::FileAccess::open(), &p).unwrap();
        assert_eq!(mesh.tris, m.triangles);
        assert_eq!(mesh.normals[2], Some([Vec3::Z, Vec3::Y, Vec3::X]));
    }

    #[test]
    fn sizes_that_do_not_fit_the_records_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.ra2");
        std::fs::write(&p, [0u8; 37]).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("m.ra2: file size 37 bytes is not a multiple of 36"),
            "{e}"
        );

        write(&p, &sample(2)).unwrap();
        std::fs::write(dir.path().join("m.ran"), [0u8; 40]).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("m.ran: file size 40 bytes is not a multiple of 36"),
            "{e}"
        );
        std::fs::write(dir.path().join("m.ran"), [0u8; 36]).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("m.ran: has vertex normals for 1 triangles but the .ra2 file has 2"));
        std::fs::remove_file(dir.path().join("m.ran")).unwrap();
        std::fs::write(dir.path().join("m.ruv"), [0u8; 25]).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("m.ruv: file size 25 bytes is not a multiple of 24"),
            "{e}"
        );

        let mut short = sample(2);
        short.uvs.as_mut().unwrap().pop();
        let q = dir.path().join("short.ra2");
        assert!(write(&q, &short).is_err());
        assert!(!q.exists(), "nothing is written");

        let e = read(&dir.path().join("none.ra2")).unwrap_err().to_string();
        assert!(e.contains("none.ra2: cannot open"), "{e}");
    }
}
