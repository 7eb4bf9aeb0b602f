//! Embree 4 through its C API, loaded at run time with `libloading` from the `libembree4.so.4`
//! given by `--embree-lib PATH` or `EMBREE_LIB` (the `embreex` wheel carries one:
//! `pip install embreex`, then `site-packages/embreex.libs/libembree4-*.so.4`).
//!
//! Embree 3 and 4 export the same symbol names with different signatures (`rtcIntersect1`
//! takes an intersect context in 3, optional arguments in 4), so one library is loaded per
//! process and its major version is checked before any query: only 4 is accepted.
//!
//! What is timed: the build is device creation (`threads=N` for the N-thread pool), one
//! triangle geometry with Embree-owned vertex and index buffers filled from our triangles,
//! and `rtcCommitScene` at the scene's default build quality (`embree`) or
//! `RTC_BUILD_QUALITY_HIGH` (`embree:high`); tracing is one `rtcIntersect1` /
//! `rtcOccluded1` per ray (single-ray API, no packets or streams, as for every other peer).
//!
//! Names: `embree`, `embree:high`.

use crate::peer::Peer;
use anyhow::{bail, Context, Result};
use libloading::Library;
use rt_core::glam::Vec3;
use rt_core::Ray;
use std::ffi::{c_char, c_int, c_uint, c_void, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

type Device = *mut c_void;
type Scene = *mut c_void;
type Geometry = *mut c_void;

const RTC_GEOMETRY_TYPE_TRIANGLE: c_int = 0;
const RTC_BUFFER_TYPE_INDEX: c_int = 0;
const RTC_BUFFER_TYPE_VERTEX: c_int = 1;
const RTC_FORMAT_UINT3: c_int = 0x5003;
const RTC_FORMAT_FLOAT3: c_int = 0x9003;
const RTC_BUILD_QUALITY_HIGH: c_int = 2;
const RTC_DEVICE_PROPERTY_VERSION: c_int = 0;
const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;

/// `struct RTC_ALIGN(16) RTCRay` of `embree4/rtcore_ray.h`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `struct RTC_ALIGN(16) RTCHit`: normal, barycentrics, primID and geomID at fixed offsets,
/// then `instID[RTC_MAX_INSTANCE_LEVEL_COUNT]` and, in builds with instance arrays,
/// `instPrimID[...]`. The tail is oversized so that any build's instance fields fit: Embree
/// only writes them, and we read primID and geomID only.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_tail: [u32; 17],
}

/// `struct RTC_ALIGN(16) RTCRayHit { RTCRay ray; RTCHit hit; }`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

/// `struct RTC_ALIGN(32) RTCRay8`: the fields of eight rays, structure of arrays.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct RtcRay8 {
    org: [[f32; 8]; 3],
    tnear: [f32; 8],
    dir: [[f32; 8]; 3],
    time: [f32; 8],
    tfar: [f32; 8],
    mask: [u32; 8],
    id: [u32; 8],
    flags: [u32; 8],
}

/// `struct RTC_ALIGN(32) RTCHit8`, with an oversized tail for the instance fields (as
/// [`RtcHit`]).
#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct RtcHit8 {
    ng: [[f32; 8]; 3],
    u: [f32; 8],
    v: [f32; 8],
    prim_id: [u32; 8],
    geom_id: [u32; 8],
    inst_tail: [[u32; 8]; 34],
}

/// `struct RTCRayHit8 { RTCRay8 ray; RTCHit8 hit; }`.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
struct RtcRayHit8 {
    ray: RtcRay8,
    hit: RtcHit8,
}

/// `valid` argument of the eight-wide queries: -1 for an active lane, 0 for an inactive one.
#[repr(C, align(32))]
struct Valid8([i32; 8]);

const _: () = assert!(std::mem::size_of::<RtcRay8>() == 384);
const _: () = assert!(std::mem::offset_of!(RtcRayHit8, hit) == 384);
const _: () = assert!(std::mem::offset_of!(RtcHit8, prim_id) == 160);
const _: () = assert!(std::mem::size_of::<RtcRay>() == 48);
const _: () = assert!(std::mem::offset_of!(RtcRayHit, hit) == 48);
const _: () = assert!(std::mem::offset_of!(RtcHit, prim_id) == 20);
const _: () = assert!(std::mem::offset_of!(RtcHit, geom_id) == 24);

