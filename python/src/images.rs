//! Images as NumPy arrays: denoising a frame with any `rt_denoise::DenoiserSpec` or a
//! sequence of frames with any `rt_temporal::TemporalSpec` (SVGF), comparing two images with
//! `render compare`'s metrics (`rt_metrics::compare`), reading an EXR as the renderer reads it,
//! and running a TOML experiment (`render experiment`).

use crate::arrays::{f32_array, frame_to_dict};
use crate::input::dict_to_input;
use crate::{rt_err, value_err};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rt_core::{Rgb, RgbImage};
use rt_denoise::DenoiserSpec;
use rt_temporal::TemporalSpec;
use std::path::PathBuf;

/// Denoises `frame` (a dict as `Scene.render` returns: `"image"` and the AOVs the denoiser
/// reads, `"samples"` for SBMF; `input.rs`) with `denoiser` (`"atrous"`, `"nlm:radius=5"`,
/// ...), as `render denoise` does, and returns the image as a `(height, width, 3)` float32
/// array.
#[pyfunction]
pub fn denoise<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    denoiser: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let built = built(denoiser, DenoiserSpec::build)?;
    let input = dict_to_input(frame, "frame")?;
    let image = py
        .detach(|| built.denoise(&input.frame))
        .map_err(|e| rt_err(format!("denoiser={denoiser}: {e}")))?;
    rgb_to_array(py, &image)
}

/// Denoises the frames of a sequence in order with `denoiser` (`"svgf"`, `"svgf:alpha=0.1"`,
/// or any single-frame spec, run on each frame alone), carrying a temporal denoiser's history
/// from frame to frame as `Scene.render(frames=..., denoiser=...)` does, and returns one
/// `(height, width, 3)` float32 array per frame. `frames` is any iterable of frame dicts
/// (`input.rs`: SVGF reads `"direct"`, `"indirect"`, `"emission"`, `"guides"` and, above one
/// sample per pixel, `"extra"`), taken one at a time.
#[pyfunction]
#[pyo3(signature = (frames, denoiser="svgf"))]
pub fn denoise_sequence<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    denoiser: &str,
) -> PyResult<Bound<'py, PyList>> {
    let mut built = built(denoiser, TemporalSpec::build)?;
    let iter = frames
        .try_iter()
        .map_err(|_| value_err("frames: expected a list (or any iterable) of frame dicts"))?;
    let out = PyList::empty(py);
    for (k, frame) in iter.enumerate() {
        let what = format!("frames[{k}]");
        let input = dict_to_input(&frame?, &what)?;
        // `push` checks these too; here the message can name the sample.
        for (j, e) in input.extra.iter().enumerate() {
            e.require(built.name(), &rt_temporal::EXTRA_SAMPLE_CHANNELS)
                .map_err(|e| rt_err(format!("{what}[\"extra\"][{j}]: {e}")))?;
        }
        let image = py
            .detach(|| built.push(&input.as_frame()))
            .map_err(|e| rt_err(format!("{what}: denoiser={denoiser}: {e}")))?;
        out.append(rgb_to_array(py, &image)?)?;
    }
    Ok(out)
}

/// `denoiser` parsed as a spec `S` and built by `build`; errors name the argument.
fn built<S, T, E>(denoiser: &str, build: impl FnOnce(&S) -> Result<T, E>) -> PyResult<T>
where
    S: std::str::FromStr,
    S::Err: std::fmt::Display,
    E: std::fmt::Display,
{
    let named = |e: &dyn std::fmt::Display| rt_err(format!("denoiser={denoiser}: {e}"));
    let spec: S = denoiser.parse().map_err(|e| named(&e))?;
    build(&spec).map_err(|e| named(&e))
}

/// The denoisers `denoise` and `Scene.render(denoiser=...)` take.
#[pyfunction]
pub fn denoisers() -> Vec<String> {
    rt_denoise::DenoiserKind::ALL
        .iter()
        .map(|k| k.name().to_string())
        .collect()
}

