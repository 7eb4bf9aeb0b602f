//! The mesh's triangles, in the order our scene loader gives them (so triangle indices agree
//! with `render bench-accel` and with the Embree script): every shape's faces in file order,
//! polygons fanned by tobj with the same options as `crates/scene/src/obj.rs`.

use anyhow::{Context, Result};
use rt_core::glam::Vec3;
use std::path::Path;

/// Loads an OBJ file's triangles (materials are not read).
pub fn load_obj(path: &Path) -> Result<Vec<[Vec3; 3]>> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Read as our loader does: lossy UTF-8, material libraries not read.
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    let mut reader = std::io::Cursor::new(text.as_bytes());
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default()))
        .with_context(|| format!("cannot parse {}", path.display()))?;
    let mut tris = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let p = |i: u32| Vec3::from_slice(&m.positions[3 * i as usize..][..3]);
        for ix in m.indices.chunks_exact(3) {
            tris.push([p(ix[0]), p(ix[1]), p(ix[2])]);
        }
    }
    anyhow::ensure!(!tris.is_empty(), "{} has no triangles", path.display());
    Ok(tris)
}
