//! Triangles of an OBJ file (`v` and `f` lines only, polygons as fans, negative indices
//! relative): enough for the meshes in `../shared/data`, with no dependency. The shipped loader
//! is `rt-scene`'s; this one lets the acceleration-structure tests read a mesh without it.

use rt_core::glam::Vec3;
use std::path::Path;

/// The triangles of OBJ text. Panics on a malformed `v` or `f` line (test input).
pub fn parse(text: &str) -> Vec<[Vec3; 3]> {
    let mut positions = Vec::new();
    let mut tris = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f32> = words.take(3).map(|w| w.parse().unwrap()).collect();
                positions.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let idx: Vec<usize> = words
                    .map(|w| {
                        let i: i64 = w.split('/').next().unwrap().parse().unwrap();
                        if i < 0 {
                            (positions.len() as i64 + i) as usize
                        } else {
                            i as usize - 1
                        }
                    })
                    .collect();
                for k in 1..idx.len().saturating_sub(1) {
                    tris.push([idx[0], idx[k], idx[k + 1]].map(|i| positions[i]));
                }
            }
            _ => {}
        }
    }
    tris
}

/// The triangles of the OBJ file at `path`, or `None` if it cannot be read.
pub fn read(path: &Path) -> Option<Vec<[Vec3; 3]>> {
    Some(parse(&std::fs::read_to_string(path).ok()?))
}

/// A mesh of `../shared/data` by its relative path ([`crate::data::file`]: `None` after a
/// visible skip line, a panic under `RT_REQUIRE_DATA=1`).
pub fn shared_mesh(relative: &str) -> Option<Vec<[Vec3; 3]>> {
    let path = crate::data::file(relative)?;
    Some(read(&path).unwrap_or_else(|| panic!("cannot read {}", path.display())))
}