/// `render compare`'s metrics of image `a` against the reference `b` (both `(height, width,
/// 3)`): a dict of `mse`, `relmse`, `rmse`, `psnr` and `ssim` (definitions in
/// docs/experiments.md), with relMSE's `epsilon` and PSNR's `peak`.
#[pyfunction]
#[pyo3(signature = (a, b, epsilon=rt_metrics::DEFAULT_EPSILON, peak=rt_metrics::DEFAULT_PEAK))]
pub fn compare<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    epsilon: f64,
    peak: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (array_to_rgb(a, "a")?, array_to_rgb(b, "b")?);
    let opts = rt_metrics::CompareOptions { epsilon, peak };
    let m = py
        .detach(|| rt_metrics::compare(&a, &b, &opts))
        .map_err(rt_err)?;
    let d = PyDict::new(py);
    d.set_item("mse", m.mse)?;
    d.set_item("relmse", m.relmse)?;
    d.set_item("rmse", m.rmse)?;
    d.set_item("psnr", m.psnr)?;
    d.set_item("ssim", m.ssim)?;
    Ok(d)
}

/// Every channel of an EXR file, read as the renderer reads it (`rt_film::read_exr`), as a
/// frame dict (`"image"`, the AOV groups, single channels).
#[pyfunction]
pub fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let exr = py.detach(|| rt_film::read_exr(&path)).map_err(rt_err)?;
    frame_to_dict(py, exr)
}

/// Runs the experiment `config` as `render experiment` does, writing into `out` (default: the
/// config's own output folder) with references cached in `cache`; returns the output folder
/// (its `results.csv` holds one row per run).
#[pyfunction]
#[pyo3(signature = (config, out=None, cache=None, threads=None, confine=None))]
pub fn run_experiment(
    py: Python<'_>,
    config: PathBuf,
    out: Option<PathBuf>,
    cache: Option<PathBuf>,
    threads: Option<usize>,
    confine: Option<PathBuf>,
) -> PyResult<PathBuf> {
    py.detach(|| {
        let plan =
            rt_experiment::config::load_confined(&config, confine.as_deref()).map_err(rt_err)?;
        let pool = rt_session::job::thread_pool(threads).map_err(rt_err)?;
        let out = out.unwrap_or_else(|| rt_experiment::default_out_dir(&plan));
        rt_experiment::prepare_out(&out).map_err(rt_err)?;
        let cache = rt_experiment::Cache::new(
            &cache.unwrap_or_else(|| PathBuf::from(rt_experiment::DEFAULT_CACHE_DIR)),
        );
        pool.install(|| rt_experiment::run(&plan, &out, &cache, &rt_experiment::Silent))
            .map_err(rt_err)?;
        Ok(out)
    })
}

/// A `(height, width, 3)` array as an image; `what` names the argument.
fn array_to_rgb(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<RgbImage> {
    let array = f32_array(obj, what)?;
    let shape = array.shape().to_vec();
    let [h, w, 3] = shape[..] else {
        return Err(value_err(format!(
            "{what}: shape {shape:?}, expected (height, width, 3)"
        )));
    };
    let v = array.as_slice().map_err(|e| value_err(e.to_string()))?;
    let pixels = v
        .chunks_exact(3)
        .map(|p| Rgb::new(p[0], p[1], p[2]))
        .collect();
    RgbImage::new(w, h, pixels).map_err(|e| value_err(format!("{what}: {e}")))
}

/// An image as a `(height, width, 3)` float32 array.
fn rgb_to_array<'py>(py: Python<'py>, image: &RgbImage) -> PyResult<Bound<'py, PyAny>> {
    let v: Vec<f32> = image.pixels().iter().flat_map(|p| p.to_array()).collect();
    Ok(PyArray1::from_vec(py, v)
        .reshape([image.height(), image.width(), 3])?
        .into_any())
}
