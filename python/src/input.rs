//! A denoiser's input as a dict of NumPy arrays and back: what `rt.denoise` and
//! `rt.denoise_sequence` read, and what `Scene.render(inputs=True)` hands over
//! (`rt_session::JobSink::denoiser_input`), so that a rendered frame can be denoised again
//! from its arrays with the same bits.
//!
//! The dict is a frame dict (`arrays.rs`: `"image"` the noisy colour, the AOV channel groups)
//! with three entries that are not channels:
//!
//! - `"samples"`: the sample records SBMF reads (`rt_film::SampleRecords`), a dict of
//!   `"pixel"` `(n,)` uint32 (row-major pixel index), `"radiance"`, `"normal"`, `"position"`,
//!   `"albedo"` `(n, 3)` and `"coc"` `(n,)`; samples of a pixel in sample order.
//! - `"guides"`: the guide buffers SVGF reads (`rt_film::GuideBuffers`), a dict of
//!   `(height, width)`, `(height, width, 2)` or `(height, width, 3)` arrays named as the
//!   struct's fields ([`GUIDES`]), `"reflected"` a dict of its own ([`REFLECTED`]).
//! - `"extra"`: samples 1, 2, ... of every pixel as one-sample frame dicts, when a denoiser that
//!   samples with guide rays (SVGF) rendered more than one sample per pixel
//!   (`rt_temporal::TemporalFrame::extra`).
//!
//! Every value round-trips bit for bit. Arrays are checked here, each named in the error
//! (`frames[2]["guides"]["motion"]: shape ...`); what the arrays mean (finite values, a
//! channel the denoiser needs) is checked by the library.

use crate::arrays::{dict_to_frame, f32_array, frame_to_dict, u32_array};
use crate::{rt_err, value_err};
use glam::{Vec2, Vec3};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rt_core::Image;
use rt_film::{GuideBuffers, NoisyFrame, ReflectedGuides, Sample, SampleRecords};
use rt_temporal::TemporalFrame;

/// Keys of a frame dict that are not channels.
pub const NOT_CHANNELS: [&str; 3] = ["samples", "guides", "extra"];

/// The entries of `"guides"`: `(height, width)` arrays `depth`, `previous_depth`,
/// `roughness` (float32), `object` and `instance` (uint32), `(height, width, 2)` `motion`,
/// `(height, width, 3)` the rest, and the dict `reflected` (optional).
pub const GUIDES: [&str; 11] = [
    "depth",
    "position",
    "normal",
    "albedo",
    "emission",
    "motion",
    "previous_depth",
    "object",
    "instance",
    "roughness",
    "reflected",
];

/// The entries of `guides["reflected"]`: `distance` `(height, width)`, the rest
/// `(height, width, 3)`.
pub const REFLECTED: [&str; 6] = [
    "position",
    "normal",
    "distance",
    "albedo",
    "direction",
    "emission",
];

/// A denoiser's input, owned: what a [`TemporalFrame`] borrows.
#[derive(Clone, Debug)]
pub struct Input {
    pub frame: NoisyFrame,
    pub guides: Option<GuideBuffers>,
    pub extra: Vec<NoisyFrame>,
}

impl Input {
    /// A copy of what the denoiser read.
    pub fn of(t: &TemporalFrame<'_>) -> Self {
        Self {
            frame: t.frame.clone(),
            guides: t.guides.cloned(),
            extra: t.extra.to_vec(),
        }
    }

    /// The input as the denoiser reads it.
    pub fn as_frame(&self) -> TemporalFrame<'_> {
        TemporalFrame {
            frame: &self.frame,
            guides: self.guides.as_ref(),
            extra: &self.extra,
        }
    }
}

/// `input` as a dict (see the module doc).
pub fn input_to_dict<'py>(py: Python<'py>, input: &Input) -> PyResult<Bound<'py, PyDict>> {
    let d = noisy_to_dict(py, &input.frame)?;
    if let Some(g) = &input.guides {
        d.set_item("guides", guides_to_dict(py, g)?)?;
    }
    if !input.extra.is_empty() {
        let extra = input
            .extra
            .iter()
            .map(|e| noisy_to_dict(py, e))
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("extra", PyList::new(py, extra)?)?;
    }
    Ok(d)
}

