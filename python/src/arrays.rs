//! NumPy arrays in and out: a frame's named EXR channels as a dict of arrays and back, and
//! arrays of any real dtype taken as contiguous `float32` or `uint32`.
//!
//! A frame is a dict: `"image"` the beauty image (`R`, `G`, `B`), then one entry per channel
//! group of the EXR the CLI writes (`"albedo"`, `"normal"`, `"variance"`, `"even"`, ...), each
//! `(height, width, 3)` in the file's component order (`R, G, B` or `X, Y, Z`), and one
//! `(height, width)` array per single channel (`"depth"` for `depth.Z`; `"blocks.spp"`, ...).
//! The values are the file's, bit for bit.

use crate::value_err;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rt_film::output::ExrImage;

/// Key of the beauty image in a frame dict.
pub const IMAGE: &str = "image";

/// Channel groups whose components are `X, Y, Z` in files (`rt_film::NoisyFrame`'s layout);
/// every other three-component group is `R, G, B`.
const XYZ_GROUPS: [&str; 4] = ["normal", "normal_variance", "position", "position_variance"];
/// Single channels stored as `NAME.Z` in files.
const Z_CHANNELS: [&str; 2] = ["depth", "depth_variance"];

/// The components of a three-component group.
fn components(group: &str) -> [&'static str; 3] {
    if XYZ_GROUPS.contains(&group) {
        ["X", "Y", "Z"]
    } else {
        ["R", "G", "B"]
    }
}

/// `exr`'s channels as a frame dict (see the module doc).
pub fn frame_to_dict<'py>(py: Python<'py>, mut exr: ExrImage) -> PyResult<Bound<'py, PyDict>> {
    let (w, h) = (exr.width, exr.height);
    let dict = PyDict::new(py);
    let mut used = vec![false; exr.channels.len()];
    let mut groups: Vec<&str> = Vec::new();
    for (name, _) in &exr.channels {
        let group = name.rsplit_once('.').map_or("", |(g, _)| g);
        if !groups.contains(&group) {
            groups.push(group);
        }
    }
    for group in groups {
        let full = |c: &str| {
            if group.is_empty() {
                c.to_string()
            } else {
                format!("{group}.{c}")
            }
        };
        let found: Vec<Option<usize>> = components(group)
            .iter()
            .map(|c| exr.channels.iter().position(|(n, _)| *n == full(c)))
            .collect();
        if let [Some(a), Some(b), Some(c)] = found[..] {
            let (a, b, c) = (&exr.channels[a].1, &exr.channels[b].1, &exr.channels[c].1);
            let mut v = Vec::with_capacity(3 * a.len());
            for i in 0..a.len() {
                v.extend_from_slice(&[a[i], b[i], c[i]]);
            }
            let key = if group.is_empty() { IMAGE } else { group };
            dict.set_item(key, PyArray1::from_vec(py, v).reshape([h, w, 3])?)?;
            for k in found.into_iter().flatten() {
                used[k] = true;
            }
        }
    }
    for ((name, values), used) in exr.channels.iter_mut().zip(used) {
        if used {
            continue;
        }
        let key = name.strip_suffix(".Z").filter(|g| Z_CHANNELS.contains(g));
        let array = PyArray1::from_vec(py, std::mem::take(values)).reshape([h, w])?;
        dict.set_item(key.unwrap_or(name), array)?;
    }
    Ok(dict)
}

/// A frame dict (see the module doc) as EXR channels; `what` names the argument in errors.
pub fn dict_to_frame(frame: &Bound<'_, PyDict>, what: &str) -> PyResult<ExrImage> {
    let mut size: Option<(usize, usize)> = None;
    let mut channels = Vec::new();
    for (key, value) in frame.iter() {
        let key: String = key
            .extract()
            .map_err(|_| value_err(format!("{what}: keys must be channel names (str)")))?;
        let array = f32_array(&value, &format!("{what}[{key:?}]"))?;
        let shape = array.shape().to_vec();
        let (h, w) = match shape[..] {
            [h, w] | [h, w, 3] => (h, w),
            _ => {
                return Err(value_err(format!(
                "{what}[{key:?}]: shape {shape:?}, expected (height, width, 3) or (height, width)"
            )))
            }
        };
        match size {
            Some(s) if s != (w, h) => {
                return Err(value_err(format!(
                    "{what}[{key:?}]: {w}x{h} pixels, but other channels have {}x{}",
                    s.0, s.1
                )))
            }
            _ => size = Some((w, h)),
        }
        let values = array.as_slice().map_err(|e| value_err(e.to_string()))?;
        if shape.len() == 2 {
            let name = if Z_CHANNELS.contains(&key.as_str()) {
                format!("{key}.Z")
            } else {
                key.clone()
            };
            channels.push((name, values.to_vec()));
        } else {
            let group = if key == IMAGE { "" } else { key.as_str() };
            for (k, c) in components(group).iter().enumerate() {
                let name = if group.is_empty() {
                    c.to_string()
                } else {
                    format!("{group}.{c}")
                };
                channels.push((name, values.iter().skip(k).step_by(3).copied().collect()));
            }
        }
    }
    let Some((width, height)) = size else {
        return Err(value_err(format!(
            "{what}: an empty frame (it needs at least \"image\")"
        )));
    };
    Ok(ExrImage {
        width,
        height,
        channels,
    })
}

/// `obj` as a C-contiguous `float32` array (converted by NumPy if it is another real dtype or
/// layout); `what` names the argument in errors.
pub fn f32_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, f32>> {
    typed_array(obj, what, "float32")
}

/// `obj` as a C-contiguous `uint32` array; negative or fractional values are refused.
pub fn u32_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, u32>> {
    let np = obj.py().import("numpy")?;
    let raw = np.call_method1("asarray", (obj,))?;
    let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "i" | "u") {
        return Err(value_err(format!(
            "{what}: expected integers, got an array of dtype {}",
            raw.getattr("dtype")?.str()?
        )));
    }
    if raw.getattr("size")?.extract::<usize>()? > 0 {
        let min: i128 = raw.call_method0("min")?.extract()?;
        let max: i128 = raw.call_method0("max")?.extract()?;
        if min < 0 || max > i128::from(u32::MAX) {
            return Err(value_err(format!(
                "{what}: values must be in 0..2^32, found {min}..{max}"
            )));
        }
    }
    typed_array(&raw, what, "uint32")
}

fn typed_array<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    dtype: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    let np = obj.py().import("numpy")?;
    let kwargs = PyDict::new(obj.py());
    kwargs.set_item("dtype", dtype)?;
    let converted = np
        .call_method("ascontiguousarray", (obj,), Some(&kwargs))
        .map_err(|e| value_err(format!("{what}: not convertible to a {dtype} array: {e}")))?;
    let array = converted
        .cast_into::<numpy::PyArrayDyn<T>>()
        .map_err(|e| value_err(format!("{what}: {e}")))?;
    Ok(array.readonly())
}

/// The rows of an `(n, k)` array as a slice of `n * k` values, checking the shape; `what`
/// names the argument.
pub fn rows<'a, T: numpy::Element>(
    array: &'a PyReadonlyArrayDyn<'_, T>,
    k: usize,
    what: &str,
) -> PyResult<&'a [T]> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != k {
        return Err(value_err(format!(
            "{what}: shape {shape:?}, expected (n, {k})"
        )));
    }
    array
        .as_slice()
        .map_err(|e| value_err(format!("{what}: {e}")))
}
