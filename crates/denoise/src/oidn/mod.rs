//! Intel Open Image Denoise (OIDN 2) as a bank member and a peer to measure against: its "RT"
//! filter, a pretrained U-Net, run on the CPU through the native library (Áfra, "Intel Open
//! Image Denoise", 2024; the network follows Ronneberger et al., "U-Net", MICCAI 2015).
//!
//! Only built with this crate's `oidn` feature. The library is loaded when the denoiser is
//! constructed: from `OIDN_LIB` if set, else by the system names `libOpenImageDenoise.so.2`
//! and `libOpenImageDenoise.so`; `tools/oidn/setup.sh` installs one (from the `pyoidn`
//! wheel) and prints its path. A missing library is [`DenoiseError::Native`] naming every
//! path tried.
//!
//! Deviations from calling OIDN directly: inputs are sanitised first (non-finite values
//! become 0, colour is clamped to be non-negative, or to [0, 1] with `hdr=off`, albedo to
//! [0, 1] and normals to [-1, 1], the ranges OIDN expects); albedo and normal are used only
//! when the frame has them (`aux=on`), and normal only together with albedo, as OIDN
//! requires. Outputs are deterministic for a given machine and thread count; across thread
//! counts OIDN's CPU device gives the same bits in our tests, but OIDN does not promise it.

#[allow(unsafe_code)] // the FFI: every unsafe block there has its SAFETY comment
mod ffi;

use crate::{DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use ffi::{Device, Quality, RtFilter, RtParams, RtShape};
use rt_core::{Image, Rgb, RgbImage};
use std::sync::{Mutex, PoisonError};

/// The environment variable naming the library file to load.
pub const OIDN_LIB_ENV: &str = "OIDN_LIB";

/// Library names the dynamic loader is asked for when `OIDN_LIB` is unset.
pub const OIDN_LIB_DEFAULTS: [&str; 2] = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

const NAME: &str = "oidn";

/// OIDN's quality/speed trade-off (`OIDNQuality`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OidnQuality {
    /// For interactive preview.
    Fast,
    /// For interactive final frames (on the CPU device OIDN 2.5 runs the high network: same
    /// bits as `High`).
    Balanced,
    /// For final frames (OIDN's default on the CPU).
    High,
}

impl OidnQuality {
    fn name(self) -> &'static str {
        match self {
            OidnQuality::Fast => "fast",
            OidnQuality::Balanced => "balanced",
            OidnQuality::High => "high",
        }
    }
}

/// The options of an [`Oidn`] denoiser.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OidnParams {
    /// Network size.
    pub quality: OidnQuality,
    /// Use the frame's albedo and normal when it has them.
    pub aux: bool,
    /// Colour is linear HDR (on) or display-referred in [0, 1] (off).
    pub hdr: bool,
    /// The auxiliary images are noise-free (OIDN then trusts them more). Ours are per-pixel
    /// means with noise at edges and behind glass, so the default is off.
    pub clean_aux: bool,
}

impl Default for OidnParams {
    fn default() -> Self {
        Self {
            quality: OidnQuality::High,
            aux: true,
            hdr: true,
            clean_aux: false,
        }
    }
}

/// The filter built for the last frame shape, and scratch buffers reused across frames of
/// that shape (so a bank run over many frames builds the network once).
struct Cached {
    filter: RtFilter,
    colour: Vec<f32>,
    albedo: Vec<f32>,
    normal: Vec<f32>,
    output: Vec<f32>,
}

/// OIDN's RT filter. Construction loads the library and creates a CPU device; the filter is
/// built for the first frame and rebuilt only when the frame's size or channels change.
pub struct Oidn {
    params: OidnParams,
    name: String,
    library: String,
    device: Device,
    cached: Mutex<Option<Cached>>,
}

impl std::fmt::Debug for Oidn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Oidn")
            .field("params", &self.params)
            .field("library", &self.library)
            .finish_non_exhaustive()
    }
}

impl Oidn {
    /// Loads the library (`OIDN_LIB`, else the default names) and creates a CPU device.
    pub fn new(params: OidnParams) -> Result<Self, DenoiseError> {
        let candidates: Vec<String> = match std::env::var(OIDN_LIB_ENV) {
            Ok(p) if !p.is_empty() => vec![p],
            _ => OIDN_LIB_DEFAULTS.map(String::from).to_vec(),
        };
        Self::with_library(params, &candidates, None)
    }

    /// Loads the first of `libraries` that loads (paths or names for the dynamic loader) and
    /// creates a CPU device with `threads` worker threads (`None`: one per core).
    pub fn with_library(
        params: OidnParams,
        libraries: &[String],
        threads: Option<usize>,
    ) -> Result<Self, DenoiseError> {
        let mut tried = Vec::new();
        for lib in libraries {
            match Device::cpu(lib, threads) {
                Ok(device) => {
                    return Ok(Self {
                        params,
                        name: Self::spec_name(params),
                        library: lib.clone(),
                        device,
                        cached: Mutex::new(None),
                    })
                }
                Err(e) => tried.push(format!("{lib} ({e})")),
            }
        }
        Err(DenoiseError::Native {
            denoiser: NAME,
            message: format!(
                "cannot load Open Image Denoise: tried {}; install it with tools/oidn/setup.sh \
                 and set {OIDN_LIB_ENV} to the path it prints",
                if tried.is_empty() {
                    "nothing".to_string()
                } else {
                    tried.join(", ")
                }
            ),
        })
    }