/// The dict `dict` as a denoiser's input; `what` names it in errors (`frames[3]`).
pub fn dict_to_input(dict: &Bound<'_, PyAny>, what: &str) -> PyResult<Input> {
    let dict = as_dict(dict, what)?;
    let frame = dict_to_noisy(&dict, what)?;
    let size = frame.colour.size();
    let guides = match dict.get_item("guides")? {
        Some(g) => Some(dict_to_guides(&g, &format!("{what}[\"guides\"]"), size)?),
        None => None,
    };
    let extra = match dict.get_item("extra")? {
        Some(list) => list
            .try_iter()
            .map_err(|_| value_err(format!("{what}[\"extra\"]: expected a list of frame dicts")))?
            .enumerate()
            .map(|(k, e)| {
                let what = format!("{what}[\"extra\"][{k}]");
                dict_to_noisy(&as_dict(&e?, &what)?, &what)
            })
            .collect::<PyResult<Vec<_>>>()?,
        None => Vec::new(),
    };
    Ok(Input {
        frame,
        guides,
        extra,
    })
}

fn as_dict<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyDict>> {
    obj.cast::<PyDict>()
        .cloned()
        .map_err(|_| value_err(format!("{what}: expected a dict of arrays")))
}

/// A noisy frame's channels and sample records as a dict.
fn noisy_to_dict<'py>(py: Python<'py>, frame: &NoisyFrame) -> PyResult<Bound<'py, PyDict>> {
    let d = frame_to_dict(py, frame.exr_image(&[]).map_err(rt_err)?)?;
    if let Some(s) = &frame.samples {
        let r = PyDict::new(py);
        r.set_item("pixel", PyArray1::from_slice(py, s.pixel()))?;
        for (key, v) in [
            ("radiance", s.radiance()),
            ("normal", s.normal()),
            ("position", s.position()),
            ("albedo", s.albedo()),
        ] {
            r.set_item(key, array(py, vec3s(v), &[v.len(), 3])?)?;
        }
        r.set_item("coc", PyArray1::from_slice(py, s.coc()))?;
        d.set_item("samples", r)?;
    }
    Ok(d)
}

/// A frame dict's channels and sample records as a noisy frame.
fn dict_to_noisy(dict: &Bound<'_, PyDict>, what: &str) -> PyResult<NoisyFrame> {
    let channels = dict.copy()?;
    for key in NOT_CHANNELS {
        if channels.contains(key)? {
            channels.del_item(key)?;
        }
    }
    let exr = dict_to_frame(&channels, what)?;
    let mut frame = NoisyFrame::from_exr_image(&exr).map_err(|e| rt_err(format!("{what}: {e}")))?;
    if let Some(records) = dict.get_item("samples")? {
        let what = format!("{what}[\"samples\"]");
        let (w, h) = frame.colour.size();
        frame.samples = Some(dict_to_records(&as_dict(&records, &what)?, &what, w, h)?);
    }
    Ok(frame)
}

