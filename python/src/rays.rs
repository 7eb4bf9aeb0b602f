//! Ray queries from NumPy: `Accel` builds any `rt_accel::AccelSpec` over an array of
//! triangles and traces arrays of rays on a thread pool, each chunk of rays read straight from
//! the arrays and answered straight into the result arrays (no per-ray Python work, no copy of
//! the rays), as `render bench-accel` traces its sets (`rt_accel::bench::measure::time`:
//! `par_chunks` of `CHUNK` rays, `closest_hit`/`any_hit` per ray).

use crate::arrays::{f32_array, rows, u32_array};
use crate::{rt_err, value_err};
use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use rt_accel::bench::measure::CHUNK;
use rt_accel::AccelSpec;
use rt_core::{Aabb, Ray};

/// `triangle` index of a ray that hit nothing.
pub const MISS: u32 = u32::MAX;

/// An acceleration structure over triangles, as `render --accel SPEC` would build it.
/// `Accel(triangles, spec="bvh8")` with `triangles` of shape `(n, 3, 3)`, or
/// `Accel(vertices, spec, indices=faces)` with `(v, 3)` vertices and `(n, 3)` indices.
#[pyclass(module = "rt_renderer", frozen)]
pub struct Accel {
    accel: Box<dyn rt_core::Accel>,
    spec: AccelSpec,
    triangles: usize,
    pool: rayon::ThreadPool,
}

#[pymethods]
impl Accel {
    #[new]
    #[pyo3(signature = (triangles, spec="bvh8", indices=None, threads=None))]
    fn new(
        py: Python<'_>,
        triangles: &Bound<'_, PyAny>,
        spec: &str,
        indices: Option<&Bound<'_, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Accel> {
        let parsed: AccelSpec = spec
            .parse()
            .map_err(|e| rt_err(format!("accel={spec}: {e}")))?;
        let tris = triangle_list(triangles, indices)?;
        let pool = rt_session::job::thread_pool(threads).map_err(rt_err)?;
        let accel = py
            .detach(|| pool.install(|| parsed.build(&tris)))
            .map_err(|e| rt_err(format!("accel={spec}: {e}")))?;
        Ok(Accel {
            accel,
            spec: parsed,
            triangles: tris.len(),
            pool,
        })
    }

    /// The structure's canonical spec (`bvh8`, `qbvh:evh=14`, ...).
    #[getter]
    fn spec(&self) -> String {
        self.spec.to_string()
    }

    /// Number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// Bytes the structure holds.
    #[getter]
    fn memory_bytes(&self) -> usize {
        self.accel.memory_bytes()
    }

    /// Worker threads of the queries.
    #[getter]
    fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Closest hits of the rays `origins[i] + t * directions[i]`, `t` in `(0, tmax]`
    /// (`tmax`: a number, an array of one per ray, or infinity). Returns a dict of arrays:
    /// `t` (float32, `inf` on a miss), `triangle` (uint32, `MISS` = 2^32-1 on a miss), `u`
    /// and `v` (float32 barycentric weights of the triangle's corners 1 and 2, 0 on a miss).
    #[pyo3(signature = (origins, directions, tmax=None))]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let rays = RayArrays::new(origins, directions, tmax)?;
        let n = rays.len();
        let (mut t, mut prim) = (vec![f32::INFINITY; n], vec![MISS; n]);
        let (mut u, mut v) = (vec![0.0f32; n], vec![0.0f32; n]);
        let rays = rays.view();
        py.detach(|| {
            self.pool.install(|| {
                t.par_chunks_mut(CHUNK)
                    .zip(prim.par_chunks_mut(CHUNK))
                    .zip(u.par_chunks_mut(CHUNK))
                    .zip(v.par_chunks_mut(CHUNK))
                    .enumerate()
                    .for_each(|(c, (((t, prim), u), v))| {
                        for k in 0..t.len() {
                            let i = c * CHUNK + k;
                            if let Some(h) =
                                self.accel.closest_hit(&rays.ray(i), rays.tmax(i), None)
                            {
                                (t[k], prim[k], u[k], v[k]) = (h.t, h.prim, h.b1, h.b2);
                            }
                        }
                    });
            })
        });
        let out = PyDict::new(py);
        out.set_item("t", PyArray1::from_vec(py, t))?;
        out.set_item("triangle", PyArray1::from_vec(py, prim))?;
        out.set_item("u", PyArray1::from_vec(py, u))?;
        out.set_item("v", PyArray1::from_vec(py, v))?;
        Ok(out)
    }

    /// Whether anything is hit with `t` in `(0, tmax]` (default: 1, the segment
    /// `origins[i]` to `origins[i] + directions[i]`, as shadow rays are traced), as a bool
    /// array.
    #[pyo3(signature = (origins, directions, tmax=None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let one = 1.0f32.into_pyobject(py)?.into_any();
        let rays = RayArrays::new(origins, directions, Some(tmax.unwrap_or(&one)))?;
        let mut hit = vec![false; rays.len()];
        let rays = rays.view();
        py.detach(|| {
            self.pool.install(|| {
                hit.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
                    for (k, o) in out.iter_mut().enumerate() {
                        let i = c * CHUNK + k;
                        *o = self.accel.any_hit(&rays.ray(i), rays.tmax(i), None, None);
                    }
                });
            })
        });
        Ok(PyArray1::from_vec(py, hit))
    }

    fn __repr__(&self) -> String {
        format!(
            "Accel({:?}, {} triangles, {} threads)",
            self.spec.to_string(),
            self.triangles,
            self.pool.current_num_threads()
        )
    }
}

