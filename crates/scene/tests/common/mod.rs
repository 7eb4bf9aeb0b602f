//! Helpers shared by the integration tests.
#![allow(dead_code)]

use rt_scene::LoadedScene;
use std::path::Path;

/// A camera and an emitting quad: the smallest valid scene. Tests append geometry to it.
pub const BASE: &str = r#"
[[camera]]
name = "main"
position = [0, 1, 4]
look_at = [0, 1, 0]

[[material]]
name = "light"
emission = [1, 1, 1]

[[material]]
name = "white"
color = [0.7, 0.7, 0.7]

[[geometry]]
name = "lamp"
shape = "quad"
vertices = [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]]
material = "light"
"#;

/// Writes `BASE + extra` to `dir/scene.toml` and loads it with `rt_scene::load`.
pub fn load_in(dir: &Path, extra: &str) -> Result<LoadedScene, String> {
    let p = dir.join("scene.toml");
    std::fs::write(&p, format!("{BASE}{extra}")).unwrap();
    rt_scene::load(&p).map_err(|e| {
        let s = e.to_string();
        assert!(!s.contains('\n'), "error is not one line: {s}");
        s
    })
}

/// The triangles of geometry `name`.
pub fn tris(s: &LoadedScene, name: &str) -> Vec<[glam::Vec3; 3]> {
    let o = s
        .scene
        .objects
        .iter()
        .find(|o| o.name == name)
        .unwrap_or_else(|| panic!("no geometry {name}"));
    s.scene.triangles[o.first as usize..(o.first + o.count) as usize].to_vec()
}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
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