/// The C functions used, copied out of the library, which stays loaded for the process.
struct Api {
    _lib: Library,
    version: isize,
    new_device: unsafe extern "C" fn(*const c_char) -> Device,
    release_device: unsafe extern "C" fn(Device),
    get_device_error: unsafe extern "C" fn(Device) -> c_int,
    get_device_property: unsafe extern "C" fn(Device, c_int) -> isize,
    new_scene: unsafe extern "C" fn(Device) -> Scene,
    set_scene_build_quality: unsafe extern "C" fn(Scene, c_int),
    commit_scene: unsafe extern "C" fn(Scene),
    release_scene: unsafe extern "C" fn(Scene),
    new_geometry: unsafe extern "C" fn(Device, c_int) -> Geometry,
    set_new_geometry_buffer:
        unsafe extern "C" fn(Geometry, c_int, c_uint, c_int, usize, usize) -> *mut c_void,
    commit_geometry: unsafe extern "C" fn(Geometry),
    attach_geometry: unsafe extern "C" fn(Scene, Geometry) -> c_uint,
    release_geometry: unsafe extern "C" fn(Geometry),
    intersect1: unsafe extern "C" fn(Scene, *mut RtcRayHit, *mut c_void),
    occluded1: unsafe extern "C" fn(Scene, *mut RtcRay, *mut c_void),
    intersect8: unsafe extern "C" fn(*const i32, Scene, *mut RtcRayHit8, *mut c_void),
    occluded8: unsafe extern "C" fn(*const i32, Scene, *mut RtcRay8, *mut c_void),
}

static LIB_PATH: OnceLock<Option<PathBuf>> = OnceLock::new();
static API: OnceLock<std::result::Result<Api, String>> = OnceLock::new();

/// Sets the library path (`--embree-lib`, else `EMBREE_LIB`); call once, before any build.
pub fn set_library(path: Option<PathBuf>) {
    let path = path.or_else(|| std::env::var_os("EMBREE_LIB").map(PathBuf::from));
    let _ = LIB_PATH.set(path);
}

fn api() -> Result<&'static Api> {
    API.get_or_init(|| {
        let path = LIB_PATH.get().cloned().flatten().ok_or_else(|| {
            "the embree peer needs Embree 4's shared library: pass --embree-lib PATH or set \
             EMBREE_LIB (`pip install embreex` carries one: \
             python3 -c 'import embreex, pathlib; print(*pathlib.Path(embreex.__file__)\
             .parent.parent.glob(\"embreex.libs/libembree4*\"))')"
                .to_string()
        })?;
        load(&path).map_err(|e| format!("{}: {e:#}", path.display()))
    })
    .as_ref()
    .map_err(|e| anyhow::anyhow!("{e}"))
}

fn load(path: &Path) -> Result<Api> {
    // SAFETY: loading Embree runs its (and TBB's) initialisers, which have no preconditions.
    let lib = unsafe { Library::new(path) }.context("cannot load the library")?;
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the symbol is declared with Embree 4's C signature (rtcore_device.h,
            // rtcore_scene.h, rtcore_geometry.h, rtcore_buffer.h); the version is checked
            // below before any of them but rtcNewDevice and rtcGetDeviceProperty is called,
            // and those two have the same signature in Embree 3 and 4.
            *unsafe { lib.get(concat!($name, "\0").as_bytes()) }
                .with_context(|| format!("no symbol {} (is this Embree?)", $name))?
        };
    }
    let mut api = Api {
        version: 0,
        new_device: sym!("rtcNewDevice"),
        release_device: sym!("rtcReleaseDevice"),
        get_device_error: sym!("rtcGetDeviceError"),
        get_device_property: sym!("rtcGetDeviceProperty"),
        new_scene: sym!("rtcNewScene"),
        set_scene_build_quality: sym!("rtcSetSceneBuildQuality"),
        commit_scene: sym!("rtcCommitScene"),
        release_scene: sym!("rtcReleaseScene"),
        new_geometry: sym!("rtcNewGeometry"),
        set_new_geometry_buffer: sym!("rtcSetNewGeometryBuffer"),
        commit_geometry: sym!("rtcCommitGeometry"),
        attach_geometry: sym!("rtcAttachGeometry"),
        release_geometry: sym!("rtcReleaseGeometry"),
        intersect1: sym!("rtcIntersect1"),
        occluded1: sym!("rtcOccluded1"),
        intersect8: sym!("rtcIntersect8"),
        occluded8: sym!("rtcOccluded8"),
        _lib: lib,
    };
    // SAFETY: a null config is allowed; the device is released right after the query.
    let device = unsafe { (api.new_device)(c"verbose=0".as_ptr()) };
    if device.is_null() {
        bail!("rtcNewDevice failed");
    }
    // SAFETY: `device` is a live device.
    api.version = unsafe { (api.get_device_property)(device, RTC_DEVICE_PROPERTY_VERSION) };
    // SAFETY: `device` is live and released once.
    unsafe { (api.release_device)(device) };
    if !(40000..50000).contains(&api.version) {
        bail!(
            "Embree version {} is not 4.x (Embree 3 has other signatures for the same symbols)",
            api.version
        );
    }
    Ok(api)
}