/// Rays as NumPy arrays, held for the duration of a query.
struct RayArrays<'py> {
    origins: numpy::PyReadonlyArrayDyn<'py, f32>,
    directions: numpy::PyReadonlyArrayDyn<'py, f32>,
    tmax: Option<numpy::PyReadonlyArrayDyn<'py, f32>>,
}

/// Plain slices of [`RayArrays`], to cross into the worker threads.
#[derive(Clone, Copy)]
struct RayView<'a> {
    origins: &'a [f32],
    directions: &'a [f32],
    /// One per ray, or one for all.
    tmax: &'a [f32],
}

impl<'py> RayArrays<'py> {
    fn new(
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let a = RayArrays {
            origins: f32_array(origins, "origins")?,
            directions: f32_array(directions, "directions")?,
            tmax: tmax.map(|t| f32_array(t, "tmax")).transpose()?,
        };
        let o = rows(&a.origins, 3, "origins")?.len() / 3;
        let d = rows(&a.directions, 3, "directions")?.len() / 3;
        if o != d {
            return Err(value_err(format!(
                "origins has {o} rays, directions {d}: they must match"
            )));
        }
        if let Some(t) = &a.tmax {
            let len = t.len();
            if len != 1 && len != o {
                return Err(value_err(format!(
                    "tmax: {len} values for {o} rays (give one, or one per ray)"
                )));
            }
            let values = t.as_slice().map_err(|e| value_err(e.to_string()))?;
            if values.iter().any(|v| v.is_nan() || *v <= 0.0) {
                return Err(value_err(
                    "tmax: every value must be positive (inf allowed)",
                ));
            }
        }
        Ok(a)
    }

    fn len(&self) -> usize {
        self.origins.len() / 3
    }

    fn view(&self) -> RayView<'_> {
        const INF: [f32; 1] = [f32::INFINITY];
        RayView {
            // Shapes checked in `new`: contiguous.
            origins: self.origins.as_slice().unwrap_or_default(),
            directions: self.directions.as_slice().unwrap_or_default(),
            tmax: self
                .tmax
                .as_ref()
                .and_then(|t| t.as_slice().ok())
                .unwrap_or(&INF),
        }
    }
}

impl RayView<'_> {
    #[inline]
    fn ray(&self, i: usize) -> Ray {
        let (o, d) = (
            &self.origins[3 * i..3 * i + 3],
            &self.directions[3 * i..3 * i + 3],
        );
        Ray::new(Vec3::new(o[0], o[1], o[2]), Vec3::new(d[0], d[1], d[2]))
    }

    #[inline]
    fn tmax(&self, i: usize) -> f32 {
        if self.tmax.len() == 1 {
            self.tmax[0]
        } else {
            self.tmax[i]
        }
    }
}

/// The triangles of `triangles` (`(n, 3, 3)`), or of `vertices` indexed by `indices`.
fn triangle_list(
    triangles: &Bound<'_, PyAny>,
    indices: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<[Vec3; 3]>> {
    let points = f32_array(triangles, "triangles")?;
    let check_finite = |v: &[f32]| {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(value_err("triangles: every coordinate must be finite"))
        }
    };
    let p = |v: &[f32], i: usize| Vec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    match indices {
        None => {
            let shape = points.shape();
            if shape.len() != 3 || shape[1] != 3 || shape[2] != 3 {
                return Err(value_err(format!(
                    "triangles: shape {shape:?}, expected (n, 3, 3) (or (v, 3) vertices with indices=)"
                )));
            }
            let v = points.as_slice().map_err(|e| value_err(e.to_string()))?;
            check_finite(v)?;
            Ok((0..shape[0])
                .map(|t| [p(v, 3 * t), p(v, 3 * t + 1), p(v, 3 * t + 2)])
                .collect())
        }
        Some(indices) => {
            let v = rows(&points, 3, "vertices")?;
            check_finite(v)?;
            let faces = u32_array(indices, "indices")?;
            let f = rows(&faces, 3, "indices")?;
            let count = v.len() / 3;
            if let Some(bad) = f.iter().find(|&&i| i as usize >= count) {
                return Err(value_err(format!(
                    "indices: index {bad} out of range for {count} vertices"
                )));
            }
            Ok(f.chunks_exact(3)
                .map(|t| {
                    [
                        p(v, t[0] as usize),
                        p(v, t[1] as usize),
                        p(v, t[2] as usize),
                    ]
                })
                .collect())
        }
    }
}

/// `count` rays from `render bench-accel`'s uniform set over the box `lo`..`hi`
/// (`rt_accel::bench::uniform`: origins uniform in the box, unit directions uniform on the
/// sphere; a function of the seed and the ray index), as `(origins, directions)` arrays.
#[pyfunction]
#[pyo3(signature = (lo, hi, count, seed=0))]
pub fn uniform_rays<'py>(
    py: Python<'py>,
    lo: [f32; 3],
    hi: [f32; 3],
    count: usize,
    seed: u64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
    if !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all()) {
        return Err(value_err("lo and hi: finite corners with lo <= hi"));
    }
    let set = py.detach(|| rt_accel::bench::uniform(&Aabb::new(lo, hi), count, seed));
    let flat = |f: fn(&Ray) -> Vec3| -> Vec<f32> {
        set.rays.iter().flat_map(|r| f(r).to_array()).collect()
    };
    let origins = PyArray1::from_vec(py, flat(|r| r.origin)).reshape([count, 3])?;
    let dirs = PyArray1::from_vec(py, flat(|r| r.dir)).reshape([count, 3])?;
    Ok((origins.into_any(), dirs.into_any()))
}

/// The structure kinds `Accel` and `render --accel` take.
#[pyfunction]
pub fn accel_kinds() -> Vec<String> {
    rt_accel::AccelKind::ALL
        .iter()
        .map(|k| k.name().to_string())
        .collect()
}
