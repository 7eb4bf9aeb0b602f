//! The part of Open Image Denoise's C API (`include/OpenImageDenoise/oidn.h`, version 2) that
//! [`super::Oidn`] calls, loaded from `libOpenImageDenoise` at run time, behind a safe
//! interface: a CPU [`Device`] and an "RT" [`RtFilter`] of fixed size that denoises
//! caller-owned `f32` RGB buffers. All of this crate's `unsafe` code is here.
//!
//! Loading at run time (`dlopen` via `libloading`) instead of linking keeps a build with the
//! `oidn` feature free of any native build step: a machine without the library builds and
//! runs, and only constructing the denoiser fails, with one error naming what was tried.
//!
//! Calls used: `oidnNewDevice(OIDN_DEVICE_TYPE_CPU)`, `oidnSetDeviceInt("numThreads")`,
//! `oidnCommitDevice`, `oidnGetDeviceError`, `oidnReleaseDevice`, `oidnNewFilter("RT")`,
//! `oidnSetSharedFilterImage` (`OIDN_FORMAT_FLOAT3`, tightly packed), `oidnSetFilterBool`
//! (`hdr`, `cleanAux`), `oidnSetFilterInt` (`quality`), `oidnCommitFilter`,
//! `oidnExecuteFilter`, `oidnReleaseFilter`.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::ptr::NonNull;
use std::sync::Arc;

/// `OIDNDeviceType::OIDN_DEVICE_TYPE_CPU`.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDNFormat::OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDNError::OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;

/// `OIDNQuality` values accepted by the RT filter's `quality` parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// `OIDN_QUALITY_FAST`.
    Fast = 4,
    /// `OIDN_QUALITY_BALANCED`.
    Balanced = 5,
    /// `OIDN_QUALITY_HIGH`.
    High = 6,
}

type Handle = *mut c_void;

/// The entry points, resolved once per load. The function-pointer types follow `oidn.h`: C
/// enums are `int`, C99 `bool` is Rust's `bool`, `size_t` is `usize`.
struct Api {
    new_device: unsafe extern "C" fn(c_int) -> Handle,
    set_device_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    commit_device: unsafe extern "C" fn(Handle),
    get_device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int,
    release_device: unsafe extern "C" fn(Handle),
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    #[allow(clippy::type_complexity)]
    set_shared_filter_image: unsafe extern "C" fn(
        Handle,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    set_filter_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
    release_filter: unsafe extern "C" fn(Handle),
    /// Declared last so that it is dropped (unloaded) after nothing can call through the
    /// pointers above.
    _lib: libloading::Library,
}

impl Api {
    /// Loads the library at `path` (a file path or a name the dynamic loader searches for) and
    /// resolves every entry point.
    fn load(path: &str) -> Result<Self, String> {
        // SAFETY: loading runs the library's initialisers. libOpenImageDenoise's (and those of
        // its dependencies, TBB and the OIDN core) only set up static state; nothing here is
        // run with assumptions the loader could break.
        let lib = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the field this initialises has the exact signature `oidn.h`
                // declares for this symbol (see the type comments on `Api`), and the pointer
                // is copied out of the `Symbol` but stays valid because `lib` is stored in
                // the same struct and dropped last.
                *unsafe { lib.get(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| format!("{path}: symbol {}: {e}", $name))?
            };
        }
        Ok(Self {
            new_device: sym!("oidnNewDevice"),
            set_device_int: sym!("oidnSetDeviceInt"),
            commit_device: sym!("oidnCommitDevice"),
            get_device_error: sym!("oidnGetDeviceError"),
            release_device: sym!("oidnReleaseDevice"),
            new_filter: sym!("oidnNewFilter"),
            set_shared_filter_image: sym!("oidnSetSharedFilterImage"),
            set_filter_bool: sym!("oidnSetFilterBool"),
            set_filter_int: sym!("oidnSetFilterInt"),
            commit_filter: sym!("oidnCommitFilter"),
            execute_filter: sym!("oidnExecuteFilter"),
            release_filter: sym!("oidnReleaseFilter"),
            _lib: lib,
        })
    }
}

