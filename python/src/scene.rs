//! `Scene`: a loaded scene held in memory, rendered as often as asked (`render.rs`), with its
//! cameras and objects changed in place between renders, never reloaded.

use crate::arrays::{f32_array, rows};
use crate::{rt_err, value_err};
use glam::{Mat4, Vec3};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rt_core::Camera;
use rt_scene::{FileAccess, LoadedScene};
use std::path::{Path, PathBuf};

/// A scene: its triangles, materials, lights and cameras, and the `[render]` defaults of its
/// file. Load one with `Scene.load(path)` (TOML, Mitsuba XML, a mesh file's scene or
/// `gen:NAME`) or `Scene.from_toml(text)`; `render(...)` renders it.
#[pyclass(module = "rt_renderer")]
pub struct Scene {
    /// The scene and its `[render]` table, as loaded and changed since.
    pub loaded: LoadedScene,
    /// The file it was read from (named in messages, and the job's scene).
    pub path: PathBuf,
    /// What the loader read (for the content hash of checkpoints).
    pub access: FileAccess,
}

#[pymethods]
impl Scene {
    /// Loads a TOML scene, a Mitsuba XML scene (`defines`: its `$name` parameters),
    /// `gen:NAME`, or a bare mesh file (`.obj`, `.ply`, ...: its triangles under a grey
    /// material, as `render bench-accel` reads it); `confine` refuses files outside that
    /// directory.
    #[staticmethod]
    #[pyo3(signature = (path, defines=None, confine=None))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        defines: Option<Bound<'_, PyDict>>,
        confine: Option<PathBuf>,
    ) -> PyResult<Scene> {
        let defines: Vec<(String, String)> = match defines {
            Some(d) => d
                .iter()
                .map(|(k, v)| Ok((k.extract()?, v.str()?.to_string())))
                .collect::<PyResult<_>>()?,
            None => Vec::new(),
        };
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        if rt_scene::MESH_EXTENSIONS.contains(&ext.as_str()) && confine.is_none() {
            // A bare mesh, as `render bench-accel` reads one: one grey material, a white
            // sky and a placeholder camera.
            let loaded = py.detach(|| rt_scene::load_mesh(&path)).map_err(rt_err)?;
            return Ok(Scene {
                loaded,
                path,
                access: FileAccess::open(),
            });
        }
        let loaded = py
            .detach(|| rt_session::load_scene(&path, confine.as_deref(), &defines))
            .map_err(rt_err)?;
        Ok(Scene {
            loaded: loaded.loaded,
            path,
            access: loaded.access,
        })
    }

    /// A scene from TOML text (docs/scene-format.md); relative file names in it are resolved
    /// against `base_dir`, and `name` stands for the file in messages.
    #[staticmethod]
    #[pyo3(signature = (text, base_dir=None, name=None))]
    fn from_toml(text: &str, base_dir: Option<PathBuf>, name: Option<PathBuf>) -> PyResult<Scene> {
        let base = base_dir.unwrap_or_else(|| PathBuf::from("."));
        let name = name.unwrap_or_else(|| PathBuf::from("<python>.toml"));
        let loaded = rt_scene::load_str(text, &base, &name).map_err(rt_err)?;
        Ok(Scene {
            loaded,
            path: name,
            access: FileAccess::open(),
        })
    }

    /// The loader's remarks (zero-area triangles, unused materials, ...), one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.warnings.clone()
    }

    /// The file the scene came from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// Number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.loaded.scene.triangle_count()
    }

    /// The cameras' names, in file order (the first renders by default).
    #[getter]
    fn cameras(&self) -> Vec<String> {
        self.loaded
            .scene
            .cameras
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// The objects' names (one per `[[geometry]]` or instance), in triangle order.
    #[getter]
    fn objects(&self) -> Vec<String> {
        self.loaded
            .scene
            .objects
            .iter()
            .map(|o| o.name.clone())
            .collect()
    }

    /// The world-space triangles as a `(n, 3, 3)` float32 array (triangle, corner, xyz).
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t = &self.loaded.scene.triangles;
        let flat: Vec<f32> = t.iter().flatten().flat_map(|v| v.to_array()).collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([t.len(), 3, 3])?
            .into_any())
    }

    /// A camera's settings as a dict (`None`: the first camera).
    #[pyo3(signature = (name=None))]
    fn camera<'py>(&self, py: Python<'py>, name: Option<&str>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.find_camera(name)?;
        let d = PyDict::new(py);
        d.set_item("name", &c.name)?;
        d.set_item("position", c.position.to_array())?;
        d.set_item("forward", c.forward.to_array())?;
        d.set_item("up", c.up.to_array())?;
        d.set_item("fov", c.fov_y_deg)?;
        d.set_item("resolution", (c.width, c.height))?;
        d.set_item("aperture", c.aperture)?;
        d.set_item("focus_distance", c.focus_distance)?;
        Ok(d)
    }

    /// Moves or changes a camera (`None`: the first) in place; what is not given stays.
    /// `look_at` and `up` default to the current view; the next render sees the change.
    #[pyo3(signature = (name=None, position=None, look_at=None, up=None, fov=None, resolution=None, aperture=None, focus_distance=None))]
    #[allow(clippy::too_many_arguments)]
    fn set_camera(
        &mut self,
        name: Option<&str>,
        position: Option<[f32; 3]>,
        look_at: Option<[f32; 3]>,
        up: Option<[f32; 3]>,
        fov: Option<f32>,
        resolution: Option<(u32, u32)>,
        aperture: Option<f32>,
        focus_distance: Option<f32>,
    ) -> PyResult<()> {
        let old = self.find_camera(name)?.clone();
        let position = position.map_or(old.position, Vec3::from);
        let target = look_at.map_or(position + old.forward, Vec3::from);
        let up = up.map_or(old.up, Vec3::from);
        let fov = fov.unwrap_or(old.fov_y_deg);
        let (width, height) = resolution.unwrap_or((old.width, old.height));
        let aperture = aperture.unwrap_or(old.aperture);
        let focus = focus_distance.unwrap_or(old.focus_distance);
        let what = format!("camera \"{}\"", old.name);
        let finite = [position, target, up].iter().all(|v| v.is_finite());
        if !finite {
            return Err(value_err(format!(
                "{what}: position, look_at and up must be finite"
            )));
        }
        let dir = target - position;
        if dir.length() == 0.0 {
            return Err(value_err(format!("{what}: look_at equals position")));
        }
        if up.length() == 0.0 || dir.normalize().cross(up.normalize()).length() < 1e-6 {
            return Err(value_err(format!(
                "{what}: up is zero or parallel to the view direction"
            )));
        }
        if !(fov > 0.0 && fov < 180.0) {
            return Err(value_err(format!(
                "{what}: fov must be in (0, 180) degrees, got {fov}"
            )));
        }
        let max = rt_session::MAX_SIDE;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(value_err(format!(
                "{what}: resolution must be between 1 and {max} on each side, got {width}x{height}"
            )));
        }
        if !(aperture.is_finite() && aperture >= 0.0 && focus.is_finite() && focus > 0.0) {
            return Err(value_err(format!(
                "{what}: aperture must be >= 0 and focus_distance > 0"
            )));
        }
        let mut camera = Camera::look_at(
            old.name.clone(),
            position,
            target,
            up,
            fov,
            width,
            height,
            aperture,
            focus,
        );
        camera.filter = old.filter;
        let slot = self.camera_index(name)?;
        self.loaded.scene.cameras[slot] = camera;
        Ok(())
    }

    /// Applies the affine `matrix` (4x4, row-major, last row `0 0 0 1`) to the object named
    /// `name` where it is now (its positions, and its normals by the inverse transpose); the
    /// next render sees it moved. Objects of `[[instance]]`s move with their animation instead.
    fn transform(&mut self, name: &str, matrix: &Bound<'_, PyAny>) -> PyResult<()> {
        let m = f32_array(matrix, "matrix")?;
        let m = rows(&m, 4, "matrix")?;
        if m.len() != 16 || m[12..] != [0.0, 0.0, 0.0, 1.0] || m.iter().any(|v| !v.is_finite()) {
            return Err(value_err(
                "matrix: expected a finite 4x4 affine matrix with last row [0, 0, 0, 1]",
            ));
        }
        let m = Mat4::from_cols_slice(m).transpose();
        if m.determinant().abs() < 1e-12 {
            return Err(value_err("matrix: not invertible"));
        }
        let scene = &mut self.loaded.scene;
        let Some(object) = scene.objects.iter().find(|o| o.name == name) else {
            let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            return Err(value_err(format!(
                "{}: no object \"{name}\" (objects: {})",
                self.path.display(),
                names.join(", ")
            )));
        };
        let range = object.first as usize..(object.first + object.count) as usize;
        if range.clone().any(|i| scene.instance_of(i as u32).is_some()) {
            return Err(value_err(format!(
                "{}: \"{name}\" is an instance: it is placed by its [[instance]] and [[animation]]",
                self.path.display()
            )));
        }
        let normal_matrix = m.inverse().transpose();
        // A mirroring map would turn front faces into back faces: reverse the winding, as the
        // scene loader does for a mirroring `transform`.
        let mirrors = m.determinant() < 0.0;
        for i in range {
            let t = &mut scene.triangles[i];
            *t = t.map(|p| m.transform_point3(p));
            if let Some(Some(n)) = scene.normals.get_mut(i) {
                *n = n.map(|v| normal_matrix.transform_vector3(v).normalize_or_zero());
            }
            if mirrors {
                scene.triangles[i].swap(1, 2);
                if let Some(Some(n)) = scene.normals.get_mut(i) {
                    n.swap(1, 2);
                }
                if let Some(Some(uv)) = scene.uvs.get_mut(i) {
                    uv.swap(1, 2);
                }
            }
        }
        // Emitters may have moved.
        scene.build_lights();
        Ok(())
    }

    /// Renders the scene as `render SCENE -o OUT.exr` with the same settings would, and
    /// returns the EXR's channels as float32 arrays (`"image"` and each AOV; see the module
    /// `rt_renderer`'s doc): the same bits. Settings not given come from the scene's
    /// `[render]` table, then the defaults. `progress(fraction)` is called on this thread as
    /// the render advances; Ctrl-C stops the render at the next pass and raises
    /// `KeyboardInterrupt`. `frames=range(a, b)` renders frames of the animation and returns
    /// a list of frame dicts (a temporal `denoiser`, `"svgf"`, carries its history across
    /// them); `frame=F` renders one; `gree="fraction=0.875"` (`""`: the defaults) denoises by
    /// GREE with the filter bank file `bank`, as `render --gree` does. `inputs=True` adds to
    /// each frame dict, under `"input"`, what the denoiser read (the noisy channels, sample
    /// records, guide buffers and further samples): `denoise(input, denoiser)`, or
    /// `denoise_sequence` over the frames' inputs, gives the frame's image again.
    #[pyo3(signature = (spp=None, integrator=None, accel=None, seed=None, error=None, time_limit=None, aovs=None, threads=None, denoiser=None, camera=None, max_depth=None, size=None, frames=None, frame=None, gree=None, bank=None, inputs=false, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        spp: Option<u32>,
        integrator: Option<String>,
        accel: Option<String>,
        seed: Option<u64>,
        error: Option<f32>,
        time_limit: Option<f64>,
        aovs: Option<Vec<String>>,
        threads: Option<usize>,
        denoiser: Option<String>,
        camera: Option<String>,
        max_depth: Option<u32>,
        size: Option<(u32, u32)>,
        frames: Option<Bound<'py, PyAny>>,
        frame: Option<u32>,
        gree: Option<String>,
        bank: Option<PathBuf>,
        inputs: bool,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frames = frames.map(|f| frame_range(&f)).transpose()?;
        let args = crate::render::RenderArgs {
            spp,
            integrator,
            accel,
            seed,
            error,
            time_limit,
            aovs,
            threads,
            denoiser,
            camera,
            max_depth,
            size,
            frames,
            frame,
            gree,
            bank,
            inputs,
        };
        crate::render::render(py, self, &args, progress)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}: {} triangles, cameras {:?})",
            self.path.display().to_string(),
            self.loaded.scene.triangle_count(),
            self.cameras()
        )
    }
}

