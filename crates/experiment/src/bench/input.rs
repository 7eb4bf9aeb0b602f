//! The benchmark's geometry: a TOML scene, a bare mesh file, or a procedural scene.

use super::BenchError;
use rt_core::{glam::Vec3, Aabb, Camera, Scene};
use std::io::Write;
use std::path::Path;

/// A loaded scene with the camera for the primary rays.
pub struct Input {
    /// The input as the user wrote it (for messages and the CSV).
    pub name: String,
    /// The scene.
    pub scene: Scene,
    /// The chosen camera.
    pub camera: Camera,
    /// Where shadow rays aim when the scene has no emissive triangles: above the geometry.
    pub fallback_light: Vec3,
    /// The loader's remarks.
    pub warnings: Vec<String>,
    /// True for a bare mesh (the camera is automatic).
    pub is_mesh: bool,
    /// Bounds of all triangles.
    pub bounds: Aabb,
}

/// Where the automatic camera of a mesh stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Outside the bounds, seeing every vertex (scanned objects: bunny, dragon).
    Outside,
    /// Inside, looking down the long horizontal axis (rooms: conference, Sibenik, kitchen).
    Inside,
}

/// Longest side of the primary ray grid by default.
const DEFAULT_WIDTH: u32 = 512;
/// Largest primary ray grid (the renderer's image limits).
pub use rt_core::limits::{MAX_IMAGE_PIXELS as MAX_PIXELS, MAX_IMAGE_SIDE as MAX_SIDE};

/// Loads `input`: `gen:NAME`, a `.toml` scene, or a mesh file; `camera` picks a scene's camera
/// by name (the first by default; a mesh has none).
pub fn load(input: &str, camera: Option<&str>) -> Result<Input, BenchError> {
    let path = Path::new(input);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let refuse = |message: String| BenchError::Input {
        input: input.to_string(),
        message,
    };
    let (loaded, is_mesh) = if input.starts_with("gen:") || ext == "toml" || ext == "xml" {
        (rt_session::load_scene(path, None, &[])?.loaded, false)
    } else if rt_scene::MESH_EXTENSIONS.contains(&ext.as_str()) {
        (rt_scene::load_mesh(path)?, true)
    } else {
        return Err(refuse(format!(
            "unknown input type (expected a .toml or .xml scene, a .{} mesh, or gen:NAME with \
             NAME one of {})",
            rt_scene::MESH_EXTENSIONS.join(", ."),
            rt_scene::procedural::NAMES.join(", ")
        )));
    };
    let scene = loaded.scene;
    let bounds = Aabb::from_points(scene.triangles.iter().flatten());
    if scene.triangles.is_empty() || bounds.is_empty() {
        return Err(refuse("the scene has no triangles".into()));
    }
    let radius = 0.5 * bounds.extent().length();
    let camera = if is_mesh {
        if camera.is_some() {
            return Err(BenchError::MeshCamera);
        }
        rt_scene::views::outside_view(&scene.triangles, &bounds)
    } else {
        rt_session::pick_camera(&scene, path, camera)?.clone()
    };
    Ok(Input {
        name: input.to_string(),
        fallback_light: bounds.center() + Vec3::Y * (2.0 * radius),
        scene,
        camera,
        warnings: loaded.warnings,
        is_mesh,
        bounds,
    })
}

/// The primary ray grid: as given, or derived from the camera's aspect ratio.
pub fn resolution(
    camera: &Camera,
    width: Option<u32>,
    height: Option<u32>,
) -> Result<(u32, u32), BenchError> {
    let aspect = camera.height as f64 / camera.width as f64;
    let from = |v: u32, a: f64| ((v as f64 * a).round() as u32).max(1);
    let (w, h) = match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, from(w, aspect)),
        (None, Some(h)) => (from(h, 1.0 / aspect), h),
        (None, None) => (DEFAULT_WIDTH, from(DEFAULT_WIDTH, aspect)),
    };
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE || w as u64 * h as u64 > MAX_PIXELS {
        return Err(BenchError::Resolution {
            width: w,
            height: h,
        });
    }
    Ok((w, h))
}

/// The procedural scene `name`'s triangles as OBJ, one `o` per part, vertices not shared,
/// coordinates printed exactly (shortest round-trip decimal).
pub fn write_obj(name: &str, output: &Path) -> Result<(), BenchError> {
    let scene = rt_scene::procedural::generate(name).map_err(|e| BenchError::Input {
        input: format!("gen:{name}"),
        message: e.to_string(),
    })?;
    let fail = |source| BenchError::Io {
        path: output.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(output).map_err(fail)?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(
        w,
        "# rt procedural scene gen:{name}, {} triangles",
        scene.triangle_count()
    )
    .map_err(fail)?;
    for object in &scene.objects {
        writeln!(w, "o {}", object.name).map_err(fail)?;
        let range = object.first as usize..(object.first + object.count) as usize;
        for t in &scene.triangles[range.clone()] {
            for v in t {
                writeln!(w, "v {} {} {}", v.x, v.y, v.z).map_err(fail)?;
            }
        }
        for i in range {
            let k = 3 * i + 1;
            writeln!(w, "f {} {} {}", k, k + 1, k + 2).map_err(fail)?;
        }
    }
    w.flush().map_err(fail)?;
    Ok(())
}