/// `(n,)` and `(n, 3)` arrays as sample records of a `w × h` image.
fn dict_to_records(
    d: &Bound<'_, PyDict>,
    what: &str,
    w: usize,
    h: usize,
) -> PyResult<SampleRecords> {
    refuse_unknown(
        d,
        what,
        &["pixel", "radiance", "normal", "position", "albedo", "coc"],
    )?;
    let get = |key: &str| {
        d.get_item(key)?
            .ok_or_else(|| value_err(format!("{what}: no \"{key}\" array")))
    };
    let pixel = u32_array(&get("pixel")?, &format!("{what}[\"pixel\"]"))?;
    let n = pixel.len();
    let pixel = check_shape(&pixel, &format!("{what}[\"pixel\"]"), &[n])?;
    let column = |key: &str, k: usize| -> PyResult<Vec<f32>> {
        let name = format!("{what}[\"{key}\"]");
        let a = f32_array(&get(key)?, &name)?;
        let shape: &[usize] = if k == 1 { &[n] } else { &[n, k] };
        Ok(check_shape(&a, &name, shape)?.to_vec())
    };
    let [radiance, normal, position, albedo] =
        ["radiance", "normal", "position", "albedo"].map(|k| column(k, 3));
    let (radiance, normal, position, albedo) = (radiance?, normal?, position?, albedo?);
    let coc = column("coc", 1)?;
    let at = |v: &[f32], i: usize| Vec3::from_slice(&v[3 * i..3 * i + 3]);
    let samples: Vec<Sample> = (0..n)
        .map(|i| Sample {
            pixel: pixel[i],
            radiance: at(&radiance, i),
            normal: at(&normal, i),
            position: at(&position, i),
            albedo: at(&albedo, i),
            coc: coc[i],
        })
        .collect();
    let side =
        |v: usize| u32::try_from(v).map_err(|_| value_err(format!("{what}: image too large")));
    SampleRecords::from_samples(side(w)?, side(h)?, &samples)
        .map_err(|e| value_err(format!("{what}: {e}")))
}

/// The guide buffers as a dict of arrays.
fn guides_to_dict<'py>(py: Python<'py>, g: &GuideBuffers) -> PyResult<Bound<'py, PyDict>> {
    let (w, h) = g.size();
    let d = PyDict::new(py);
    let three = |img: &Image<Vec3>| array(py, vec3s(img.pixels()), &[h, w, 3]);
    let one = |img: &Image<f32>| array(py, img.pixels().to_vec(), &[h, w]);
    d.set_item("depth", one(&g.depth)?)?;
    d.set_item("position", three(&g.position)?)?;
    d.set_item("normal", three(&g.normal)?)?;
    d.set_item("albedo", three(&g.albedo)?)?;
    d.set_item("emission", three(&g.emission)?)?;
    let motion = g
        .motion
        .pixels()
        .iter()
        .flat_map(|m| m.to_array())
        .collect();
    d.set_item("motion", array(py, motion, &[h, w, 2])?)?;
    d.set_item("previous_depth", one(&g.previous_depth)?)?;
    d.set_item("object", array(py, g.object.pixels().to_vec(), &[h, w])?)?;
    d.set_item(
        "instance",
        array(py, g.instance.pixels().to_vec(), &[h, w])?,
    )?;
    d.set_item("roughness", one(&g.roughness)?)?;
    if let Some(r) = &g.reflected {
        let rd = PyDict::new(py);
        rd.set_item("position", three(&r.position)?)?;
        rd.set_item("normal", three(&r.normal)?)?;
        rd.set_item("distance", one(&r.distance)?)?;
        rd.set_item("albedo", three(&r.albedo)?)?;
        rd.set_item("direction", three(&r.direction)?)?;
        rd.set_item("emission", three(&r.emission)?)?;
        d.set_item("reflected", rd)?;
    }
    Ok(d)
}

/// A dict of guide arrays of a `size` frame as guide buffers.
fn dict_to_guides(
    obj: &Bound<'_, PyAny>,
    what: &str,
    size: (usize, usize),
) -> PyResult<GuideBuffers> {
    let d = as_dict(obj, what)?;
    refuse_unknown(&d, what, &GUIDES)?;
    let planes = Planes { d: &d, what, size };
    let reflected = match d.get_item("reflected")? {
        Some(r) => {
            let what = format!("{what}[\"reflected\"]");
            let d = as_dict(&r, &what)?;
            refuse_unknown(&d, &what, &REFLECTED)?;
            let p = Planes {
                d: &d,
                what: &what,
                size,
            };
            Some(ReflectedGuides {
                position: p.three("position")?,
                normal: p.three("normal")?,
                distance: p.one("distance")?,
                albedo: p.three("albedo")?,
                direction: p.three("direction")?,
                emission: p.three("emission")?,
            })
        }
        None => None,
    };
    Ok(GuideBuffers {
        depth: planes.one("depth")?,
        position: planes.three("position")?,
        normal: planes.three("normal")?,
        albedo: planes.three("albedo")?,
        emission: planes.three("emission")?,
        motion: planes.motion("motion")?,
        previous_depth: planes.one("previous_depth")?,
        object: planes.ids("object")?,
        instance: planes.ids("instance")?,
        roughness: planes.one("roughness")?,
        reflected,
    })
}