/// The device and the library it came from; released when the last [`Device`] or
/// [`RtFilter`] using it goes.
struct DeviceInner {
    api: Api,
    raw: NonNull<c_void>,
}

// SAFETY: the OIDN API documentation states that all API calls are thread-safe (calls on one
// device are serialised by the library), so the device handle may be used and released from
// any thread. `Api` holds only function pointers and the library handle.
unsafe impl Send for DeviceInner {}
// SAFETY: as for `Send`: concurrent calls through `&DeviceInner` are allowed by OIDN.
unsafe impl Sync for DeviceInner {}

impl DeviceInner {
    /// The first error recorded on the device since the last query, clearing it.
    fn check(&self, what: &str) -> Result<(), String> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: `raw` is a live device of this library; `message` is a valid out-pointer.
        let code = unsafe { (self.api.get_device_error)(self.raw.as_ptr(), &mut message) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if message.is_null() {
            "no message".to_string()
        } else {
            // SAFETY: OIDN returns a NUL-terminated string owned by the device, valid until
            // the next call on it; it is copied out at once.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(format!("{what} failed (OIDN error {code}): {text}"))
    }
}

impl Drop for DeviceInner {
    fn drop(&mut self) {
        // SAFETY: `raw` is live and this is its only owner (every filter holds an `Arc` to
        // this value, so none outlives the release).
        unsafe { (self.api.release_device)(self.raw.as_ptr()) }
    }
}

/// A committed OIDN CPU device.
#[derive(Clone)]
pub struct Device(Arc<DeviceInner>);

impl Device {
    /// Loads the library at `path` and creates and commits a CPU device, with `threads` worker
    /// threads (`None`: OIDN's default, one per core).
    pub fn cpu(path: &str, threads: Option<usize>) -> Result<Self, String> {
        let api = Api::load(path)?;
        // SAFETY: `oidnNewDevice` takes a device type and returns a new handle or null.
        let raw = unsafe { (api.new_device)(DEVICE_TYPE_CPU) };
        let Some(raw) = NonNull::new(raw) else {
            return Err(format!(
                "{path}: oidnNewDevice(CPU) returned no device (CPU unsupported?)"
            ));
        };
        let inner = DeviceInner { api, raw };
        inner.check("oidnNewDevice(CPU)")?;
        if let Some(n) = threads {
            let n = c_int::try_from(n).map_err(|_| format!("{n} threads is too many"))?;
            // SAFETY: live device, NUL-terminated parameter name, plain int value.
            unsafe { (inner.api.set_device_int)(raw.as_ptr(), c"numThreads".as_ptr(), n) };
        }
        // SAFETY: live device, committed once before use as the API requires.
        unsafe { (inner.api.commit_device)(raw.as_ptr()) };
        inner.check("oidnCommitDevice")?;
        Ok(Self(Arc::new(inner)))
    }
}

/// What an [`RtFilter`] is built for; a frame of another shape needs another filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtShape {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Whether an albedo image is given.
    pub albedo: bool,
    /// Whether a normal image is given (OIDN accepts it only together with albedo).
    pub normal: bool,
}

/// The RT filter's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtParams {
    /// `quality`.
    pub quality: Quality,
    /// `hdr`: colour is linear HDR rather than in [0, 1].
    pub hdr: bool,
    /// `cleanAux`: the auxiliary images are noise-free.
    pub clean_aux: bool,
}

/// A committed "RT" filter of one [`RtShape`]. Images are bound afresh from the caller's
/// slices on every [`RtFilter::execute`], so no pointer the filter holds is ever used after
/// the slice it came from.
pub struct RtFilter {
    device: Device,
    raw: NonNull<c_void>,
    shape: RtShape,
}

// SAFETY: the filter handle may be used from any thread (OIDN API calls are thread-safe);
// `RtFilter` is not `Sync`, and `execute` takes `&mut self`, so one thread at a time binds
// images and runs it.
unsafe impl Send for RtFilter {}