/// Loads the library now (not inside the first timed build) and checks its version.
pub fn preload() -> Result<()> {
    api().map(|_| ())
}

/// The Embree version of the loaded library, e.g. `4.4.0`.
pub fn version() -> Option<String> {
    let v = api().ok()?.version;
    Some(format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100))
}

/// A committed scene of one triangle mesh.
pub struct Embree {
    name: String,
    /// `embree@8`: streams traced eight rays per `rtcIntersect8` / `rtcOccluded8` call.
    packets: bool,
    api: &'static Api,
    device: Device,
    scene: Scene,
}

// SAFETY: a committed Embree scene may be queried from any number of threads at once
// (rtcIntersect1 / rtcOccluded1 are thread-safe on committed scenes), and the device and scene
// are released only in Drop, when no query can be running.
unsafe impl Send for Embree {}
// SAFETY: as for Send: queries take `&self` and only read the committed scene.
unsafe impl Sync for Embree {}

impl Drop for Embree {
    fn drop(&mut self) {
        // SAFETY: both handles are live and released once, the scene before its device.
        unsafe {
            (self.api.release_scene)(self.scene);
            (self.api.release_device)(self.device);
        }
    }
}

/// Builds `embree` or `embree:high` with as many TBB threads as the current rayon pool.
pub fn build(name: &str, tris: &[[Vec3; 3]]) -> Result<Box<dyn Peer>> {
    let (base, packets) = match name.strip_suffix("@8") {
        Some(base) => (base, true),
        None => (name, false),
    };
    let high = match base {
        "embree" => false,
        "embree:high" => true,
        _ => bail!("{name}: unknown Embree variant (embree, embree:high, each with @8)"),
    };
    let api = api()?;
    let threads = rayon::current_num_threads();
    let config = CString::new(format!("threads={threads},verbose=0"))?;
    // SAFETY: `config` is a NUL-terminated string that outlives the call.
    let device = unsafe { (api.new_device)(config.as_ptr()) };
    if device.is_null() {
        bail!("{name}: rtcNewDevice failed");
    }
    let count = tris.len();
    // SAFETY: every handle below comes from the live `device`; the buffers Embree returns hold
    // `count` items of the requested stride (it pads them for its SIMD loads), and we write
    // exactly `count` items into each before committing.
    let scene = unsafe {
        let scene = (api.new_scene)(device);
        if high {
            (api.set_scene_build_quality)(scene, RTC_BUILD_QUALITY_HIGH);
        }
        let geom = (api.new_geometry)(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        let vertices = (api.set_new_geometry_buffer)(
            geom,
            RTC_BUFFER_TYPE_VERTEX,
            0,
            RTC_FORMAT_FLOAT3,
            12,
            3 * count,
        ) as *mut [f32; 3];
        let indices = (api.set_new_geometry_buffer)(
            geom,
            RTC_BUFFER_TYPE_INDEX,
            0,
            RTC_FORMAT_UINT3,
            12,
            count,
        ) as *mut [u32; 3];
        if vertices.is_null() || indices.is_null() {
            let err = (api.get_device_error)(device);
            (api.release_geometry)(geom);
            (api.release_scene)(scene);
            (api.release_device)(device);
            bail!("{name}: rtcSetNewGeometryBuffer failed (RTCError {err})");
        }
        let vertices = std::slice::from_raw_parts_mut(vertices, 3 * count);
        let indices = std::slice::from_raw_parts_mut(indices, count);
        for (i, t) in tris.iter().enumerate() {
            for (k, p) in t.iter().enumerate() {
                vertices[3 * i + k] = p.to_array();
            }
            let base = 3 * i as u32;
            indices[i] = [base, base + 1, base + 2];
        }
        (api.commit_geometry)(geom);
        (api.attach_geometry)(scene, geom);
        (api.release_geometry)(geom);
        (api.commit_scene)(scene);
        scene
    };
    // SAFETY: `device` is live.
    let err = unsafe { (api.get_device_error)(device) };
    let peer = Embree {
        name: name.to_string(),
        packets,
        api,
        device,
        scene,
    };
    if err != 0 {
        bail!("{name}: the scene build failed (RTCError {err})");
    }
    Ok(Box::new(peer))
}

/// Up to eight rays as an `RTCRay8` and the lanes to trace.
fn rtc_ray8(rays: &[Ray], t_max: f32) -> (RtcRay8, Valid8) {
    let mut r = RtcRay8 {
        org: [[0.0; 8]; 3],
        tnear: [0.0; 8],
        dir: [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 8], [1.0; 8]],
        time: [0.0; 8],
        tfar: [t_max; 8],
        mask: [u32::MAX; 8],
        id: [0; 8],
        flags: [0; 8],
    };
    let mut valid = Valid8([0; 8]);
    for (i, ray) in rays.iter().enumerate().take(8) {
        for a in 0..3 {
            r.org[a][i] = ray.origin[a];
            r.dir[a][i] = ray.dir[a];
        }
        valid.0[i] = -1;
    }
    (r, valid)
}