    /// From spec options: `quality=fast|balanced|high` (high), `aux=on|off` (on), `hdr=on|off`
    /// (on), `clean-aux=on|off` (off).
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let d = OidnParams::default();
        let quality = match o.pick("quality", &["fast", "balanced", "high"], "high")? {
            "fast" => OidnQuality::Fast,
            "balanced" => OidnQuality::Balanced,
            _ => OidnQuality::High,
        };
        Self::new(OidnParams {
            quality,
            aux: o.on_off("aux", d.aux)?,
            hdr: o.on_off("hdr", d.hdr)?,
            clean_aux: o.on_off("clean-aux", d.clean_aux)?,
        })
    }

    /// The library file or name that was loaded.
    pub fn library(&self) -> &str {
        &self.library
    }

    fn spec_name(p: OidnParams) -> String {
        let on = |b: bool| if b { "on" } else { "off" };
        format!(
            "{NAME}:quality={}:aux={}:hdr={}:clean-aux={}",
            p.quality.name(),
            on(p.aux),
            on(p.hdr),
            on(p.clean_aux)
        )
    }

    /// Denoises `frame`, or says why OIDN failed (out of memory, an unsupported CPU).
    pub fn try_filter(&self, frame: &NoisyFrame) -> Result<RgbImage, DenoiseError> {
        frame.check()?;
        let (w, h) = frame.colour.size();
        let albedo = frame.albedo.as_ref().filter(|_| self.params.aux);
        let normal = frame.normal.as_ref().filter(|_| albedo.is_some());
        let shape = RtShape {
            width: w,
            height: h,
            albedo: albedo.is_some(),
            normal: normal.is_some(),
        };
        let native = |message: String| DenoiseError::Native {
            denoiser: NAME,
            message,
        };
        // A panic cannot happen while the lock is held with a half-updated cache (the code
        // below does not panic), so a poisoned lock is safe to take over.
        let mut guard = self.cached.lock().unwrap_or_else(PoisonError::into_inner);
        if guard.as_ref().map(|c| c.filter.shape()) != Some(shape) {
            *guard = None; // release the old network before building the new one
            let n = 3 * w * h;
            let filter = RtFilter::new(&self.device, shape, self.rt_params()).map_err(native)?;
            *guard = Some(Cached {
                filter,
                colour: vec![0.0; n],
                albedo: vec![0.0; if shape.albedo { n } else { 0 }],
                normal: vec![0.0; if shape.normal { n } else { 0 }],
                output: vec![0.0; n],
            });
        }
        let Some(c) = guard.as_mut() else {
            return Err(native("no filter".into()));
        };
        let hi = if self.params.hdr { f32::MAX } else { 1.0 };
        pack(&frame.colour, &mut c.colour, 0.0, hi);
        if let Some(a) = albedo {
            pack(a, &mut c.albedo, 0.0, 1.0);
        }
        if let Some(nrm) = normal {
            pack(nrm, &mut c.normal, -1.0, 1.0);
        }
        let result = c.filter.execute(
            &c.colour,
            Some(c.albedo.as_slice()).filter(|_| shape.albedo),
            Some(c.normal.as_slice()).filter(|_| shape.normal),
            &mut c.output,
        );
        if let Err(e) = result {
            *guard = None; // a failed filter is not reused
            return Err(native(e));
        }
        let px = c
            .output
            .chunks_exact(3)
            .map(|p| Rgb::new(p[0], p[1], p[2]))
            .collect();
        Image::new(w, h, px).map_err(|e| native(e.to_string()))
    }

    fn rt_params(&self) -> RtParams {
        RtParams {
            quality: match self.params.quality {
                OidnQuality::Fast => Quality::Fast,
                OidnQuality::Balanced => Quality::Balanced,
                OidnQuality::High => Quality::High,
            },
            hdr: self.params.hdr,
            clean_aux: self.params.clean_aux,
        }
    }
}

/// Writes `img` into `out` as packed RGB floats, non-finite components as 0 and the rest
/// clamped to `[lo, hi]`.
fn pack(img: &Image<Rgb>, out: &mut [f32], lo: f32, hi: f32) {
    for (p, o) in img.pixels().iter().zip(out.chunks_exact_mut(3)) {
        for (v, o) in p.to_array().into_iter().zip(o) {
            *o = if v.is_finite() { v.clamp(lo, hi) } else { 0.0 };
        }
    }
}

impl Denoiser for Oidn {
    fn name(&self) -> &str {
        &self.name
    }

    /// The frame's colour denoised, or the colour unchanged if OIDN fails at run time (call
    /// [`Denoiser::denoise`] or [`Oidn::try_filter`] to get the error instead).
    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        self.try_filter(frame)
            .unwrap_or_else(|_| frame.colour.clone())
    }

    fn denoise(&self, frame: &NoisyFrame) -> Result<RgbImage, DenoiseError> {
        let mut out = self.try_filter(frame)?;
        for p in out.pixels_mut() {
            if !p.is_finite() {
                *p = Rgb::ZERO;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