/// The per-pixel arrays of a dict, each of a frame's `size`.
struct Planes<'a, 'py> {
    d: &'a Bound<'py, PyDict>,
    what: &'a str,
    size: (usize, usize),
}

impl<'py> Planes<'_, 'py> {
    /// The array `key` (an error naming it if it is missing).
    fn get(&self, key: &str, k: usize) -> PyResult<(Bound<'py, PyAny>, String, Vec<usize>)> {
        let (w, h) = self.size;
        let shape = if k == 1 { vec![h, w] } else { vec![h, w, k] };
        let value = self.d.get_item(key)?.ok_or_else(|| {
            value_err(format!(
                "{}: no \"{key}\" array (expected shape {shape:?})",
                self.what
            ))
        })?;
        Ok((value, format!("{}[\"{key}\"]", self.what), shape))
    }

    fn floats(&self, key: &str, k: usize) -> PyResult<Vec<f32>> {
        let (value, name, shape) = self.get(key, k)?;
        let a = f32_array(&value, &name)?;
        Ok(check_shape(&a, &name, &shape)?.to_vec())
    }

    fn one(&self, key: &str) -> PyResult<Image<f32>> {
        self.image(self.floats(key, 1)?)
    }

    fn three(&self, key: &str) -> PyResult<Image<Vec3>> {
        let v = self.floats(key, 3)?;
        self.image(v.chunks_exact(3).map(Vec3::from_slice).collect())
    }

    fn motion(&self, key: &str) -> PyResult<Image<Vec2>> {
        let v = self.floats(key, 2)?;
        self.image(v.chunks_exact(2).map(Vec2::from_slice).collect())
    }

    fn ids(&self, key: &str) -> PyResult<Image<u32>> {
        let (value, name, shape) = self.get(key, 1)?;
        let a = u32_array(&value, &name)?;
        self.image(check_shape(&a, &name, &shape)?.to_vec())
    }

    fn image<T>(&self, pixels: Vec<T>) -> PyResult<Image<T>> {
        let (w, h) = self.size;
        Image::new(w, h, pixels).map_err(|e| value_err(format!("{}: {e}", self.what)))
    }
}

/// The values of `a`, refused unless its shape is `shape`.
fn check_shape<'a, T: numpy::Element>(
    a: &'a numpy::PyReadonlyArrayDyn<'_, T>,
    name: &str,
    shape: &[usize],
) -> PyResult<&'a [T]> {
    if a.shape() != shape {
        return Err(value_err(format!(
            "{name}: shape {:?}, expected {shape:?}",
            a.shape()
        )));
    }
    a.as_slice().map_err(|e| value_err(format!("{name}: {e}")))
}

/// Refuses a key of `d` not in `known` (a misspelt buffer would otherwise be ignored).
fn refuse_unknown(d: &Bound<'_, PyDict>, what: &str, known: &[&str]) -> PyResult<()> {
    for key in d.keys() {
        let key: String = key
            .extract()
            .map_err(|_| value_err(format!("{what}: keys must be names (str)")))?;
        if !known.contains(&key.as_str()) {
            return Err(value_err(format!(
                "{what}: unknown array \"{key}\" (expected {})",
                known.join(", ")
            )));
        }
    }
    Ok(())
}

fn vec3s(v: &[Vec3]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

/// `values` as an array of `shape`.
fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, values).reshape(shape)?.into_any())
}