fn rtc_ray(ray: &Ray, t_max: f32) -> RtcRay {
    RtcRay {
        org: ray.origin.to_array(),
        tnear: 0.0,
        dir: ray.dir.to_array(),
        time: 0.0,
        tfar: t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

impl Peer for Embree {
    fn name(&self) -> &str {
        &self.name
    }

    fn bytes(&self) -> Option<usize> {
        None
    }

    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
        let mut rh = RtcRayHit {
            ray: rtc_ray(ray, t_max),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: RTC_INVALID_GEOMETRY_ID,
                geom_id: RTC_INVALID_GEOMETRY_ID,
                inst_tail: [RTC_INVALID_GEOMETRY_ID; 17],
            },
        };
        // SAFETY: the scene is committed; `rh` is a 16-byte aligned RTCRayHit (with room for
        // any instance fields) that lives across the call; null arguments are allowed.
        unsafe { (self.api.intersect1)(self.scene, &mut rh, std::ptr::null_mut()) };
        (rh.hit.geom_id != RTC_INVALID_GEOMETRY_ID).then_some((rh.ray.tfar, rh.hit.prim_id))
    }

    fn is_stream(&self) -> bool {
        self.packets
    }

    fn closest_stream(&self, rays: &[Ray], t_max: f32, out: &mut [Option<(f32, u32)>]) {
        for (rays, out) in rays.chunks(8).zip(out.chunks_mut(8)) {
            let (ray, valid) = rtc_ray8(rays, t_max);
            let mut rh = RtcRayHit8 {
                ray,
                hit: RtcHit8 {
                    ng: [[0.0; 8]; 3],
                    u: [0.0; 8],
                    v: [0.0; 8],
                    prim_id: [RTC_INVALID_GEOMETRY_ID; 8],
                    geom_id: [RTC_INVALID_GEOMETRY_ID; 8],
                    inst_tail: [[RTC_INVALID_GEOMETRY_ID; 8]; 34],
                },
            };
            // SAFETY: the scene is committed; `valid` and `rh` are 32-byte aligned
            // (RTCRayHit8 with room for any instance fields) and live across the call; null
            // arguments are allowed.
            unsafe {
                (self.api.intersect8)(valid.0.as_ptr(), self.scene, &mut rh, std::ptr::null_mut())
            };
            for (i, o) in out.iter_mut().enumerate() {
                *o = (rh.hit.geom_id[i] != RTC_INVALID_GEOMETRY_ID)
                    .then_some((rh.ray.tfar[i], rh.hit.prim_id[i]));
            }
        }
    }

    fn occluded_stream(&self, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        for (rays, out) in rays.chunks(8).zip(out.chunks_mut(8)) {
            let (mut ray, valid) = rtc_ray8(rays, t_max);
            // SAFETY: as in `closest_stream`, with an RTCRay8. Embree sets an occluded lane's
            // tfar to -inf.
            unsafe {
                (self.api.occluded8)(valid.0.as_ptr(), self.scene, &mut ray, std::ptr::null_mut())
            };
            for (i, o) in out.iter_mut().enumerate() {
                *o = ray.tfar[i] == f32::NEG_INFINITY;
            }
        }
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let mut r = rtc_ray(ray, t_max);
        // SAFETY: the scene is committed; `r` is a 16-byte aligned RTCRay that lives across
        // the call; null arguments are allowed. Embree sets tfar to -inf when occluded.
        unsafe { (self.api.occluded1)(self.scene, &mut r, std::ptr::null_mut()) };
        r.tfar == f32::NEG_INFINITY
    }
}