/// `frames=`: a `range` of step 1 or a pair `(a, b)`, as `a..b`.
fn frame_range(obj: &Bound<'_, PyAny>) -> PyResult<std::ops::Range<u32>> {
    let bad = || value_err("frames: expected range(a, b) or (a, b) with 0 <= a < b");
    let (a, b): (i64, i64) = match obj.extract::<(i64, i64)>() {
        Ok(pair) => pair,
        Err(_) => {
            let step: i64 = obj.getattr("step").map_err(|_| bad())?.extract()?;
            if step != 1 {
                return Err(value_err("frames: a range of step 1"));
            }
            (
                obj.getattr("start")?.extract()?,
                obj.getattr("stop")?.extract()?,
            )
        }
    };
    match (u32::try_from(a), u32::try_from(b)) {
        (Ok(a), Ok(b)) if a < b => Ok(a..b),
        _ => Err(bad()),
    }
}

impl Scene {
    fn camera_index(&self, name: Option<&str>) -> PyResult<usize> {
        let cameras = &self.loaded.scene.cameras;
        match name {
            None if !cameras.is_empty() => Ok(0),
            _ => {
                let c = rt_session::pick_camera(&self.loaded.scene, &self.path, name)
                    .map_err(rt_err)?;
                Ok(cameras.iter().position(|k| k.name == c.name).unwrap_or(0))
            }
        }
    }

    fn find_camera(&self, name: Option<&str>) -> PyResult<&Camera> {
        rt_session::pick_camera(&self.loaded.scene, &self.path, name).map_err(rt_err)
    }

    /// The scene path as the job names it.
    pub fn job_path(&self) -> &Path {
        &self.path
    }
}