impl RtFilter {
    /// Creates the filter on `device` and sets its parameters. It is committed on each
    /// [`RtFilter::execute`]: the first commit builds the network for the shape; later ones
    /// only take the new image pointers.
    pub fn new(device: &Device, shape: RtShape, params: RtParams) -> Result<Self, String> {
        if shape.normal && !shape.albedo {
            return Err("OIDN takes a normal image only together with albedo".into());
        }
        if shape.width == 0 || shape.height == 0 {
            return Err("OIDN cannot filter an empty image".into());
        }
        let d = &device.0;
        // SAFETY: live device, NUL-terminated filter type.
        let raw = unsafe { (d.api.new_filter)(d.raw.as_ptr(), c"RT".as_ptr()) };
        let Some(raw) = NonNull::new(raw) else {
            d.check("oidnNewFilter(RT)")?;
            return Err("oidnNewFilter(RT) returned no filter".into());
        };
        // Owned from here on, so an early return below releases it.
        let filter = Self {
            device: device.clone(),
            raw,
            shape,
        };
        let f = raw.as_ptr();
        // SAFETY: three calls on a live filter with NUL-terminated parameter names of the RT
        // filter and plain values.
        unsafe {
            (d.api.set_filter_bool)(f, c"hdr".as_ptr(), params.hdr);
            (d.api.set_filter_bool)(f, c"cleanAux".as_ptr(), params.clean_aux);
            (d.api.set_filter_int)(f, c"quality".as_ptr(), params.quality as c_int);
        }
        d.check("setting the RT filter's parameters")?;
        Ok(filter)
    }

    /// The shape this filter was built for.
    pub fn shape(&self) -> RtShape {
        self.shape
    }

    /// Denoises `colour` (with `albedo` and `normal` as the shape says) into `output`. Every
    /// slice holds `3 * width * height` floats, RGB per pixel, rows top to bottom.
    pub fn execute(
        &mut self,
        colour: &[f32],
        albedo: Option<&[f32]>,
        normal: Option<&[f32]>,
        output: &mut [f32],
    ) -> Result<(), String> {
        let s = self.shape;
        let n = 3 * s.width * s.height;
        let len_ok = |b: Option<&[f32]>, want: bool| match b {
            Some(b) => want && b.len() == n,
            None => !want,
        };
        if colour.len() != n
            || output.len() != n
            || !len_ok(albedo, s.albedo)
            || !len_ok(normal, s.normal)
        {
            return Err(format!(
                "buffers do not match the filter's shape {}x{} (albedo {}, normal {})",
                s.width, s.height, s.albedo, s.normal
            ));
        }
        let d = &self.device.0;
        let f = self.raw.as_ptr();
        let bind = |name: &CStr, ptr: *mut f32| {
            // SAFETY: live filter; `ptr` points at `n` = 3·width·height floats (checked
            // above), tightly packed FLOAT3 pixels (strides 0 = packed, offset 0). OIDN reads
            // the inputs and writes only the output, and only during the execute below,
            // while the borrows of the slices are held.
            unsafe {
                (d.api.set_shared_filter_image)(
                    f,
                    name.as_ptr(),
                    ptr.cast(),
                    FORMAT_FLOAT3,
                    s.width,
                    s.height,
                    0,
                    0,
                    0,
                )
            }
        };
        // OIDN's API takes `void*` for every image, inputs included; it never writes inputs.
        bind(c"color", colour.as_ptr().cast_mut());
        if let Some(a) = albedo {
            bind(c"albedo", a.as_ptr().cast_mut());
        }
        if let Some(nrm) = normal {
            bind(c"normal", nrm.as_ptr().cast_mut());
        }
        bind(c"output", output.as_mut_ptr());
        d.check("binding images")?;
        // SAFETY: live filter with every image bound to a buffer borrowed for this call.
        unsafe { (d.api.commit_filter)(f) };
        d.check("oidnCommitFilter")?;
        // SAFETY: as above; the call is synchronous, so OIDN is done with the buffers when it
        // returns.
        unsafe { (d.api.execute_filter)(f) };
        d.check("oidnExecuteFilter")
    }
}

impl Drop for RtFilter {
    fn drop(&mut self) {
        // SAFETY: `raw` is live and owned by this value alone; the device it came from is kept
        // alive by `self.device` until after this call.
        unsafe { (self.device.0.api.release_filter)(self.raw.as_ptr()) }
    }
}
