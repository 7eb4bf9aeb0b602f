#!/usr/bin/env python3
"""Build test scenes from Mitsuba 3's own scene description, for both renderers.

The other direction of `toml_to_mitsuba.py`: the scene is defined by a Mitsuba scene dict
(Mitsuba's `mi.cornell_box()`), and this script writes our TOML scene from it, so that
Mitsuba renders the scene exactly as Mitsuba defines it and we render the same triangles,
materials, light and camera. Cross-checking and benchmarking only (used by
`tools/bench/time_to_error.py`); nothing in the project's tests needs it.

Scenes
------
cbox    `mi.cornell_box()` unchanged except for two settings: the pixel filter is `box`
        (ours; `mi.cornell_box()` has `gaussian`) and the integrator is `path` with
        `max_depth = -1` (unlimited; Russian roulette from depth 5, Mitsuba's default).
        Render ours with `--max-depth 10000` (our MAX_DEPTH, `render --help`) to match.
dragon  the same box with the two cubes replaced by the Stanford dragon
        (`../shared/data/models/stanford-dragon.obj`, 871,414 triangles), scaled to 1.2 wide
        (its longest horizontal side, after a 30 degree turn about +y), centred on the floor
        and standing on it (1e-4 above it). The transform is computed once here and given to
        both: our TOML gets `transform = {scale, rotate, translate}`, Mitsuba's `obj` shape the
        4x4 matrix T * Rz * Ry * Rx * S of the same numbers (our `Transform::from_trs` order).
        Mitsuba's obj loader renumbers the vertices but keeps the face order, each face's
        winding and the positions (checked by `check`: every loaded triangle corner equals
        ours transformed here up to float32 rounding, no re-centring or flipping);
        `face_normals = True` is set because the OBJ has no normals and Mitsuba would otherwise
        shade with smoothed vertex normals, while ours shades a normal-less OBJ flat.

Conversion (scene dict -> TOML)
-------------------------------
* Every `rectangle` and `cube` is loaded by Mitsuba (in 3.9 both are meshes) and written as
  an inline `positions` + `indices` mesh with Mitsuba's own world-space vertices (float32,
  written in the shortest form that reads back as the same float32) and faces. The winding
  is checked against Mitsuba's vertex normals (its shading frame, which decides the emitting
  side): our front face is the CCW side, normal (v1-v0) x (v2-v0); a face whose cross product
  disagrees is reversed (none do in `mi.cornell_box()`), so our emitter faces the same way.
* `diffuse` with an `rgb` reflectance -> our `diffuse` `color`; `ref` BSDFs are resolved.
* An `area` emitter -> a material with the shape's BSDF colour (the light also reflects, in
  both renderers) and `emission` = the radiance, front face only (Mitsuba's area lights are
  one-sided too).
* `perspective` sensor -> our camera: position, look_at = position + forward and up from the
  columns of `to_world` (Mitsuba's look-at frame; the image orientation matches, see
  README.md); `fov_axis` `smaller` on the square 256x256 film is the vertical field of view,
  ours (other axes/aspect ratios are converted by the tangent). Near clip 0.001 and far clip
  100 do not cut anything in this scene (ours has no clip planes).

One-sided versus two-sided diffuse
----------------------------------
Mitsuba's `diffuse` is one-sided: a ray hitting it from the back (against the shading
normal) gets black. Ours is two-sided. Nowhere in the box is a back face hit, except in the
0.01-high gap between the light (y = 0.99, facing down, with the white BSDF) and the ceiling
(y = 1): there the light's top side is black in Mitsuba and white in ours, so the gap, lit
only through its 0.01-high sides, is darker in Mitsuba. The camera looks into the gap just
beyond the light's near edge, and the ceiling just around the light sees into it. Measured
with `check cbox --gap --ref REF --ref-var VAR` (ours and Mitsuba with the light's BSDF
wrapped in `twosided`, each at 1024 spp, against the cached 16384-spp Mitsuba reference):
* image means agree within noise: ours - Mitsuba = +0.022% R, +0.006% G, +0.006% B (z of the
  image-mean difference 1.6, 0.4, 0.3); the two-sided light alone gives +0.02% R;
* but not per pixel in a 1-2 pixel ring around the light (dark ceiling pixels, values
  ~0.005): there ours is 2.2x Mitsuba's value (median; up to 2.7x); 32 of the 33 pixels
  (of 65,536) with a channel at |z| > 5 are in it. Against Mitsuba with a two-sided light
  BSDF no pixel has |z| > 5 and the image means differ by 0.003% (z 0.2), so the ring is
  this effect and nothing else;
* in relMSE (epsilon 0.01) the ring adds about 1.5e-5 to ours against Mitsuba's reference,
  about 5% of Mitsuba's own relMSE at 1024 spp; the dragon scene has the same ring. Time to
  error (tools/bench/time-to-error.sh) is therefore slightly pessimistic for ours; see
  docs/benchmarks.md.
`mi.cornell_box()` is kept as it is. The dragon's BSDF is wrapped in `twosided` in Mitsuba,
since the scanned mesh has holes (4,270 boundary edges) through which back faces can be seen.

Usage
-----
  python3 tools/reference/mitsuba_to_toml.py write {cbox|dragon} OUT.toml [--dragon OBJ]
  python3 tools/reference/mitsuba_to_toml.py render {cbox|dragon} OUT.exr --spp N
          [--seed S] [--threads T] [--var-out VAR.exr] [--passes P] [--variant V]
  python3 tools/reference/mitsuba_to_toml.py check {cbox|dragon} [--spp 1024]
          [--render target/release/render] [--threads 2] [--out DIR] [--gap]
          [--ref REF.exr --ref-var REF_VAR.exr]

`write` writes our TOML; `render` renders the Mitsuba dict (EXR written with mi.Bitmap);
`check` writes the TOML, renders both at --spp (ours with `--aov variance`, Mitsuba in 16
passes for its variance; or takes Mitsuba's image from --ref, e.g. the cached 16384-spp
reference of tools/bench/time-to-error.sh) and compares them with `render compare` (MSE,
relMSE) and `compare.py` (means, block differences, z-scores from both variances); for the
dragon it first checks that Mitsuba loads the mesh where ours puts it.

Install: `pip install mitsuba numpy`; `apt-get install libllvm19` for the llvm variants
(DRJIT_LIBLLVM_PATH is set to /usr/lib/x86_64-linux-gnu/libLLVM-19.so when it exists).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import time

_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(_LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM19

import numpy as np  # noqa: E402
import mitsuba as mi  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_DRAGON = os.path.normpath(
    os.path.join(REPO, "..", "shared", "data", "models", "stanford-dragon.obj"))
SCENES = ("cbox", "dragon")
OUR_MAX_DEPTH = 10000  # rt_integrators MAX_DEPTH; `render --help`

# Dragon placement: turned about +y, longest horizontal side DRAGON_WIDTH, on the floor.
DRAGON_ROTATE_Y = 30.0
DRAGON_WIDTH = 1.2
DRAGON_LIFT = 1e-4
FLOOR_Y = -1.0


def die(msg: str) -> None:
    print(f"mitsuba_to_toml: error: {msg}", file=sys.stderr)
    sys.exit(2)


def ensure_variant(variant: str | None = None) -> str:
    """Sets a variant if none is set (default llvm_ad_rgb, else scalar_rgb)."""
    if variant:
        mi.set_variant(variant)
        return variant
    if mi.variant() is not None:
        return mi.variant()
    for v in ("llvm_ad_rgb", "scalar_rgb"):
        try:
            mi.set_variant(v)
            return v
        except Exception as e:  # pragma: no cover - environment dependent
            print(f"mitsuba_to_toml: warning: variant {v} unavailable ({e})", file=sys.stderr)
    die("no usable Mitsuba variant")
    return ""


# ----------------------------------------------------------------------------
# the dragon's transform, computed once for both renderers
# ----------------------------------------------------------------------------

def read_obj_positions(path: str) -> np.ndarray:
    """The `v` lines of an OBJ as an (N, 3) float64 array (enough for its bounds)."""
    rows = []
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"v "):
                rows.append(line[2:])
    if not rows:
        die(f"{path}: no vertices")
    return np.loadtxt(rows, dtype=np.float64).reshape(-1, 3)


def euler_matrix(rotate_deg) -> np.ndarray:
    """Rotation about x, then y, then z (world axes, right-hand rule): Rz @ Ry @ Rx."""
    ax, ay, az = np.radians(np.asarray(rotate_deg, float))
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    return rz @ ry @ rx


def trs_matrix(translate, rotate, scale: float) -> np.ndarray:
    """4x4 of `Transform::from_trs`: scale, then rotate (x, y, z), then translate."""
    m = np.eye(4)
    m[:3, :3] = euler_matrix(rotate) * float(scale)
    m[:3, 3] = np.asarray(translate, float)
    return m


_dragon_cache: dict[str, dict] = {}


def dragon_placement(obj_path: str) -> dict:
    """{'scale', 'rotate', 'translate', 'matrix'} placing the OBJ on the box floor."""
    if obj_path in _dragon_cache:
        return _dragon_cache[obj_path]
    if not os.path.exists(obj_path):
        die(f"dragon mesh not found: {obj_path} (pass --dragon PATH)")
    p = read_obj_positions(obj_path)
    rot = [0.0, DRAGON_ROTATE_Y, 0.0]
    r = euler_matrix(rot)
    q = p @ r.T
    lo, hi = q.min(0), q.max(0)
    s = DRAGON_WIDTH / max(hi[0] - lo[0], hi[2] - lo[2])
    # After scaling: centre x and z on 0, lowest point DRAGON_LIFT above the floor.
    cx, cz = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2])
    t = [-s * cx, FLOOR_Y + DRAGON_LIFT - s * lo[1], -s * cz]
    # Round to the digits written into the TOML, so both renderers get the same numbers.
    s = float(f"{s:.9g}")
    t = [float(f"{x:.9g}") for x in t]
    out = {"scale": s, "rotate": rot, "translate": t, "matrix": trs_matrix(t, rot, s),
           "positions": p, "height": s * (hi[1] - lo[1])}
    _dragon_cache[obj_path] = out
    return out


# ----------------------------------------------------------------------------
# the Mitsuba scene dicts
# ----------------------------------------------------------------------------

def mitsuba_dict(name: str, dragon_obj: str = DEFAULT_DRAGON, light_twosided: bool = False
                 ) -> dict:
    """The Mitsuba scene dict of `name` (needs a variant set)."""
    ensure_variant()
    if name not in SCENES:
        die(f"unknown scene {name!r} (expected one of {', '.join(SCENES)})")
    d = mi.cornell_box()
    d["sensor"]["film"]["rfilter"] = {"type": "box"}
    d["integrator"] = {"type": "path", "max_depth": -1}
    if light_twosided:  # only for the one-sided/two-sided check
        d["light"]["bsdf"] = {"type": "twosided", "material": dict(d["white"])}
    if name == "dragon":
        del d["small-box"], d["large-box"]
        pl = dragon_placement(dragon_obj)
        d["dragon"] = {
            "type": "obj",
            "filename": dragon_obj,
            "face_normals": True,
            "to_world": mi.ScalarTransform4f(pl["matrix"].tolist()),
            "bsdf": {"type": "twosided", "material": dict(d["white"])},
        }
    return d


# ----------------------------------------------------------------------------
# scene dict -> our TOML
# ----------------------------------------------------------------------------

def f32(x) -> str:
    """Shortest decimal that reads back as the same float32."""
    s = np.format_float_positional(np.float32(x), unique=True, trim="-")
    assert np.float32(float(s)) == np.float32(x), (x, s)
    return s


def f64(x) -> str:
    return repr(float(x))


def vec(v, fmt=f64) -> str:
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def resolve_bsdf(d: dict, b: dict) -> dict:
    while b.get("type") == "ref":
        b = d[b["id"]]
    return b


def bsdf_color(d: dict, b: dict, what: str) -> list[float]:
    b = resolve_bsdf(d, b)
    if b.get("type") == "twosided":  # ours is two-sided anyway
        b = resolve_bsdf(d, b["material"])
    if b.get("type") != "diffuse":
        die(f"{what}: only diffuse BSDFs are converted, got {b.get('type')!r}")
    r = b.get("reflectance", {"type": "rgb", "value": [0.5, 0.5, 0.5]})
    if isinstance(r, (int, float)):
        return [float(r)] * 3
    if r.get("type") != "rgb":
        die(f"{what}: reflectance must be rgb")
    v = r["value"]
    return [float(x) for x in (v if isinstance(v, (list, tuple)) else [v] * 3)]


def mesh_of(shape_dict: dict):
    """World-space positions, faces and vertex normals of a Mitsuba mesh shape."""
    sd = {k: v for k, v in shape_dict.items() if k not in ("bsdf", "emitter")}
    s = mi.load_dict(sd)
    if not s.is_mesh():
        die(f"shape type {shape_dict['type']!r} is not a mesh in this Mitsuba version")
    params = mi.traverse(s)
    if "vertex_positions" in params:
        p = np.array(params["vertex_positions"], np.float32).reshape(-1, 3)
        f = np.array(params["faces"], np.int64).reshape(-1, 3)
        n = (np.array(params["vertex_normals"], np.float32).reshape(-1, 3)
             if "vertex_normals" in params else None)
    else:  # rectangle/cube in 3.9 expose only to_world; ask the mesh itself
        p = np.array([np.array(s.vertex_position(i)) for i in range(s.vertex_count())],
                     np.float32).reshape(-1, 3)
        f = np.array([np.array(s.face_indices(i)) for i in range(s.face_count())],
                     np.int64).reshape(-1, 3)
        n = (np.array([np.array(s.vertex_normal(i)) for i in range(s.vertex_count())],
                      np.float32).reshape(-1, 3) if s.has_vertex_normals() else None)
    return p, f, n


def camera_toml(sensor: dict) -> str:
    if sensor.get("type") != "perspective":
        die(f"sensor type {sensor.get('type')!r} not converted (perspective only)")
    m = np.array(sensor["to_world"].matrix, np.float64)
    pos, up, fwd = m[:3, 3], m[:3, 1], m[:3, 2]
    film = sensor["film"]
    w, h = int(film.get("width", 768)), int(film.get("height", 576))
    fov = float(sensor.get("fov", 0.0)) if "fov" in sensor else None
    if fov is None:
        die("sensor without fov (focal_length is not converted)")
    axis = sensor.get("fov_axis", "x")
    if axis == "smaller":
        axis = "y" if h <= w else "x"
    elif axis == "larger":
        axis = "y" if h >= w else "x"
    elif axis == "diagonal":
        die("fov_axis diagonal not converted")
    if axis == "x":
        fov = math.degrees(2 * math.atan(math.tan(math.radians(fov) / 2) * h / w))
    return "\n".join([
        "[[camera]]",
        'name = "main"',
        f"position = {vec(pos, f32)}",
        f"look_at = {vec(pos + fwd, f32)}",
        f"up = {vec(up, f32)}",
        f"fov = {f64(fov)}   # vertical (Mitsuba fov_axis {sensor.get('fov_axis', 'x')!r}, "
        f"{w}x{h})",
        f"resolution = [{w}, {h}]",
        ""])


def toml_text(name: str, dragon_obj: str = DEFAULT_DRAGON) -> str:
    """Our TOML scene for `name`, converted from mitsuba_dict(name)."""
    d = mitsuba_dict(name, dragon_obj)
    out = [f"# {name}: generated by tools/reference/mitsuba_to_toml.py from Mitsuba "
           f"{mi.__version__}'s mi.cornell_box()" + (" with the Stanford dragon" if
                                                      name == "dragon" else "") + ".",
           "# Do not edit: regenerate with `mitsuba_to_toml.py write " + name + " OUT.toml`.",
           "# Units and axes are Mitsuba's (+y up, box [-1, 1]^3, camera on +z).", ""]
    out.append(camera_toml(d["sensor"]))
    mats: dict[str, list[float]] = {}
    mat_lines: list[str] = []
    geo_lines: list[str] = []
    n_emit = 0
    for key, v in d.items():
        if not isinstance(v, dict) or key in ("sensor", "integrator"):
            continue
        t = v.get("type")
        if t in ("diffuse", "twosided", "ref"):
            continue  # BSDFs: emitted where used
        if t not in ("rectangle", "cube", "obj"):
            die(f"{key}: shape type {t!r} not converted")
        color = bsdf_color(d, v.get("bsdf", {"type": "diffuse"}), key)
        emitter = v.get("emitter")
        if emitter is not None:
            if emitter.get("type") != "area" or emitter["radiance"].get("type") != "rgb":
                die(f"{key}: only area emitters with rgb radiance are converted")
            mname = f"{key}-emitter"
            emission = [float(x) for x in emitter["radiance"]["value"]]
            mat_lines += ["[[material]]", f'name = "{mname}"', 'type = "diffuse"',
                          f"color = {vec(color)}", f"emission = {vec(emission)}   "
                          "# front face only, as Mitsuba's area light", ""]
            n_emit += 1
        else:
            mname = next((k for k, c in mats.items() if c == color), None)
            if mname is None:
                b = v.get("bsdf", {})
                mname = b["id"] if b.get("type") == "ref" else f"{key}-bsdf"
                mats[mname] = color
                mat_lines += ["[[material]]", f'name = "{mname}"', 'type = "diffuse"',
                              f"color = {vec(color)}", ""]
        if t == "obj":
            pl = dragon_placement(v["filename"])
            geo_lines += [
                "[[geometry]]", f'name = "{key}"', f'file = "{v["filename"]}"',
                f'material = "{mname}"',
                f"transform = {{ scale = {f64(pl['scale'])}, rotate = {vec(pl['rotate'])}, "
                f"translate = {vec(pl['translate'])} }}", ""]
            continue
        p, f, n = mesh_of(v)
        flipped = 0
        for i, (a, b, c) in enumerate(f):
            cross = np.cross(p[b].astype(np.float64) - p[a], p[c].astype(np.float64) - p[a])
            if n is not None:
                ref = n[a].astype(np.float64) + n[b] + n[c]
                if np.dot(cross, ref) < 0:
                    f[i] = [a, c, b]
                    flipped += 1
        if flipped:
            print(f"mitsuba_to_toml: note: {key}: {flipped} faces reversed to match "
                  "Mitsuba's normals", file=sys.stderr)
        geo_lines += ["[[geometry]]", f'name = "{key}"  # Mitsuba {t}',
                      "positions = [" + ", ".join(vec(q, f32) for q in p) + "]",
                      "indices = [" + ", ".join(vec(q, str) for q in f) + "]",
                      f'material = "{mname}"', ""]
    if n_emit == 0:
        die("scene has no emitter")
    out += mat_lines + geo_lines
    out += ["[render]", 'integrator = "path"',
            f"max_depth = {OUR_MAX_DEPTH}   # Mitsuba path max_depth = -1 (unlimited)", ""]
    return "\n".join(out)


def write_toml(name: str, path: str, dragon_obj: str = DEFAULT_DRAGON) -> str:
    text = toml_text(name, dragon_obj)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
    return hashlib.sha256(text.encode()).hexdigest()


# ----------------------------------------------------------------------------
# rendering with Mitsuba
# ----------------------------------------------------------------------------

def render_passes(scene, spp: int, seed: int, passes: int | None = None,
                  max_lanes: int = 1 << 23, want_var: bool = False, log=None):
    """Renders `spp` in equal passes (each at most max_lanes pixel-samples on llvm);
    returns (mean, var_of_mean or None, n_passes, spp_per_pass). Pass p uses seed
    seed * 100003 + p, so two seeds never share a pass seed below 100003 passes."""
    film = scene.sensors()[0].film()
    w, h = film.crop_size()
    n = passes or 1
    if mi.variant().startswith("llvm"):
        n = max(n, math.ceil(w * h * spp / max_lanes))
    n = min(n, spp)
    while spp % n:
        n += 1
    per = spp // n
    acc = np.zeros((h, w, 3))
    acc2 = np.zeros((h, w, 3)) if want_var else None
    t0 = time.perf_counter()
    for p in range(n):
        a = np.array(mi.render(scene, spp=per, seed=seed * 100003 + p), np.float64)[..., :3]
        acc += a
        if acc2 is not None:
            acc2 += a * a
        if log:
            log(f"pass {p + 1}/{n} ({per} spp): {time.perf_counter() - t0:.1f} s")
    mean = acc / n
    var = None
    if acc2 is not None and n > 1:
        var = np.maximum(acc2 / n - mean * mean, 0.0) / (n - 1)
    return mean, var, n, per


def write_exr(path: str, img: np.ndarray) -> None:
    """Writes an RGB EXR with mi.Bitmap (the Dr.Jit pool must have >= 2 threads)."""
    tmp = path + ".tmp.exr"
    mi.Bitmap(np.ascontiguousarray(img, np.float32), mi.Bitmap.PixelFormat.RGB).write(tmp)
    os.replace(tmp, path)


def read_exr(path: str) -> np.ndarray:
    ensure_variant()
    b = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                srgb_gamma=False)
    return np.array(b, np.float64)


def set_threads(n: int | None) -> int:
    import drjit as dr
    old = dr.thread_count()
    if n:
        dr.set_thread_count(n)
    return old


# ----------------------------------------------------------------------------
# checks
# ----------------------------------------------------------------------------

def check_dragon_placement(obj_path: str) -> float:
    """Max |corner of Mitsuba's loaded triangle i - our transform of the OBJ's triangle i|.

    Mitsuba's obj loader renumbers the vertices (so they are compared through the faces), but
    keeps the face order, each face's corner order (no flipped winding) and the positions
    (no re-centring): the difference is float32 rounding."""
    pl = dragon_placement(obj_path)
    d = mitsuba_dict("dragon", obj_path)
    p_mi, f_mi, n_mi = mesh_of(d["dragon"])
    ours = pl["positions"] @ pl["matrix"][:3, :3].T + pl["matrix"][:3, 3]
    rows = []
    with open(obj_path, "rb") as f:
        for line in f:
            if line.startswith(b"f "):
                rows.append(line[2:])
    faces = np.loadtxt(rows, dtype=np.int64).reshape(-1, 3) - 1
    if faces.shape != f_mi.shape:
        die(f"dragon: Mitsuba has {len(f_mi)} triangles, the OBJ {len(faces)}")
    err = float(np.abs(p_mi[f_mi] - ours[faces]).max())
    print(f"dragon: {len(f_mi)} triangles, same order and winding in Mitsuba; max |Mitsuba "
          f"corner - ours| = {err:.3g} (scale {pl['scale']:.6g}, height {pl['height']:.4g}, "
          f"lowest y {float(p_mi[:, 1].min()):.6g}); Mitsuba vertex normals: "
          f"{'none (flat)' if n_mi is None or n_mi.size == 0 else len(n_mi)}")
    return err


def run(cmd, **kw):
    print("$ " + " ".join(cmd), flush=True)
    return subprocess.run(cmd, check=True, **kw)


def cmd_check(args) -> int:
    import drjit as dr
    os.makedirs(args.out, exist_ok=True)
    name = args.scene
    toml = os.path.join(args.out, f"{name}.toml")
    write_toml(name, toml, args.dragon)
    print(f"wrote {toml}")
    if name == "dragon":
        err = check_dragon_placement(args.dragon)
        if err > 1e-5:
            die(f"Mitsuba's dragon is not where ours is (max difference {err})")
    cmp_py = os.path.join(HERE, "compare.py")
    old = dr.thread_count()

    def mitsuba(tag: str, two: bool, seed: int):
        scene = mi.load_dict(mitsuba_dict(name, args.dragon, light_twosided=two))
        set_threads(args.threads)
        try:
            t0 = time.perf_counter()
            mean, var, n, per = render_passes(scene, args.spp, seed, passes=16,
                                              want_var=True)
            print(f"{tag}: {args.spp} spp ({n} x {per}) in {time.perf_counter() - t0:.1f} s")
        finally:
            dr.set_thread_count(max(2, old))
        img = os.path.join(args.out, f"{name}-{tag}.exr")
        var_img = os.path.join(args.out, f"{name}-{tag}-var.exr")
        write_exr(img, mean)
        write_exr(var_img, var)
        return img, var_img

    if args.ref:
        if not args.ref_var:
            die("--ref needs --ref-var (the variance of its pixel means)")
        mit, mvar = args.ref, args.ref_var
    else:
        mit, mvar = mitsuba("mitsuba", False, args.seed)
    ours = os.path.join(args.out, f"{name}-ours.exr")
    run([args.render, toml, "--spp", str(args.spp), "--threads", str(args.threads),
         "--max-depth", str(OUR_MAX_DEPTH), "--aov", "variance", "-o", ours])
    print(f"\n== ours ({ours}) against Mitsuba ({mit}) ==", flush=True)
    run([args.render, "compare", ours, mit])
    run([sys.executable, cmp_py, ours, mit, "--var-b", mvar])
    if args.gap:
        m2, v2 = mitsuba("mitsuba-light2s", True, args.seed + 1)  # independent
        print(f"\n== Mitsuba with a two-sided light BSDF ({m2}) against Mitsuba as is "
              f"({mit}) ==", flush=True)
        run([args.render, "compare", m2, mit])
        run([sys.executable, cmp_py, m2, mit, "--var", v2, "--var-b", mvar])
        print(f"\n== ours against Mitsuba with a two-sided light BSDF ({m2}) ==", flush=True)
        run([args.render, "compare", ours, m2])
        run([sys.executable, cmp_py, ours, m2, "--var-b", v2])
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("write", help="write our TOML scene")
    w.add_argument("scene", choices=SCENES)
    w.add_argument("output")
    r = sub.add_parser("render", help="render the Mitsuba dict")
    r.add_argument("scene", choices=SCENES)
    r.add_argument("output")
    r.add_argument("--spp", type=int, default=256)
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--passes", type=int, default=1)
    r.add_argument("--var-out", default=None)
    c = sub.add_parser("check", help="render both and compare")
    c.add_argument("scene", choices=SCENES)
    c.add_argument("--spp", type=int, default=1024)
    c.add_argument("--seed", type=int, default=3)
    c.add_argument("--out", default="/tmp/mitsuba-to-toml-check")
    c.add_argument("--render", default=os.path.join(REPO, "target", "release", "render"))
    c.add_argument("--ref", default=None,
                   help="compare against this Mitsuba image instead of rendering one at --spp")
    c.add_argument("--ref-var", default=None, help="variance of --ref's pixel means")
    c.add_argument("--gap", action="store_true",
                   help="also render Mitsuba with a two-sided light BSDF (the gap check)")
    for p in (w, r, c):
        p.add_argument("--dragon", default=DEFAULT_DRAGON, help="the dragon OBJ")
        p.add_argument("--variant", default=None, help="Mitsuba variant (default llvm_ad_rgb)")
    for p in (r, c):
        p.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)
    ensure_variant(args.variant)
    if args.cmd == "write":
        h = write_toml(args.scene, args.output, args.dragon)
        print(f"wrote {args.output} (sha256 {h[:12]})")
        return 0
    if args.cmd == "render":
        import drjit as dr
        scene = mi.load_dict(mitsuba_dict(args.scene, args.dragon))
        old = set_threads(args.threads)
        try:
            t0 = time.perf_counter()
            mean, var, n, per = render_passes(scene, args.spp, args.seed, args.passes,
                                              want_var=bool(args.var_out))
            el = time.perf_counter() - t0
        finally:
            dr.set_thread_count(max(2, old))
        write_exr(args.output, mean)
        if args.var_out:
            if var is None:
                die("--var-out needs --passes >= 2")
            write_exr(args.var_out, var)
        print(json.dumps({"spp": args.spp, "passes": n, "seconds": el, "output": args.output}))
        return 0
    return cmd_check(args)


if __name__ == "__main__":
    sys.exit(main())
