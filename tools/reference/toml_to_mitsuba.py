#!/usr/bin/env python3
"""Render one of our TOML scenes with Mitsuba 3 as an independent reference.

Cross-checking tool only: the project's own tests never need Mitsuba.

Usage:
    python3 tools/reference/toml_to_mitsuba.py SCENE.toml -o out.exr \
        --spp 1024 --max-depth 64 [--camera NAME] [--resolution W H] \
        [--variant llvm_ad_rgb|scalar_rgb] [--seed 0] [--threads N] \
        [--var-out var.exr] [--passes N]

Supported subset of docs/scene-format.md (anything else is a clear error):
  [environment] color / map / strength;  [[camera]] (all keys);
  [[material]] type = diffuse | mirror | glass (hardness 1), color, ior, emission;
  [[geometry]] shape = quad | box | sphere | disk, or positions + indices
  (+ optional normals), with an optional transform = {translate, rotate, scale}.
  Not supported: mesh files, textures, layered/glossy/plastic/metal materials,
  rough glass, two_sided emission, [[assign]].

Conventions (see README.md next to this file for the details):
  * our --max-depth D = at most D bounces  ->  Mitsuba path max_depth = D + 1
  * camera fov is VERTICAL                 ->  fov_axis = 'y'
  * emission is front-face only (CCW)      ->  Mitsuba 'area' emitter (one-sided,
                                               front = CCW winding normal)
  * diffuse / mirror are wrapped in 'twosided' (our shading is two-sided;
    Mitsuba's diffuse/conductor are black from the back side).
  * envmap: equirect, +y up, row 0 = zenith, centre column = -z, u grows
    towards +x  ->  Mitsuba 'envmap' with to_world = scale(-1, 1, -1)
    (= a 180 degree rotation about +y).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import tomllib

# Prefer Debian's libLLVM 19 for the llvm_* variants if the user did not say.
_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(_LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM19

import numpy as np  # noqa: E402
import mitsuba as mi  # noqa: E402


# ----------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------

def die(msg: str) -> None:
    print(f"toml_to_mitsuba: error: {msg}", file=sys.stderr)
    sys.exit(2)


def warn(msg: str) -> None:
    print(f"toml_to_mitsuba: warning: {msg}", file=sys.stderr)


def vec3(v, what: str) -> list[float]:
    if not isinstance(v, (list, tuple)) or len(v) != 3:
        die(f"{what}: expected a 3-vector, got {v!r}")
    return [float(x) for x in v]


def pick_variant(requested: str | None) -> str:
    """Set the requested variant, or the best one that works here."""
    candidates = [requested] if requested else ["llvm_ad_rgb", "scalar_rgb"]
    last_err = None
    for v in candidates:
        try:
            mi.set_variant(v)
            if v.startswith("llvm"):
                # Force a JIT compile so a missing/broken libLLVM shows up now.
                import drjit as dr
                x = dr.arange(mi.Float, 4) * 2
                dr.eval(x)
                _ = x.numpy()
            return v
        except Exception as e:  # pragma: no cover - environment dependent
            last_err = e
            warn(f"variant {v} unavailable ({e})")
    die(f"no usable Mitsuba variant ({last_err})")
    return ""  # unreachable


# ----------------------------------------------------------------------------
# materials
# ----------------------------------------------------------------------------

def make_bsdf(mat: dict, lenient: bool = False):
    name = mat.get("name")
    t = mat.get("type", "layered" if "layers" in mat else "diffuse")
    if "texture" in mat:
        if not lenient:
            die(f"material {name!r}: textures are not supported (--lenient ignores them)")
        warn(f"material {name!r}: texture ignored (--lenient)")
    if t not in ("diffuse", "mirror", "glass") and lenient:
        warn(f"material {name!r}: type {t!r} replaced by diffuse of its color (--lenient)")
        t = "diffuse"
    elif t == "glass" and float(mat.get("hardness", 1.0)) < 1.0 and lenient:
        warn(f"material {name!r}: rough glass replaced by smooth glass (--lenient)")
        mat = {k: v for k, v in mat.items() if k != "hardness"}
    color = vec3(mat.get("color", [0.8, 0.8, 0.8]), f"material {name}.color")
    if t == "diffuse":
        b = {"type": "diffuse", "reflectance": {"type": "rgb", "value": color}}
    elif t == "mirror":
        b = {"type": "conductor", "material": "none",
             "specular_reflectance": {"type": "rgb", "value": color}}
    elif t == "glass":
        if float(mat.get("hardness", 1.0)) < 1.0:
            die(f"material {name!r}: rough (frosted) glass, hardness < 1, is not supported")
        ior = float(mat.get("ior", 1.5))
        # Dielectrics are inherently two-sided; never wrap them. The interior
        # (int_ior) is behind the front face, as in our format.
        return mi.load_dict({"type": "dielectric", "int_ior": ior, "ext_ior": 1.0,
                             "specular_transmittance": {"type": "rgb", "value": color}})
    else:
        die(f"material {name!r}: unsupported type {t!r} (supported: diffuse, mirror, glass; "
            "--lenient substitutes diffuse)")
    # Our shading is two-sided; Mitsuba's diffuse/conductor are black from the back.
    return mi.load_dict({"type": "twosided", "material": b})


# ----------------------------------------------------------------------------
# geometry: everything becomes (positions, faces, optional vertex normals)
# ----------------------------------------------------------------------------

def quad_mesh(v):
    return np.asarray(v, float), np.array([[0, 1, 2], [0, 2, 3]]), None


def box_mesh(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if np.any(hi <= lo):
        die(f"box: max {hi} must exceed min {lo} in every component")
    center = 0.5 * (lo + hi)
    P, F = [], []
    for axis in range(3):
        for side in (0, 1):
            b, c = (axis + 1) % 3, (axis + 2) % 3

            def corner(sb, sc):
                p = np.zeros(3)
                p[axis] = hi[axis] if side else lo[axis]
                p[b] = hi[b] if sb else lo[b]
                p[c] = hi[c] if sc else lo[c]
                return p
            v = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
            n = np.cross(v[1] - v[0], v[2] - v[0])
            if np.dot(n, 0.5 * (v[0] + v[2]) - center) < 0:
                v[1], v[3] = v[3], v[1]
            k = len(P)
            P += v
            F += [[k, k + 1, k + 2], [k, k + 2, k + 3]]
    return np.array(P), np.array(F), None


def sphere_mesh(center, radius, subdivisions):
    """Icosphere exactly as crates/scene/src/shapes.rs builds it (smooth normals)."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    verts = [np.array(p, float) / np.linalg.norm(p) for p in [
        [-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
        [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]]
    faces = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
             [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
             [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
             [8, 6, 7], [9, 8, 1]]
    for _ in range(subdivisions):
        mid = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]
        nxt = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            nxt += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        faces = nxt
    V = np.array(verts)
    F = np.array(faces)
    for f in F:  # keep outward (the table already is)
        n = np.cross(V[f[1]] - V[f[0]], V[f[2]] - V[f[0]])
        if np.dot(n, V[f].sum(0)) < 0:
            f[1], f[2] = f[2], f[1]
    return np.asarray(center, float) + V * radius, F, V.copy()


def any_orthonormal_pair(n):
    """glam's Vec3::any_orthonormal_pair (Duff et al. 2017)."""
    x, y, z = n
    sign = 1.0 if z >= 0.0 and math.copysign(1.0, z) > 0 else -1.0
    a = -1.0 / (sign + z)
    b = x * y * a
    return (np.array([1.0 + sign * x * x * a, sign * b, -sign * x]),
            np.array([b, sign + y * y * a, -y]))


def disk_mesh(center, normal, radius, segments):
    c = np.asarray(center, float)
    n = np.asarray(normal, float)
    if not np.any(n):
        die("disk: normal must be non-zero")
    n = n / np.linalg.norm(n)
    t, b = any_orthonormal_pair(n)
    if np.dot(np.cross(t, b), n) <= 0:
        t, b = b, t
    P = [c]
    for i in range(segments):
        a = 2 * math.pi * i / segments
        P.append(c + (t * math.cos(a) + b * math.sin(a)) * radius)
    F = [[0, 1 + i, 1 + (i + 1) % segments] for i in range(segments)]
    return np.array(P), np.array(F), None


def apply_transform(tr: dict, P, F, N):
    """Scale, then rotate about x, y, z (world axes), then translate (from_trs)."""
    s = tr.get("scale", 1.0)
    s = np.array([float(s)] * 3) if isinstance(s, (int, float)) else np.array(vec3(s, "scale"))
    if np.any(s == 0):
        die("transform.scale components must be non-zero")
    ax, ay, az = np.radians(vec3(tr.get("rotate", [0, 0, 0]), "rotate"))
    Rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    Ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    Rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    M = Rz @ Ry @ Rx @ np.diag(s)
    T = np.array(vec3(tr.get("translate", [0, 0, 0]), "translate"))
    P = P @ M.T + T
    if N is not None:
        N = N @ np.linalg.inv(M)  # rows: (M^-T n)^T = n^T M^-1
        N = N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-30)
    if np.linalg.det(M) < 0:  # mirroring: keep front faces in front
        F = F[:, ::-1].copy()
    return P, F, N


def geometry_mesh(geo: dict):
    name = geo.get("name", "?")
    shape = geo.get("shape")
    if "file" in geo:
        die(f"geometry {name!r}: mesh files are not supported by this converter")
    if shape == "quad":
        v = np.asarray(geo["vertices"], float)
        if v.shape != (4, 3):
            die(f"geometry {name!r}: quad needs 4 vertices of 3 coordinates")
        P, F, N = quad_mesh(v)
    elif shape == "box":
        P, F, N = box_mesh(vec3(geo["min"], "min"), vec3(geo["max"], "max"))
    elif shape == "sphere":
        P, F, N = sphere_mesh(vec3(geo.get("center", [0, 0, 0]), "center"),
                              float(geo["radius"]), int(geo.get("subdivisions", 3)))
    elif shape == "disk":
        P, F, N = disk_mesh(vec3(geo.get("center", [0, 0, 0]), "center"),
                            vec3(geo.get("normal", [0, 1, 0]), "normal"),
                            float(geo["radius"]), int(geo.get("segments", 64)))
    elif shape is None and "positions" in geo:
        P = np.asarray(geo["positions"], float)
        F = np.asarray(geo["indices"], np.int64)
        if P.ndim != 2 or P.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
            die(f"geometry {name!r}: positions must be Nx3 and indices Mx3")
        if F.size and (F.min() < 0 or F.max() >= len(P)):
            die(f"geometry {name!r}: index out of range")
        N = None
        if "normals" in geo:
            N = np.asarray(geo["normals"], float)
            if N.shape != P.shape:
                die(f"geometry {name!r}: need one normal per position")
            N = N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-30)
    else:
        die(f"geometry {name!r}: unsupported shape {shape!r} "
            "(quad, box, sphere, disk, or positions + indices)")
    if "transform" in geo:
        P, F, N = apply_transform(geo["transform"], P, F, N)
    return P, F, N


def make_mesh(name: str, P, F, N, bsdf, emitter_radiance):
    props = mi.Properties()
    props["bsdf"] = bsdf
    if emitter_radiance is not None:
        props["emitter"] = mi.load_dict({"type": "area",
                                         "radiance": {"type": "rgb", "value": emitter_radiance}})
    mesh = mi.Mesh(name, len(P), len(F), props=props, has_vertex_normals=N is not None)
    params = mi.traverse(mesh)
    # Use the buffer types of the current variant (dynamic arrays even in scalar mode).
    params["vertex_positions"] = type(params["vertex_positions"])(
        np.ascontiguousarray(P, np.float32).ravel())
    params["faces"] = type(params["faces"])(np.ascontiguousarray(F, np.uint32).ravel())
    if N is not None:
        params["vertex_normals"] = type(params["vertex_normals"])(
            np.ascontiguousarray(N, np.float32).ravel())
    params.update()
    return mesh


# ----------------------------------------------------------------------------
# scene
# ----------------------------------------------------------------------------

def build_scene_dict(scene: dict, base_dir: str, args) -> dict:
    if scene.get("assign"):
        if not args.lenient:
            die("[[assign]] is not supported by this converter (--lenient ignores it)")
        warn("[[assign]] ignored (--lenient)")
    # --- camera ---------------------------------------------------------
    cams = scene.get("camera", [])
    if not cams:
        die("scene has no [[camera]]")
    cam = cams[0]
    if args.camera is not None:
        matches = [c for c in cams if c.get("name") == args.camera]
        if not matches:
            die(f"no camera named {args.camera!r} (have: {[c.get('name') for c in cams]})")
        cam = matches[0]
    width, height = [int(x) for x in cam.get("resolution", [512, 512])]
    if args.resolution:
        width, height = args.resolution
    origin = vec3(cam["position"], "camera.position")
    target = vec3(cam["look_at"], "camera.look_at")
    up = vec3(cam.get("up", [0.0, 1.0, 0.0]), "camera.up")
    fov = float(cam.get("fov", 40.0))
    aperture = float(cam.get("aperture", 0.0))
    sensor = {
        "type": "perspective",
        "fov": fov,
        "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=up),
        "film": {
            "type": "hdrfilm",
            "width": width,
            "height": height,
            "rfilter": {"type": "box"},
            "pixel_format": "rgb",
            "component_format": "float32",
            "sample_border": False,
        },
        "sampler": {"type": "independent", "sample_count": 1, "seed": args.seed},
    }
    if aperture > 0.0:
        sensor["type"] = "thinlens"
        sensor["aperture_radius"] = aperture
        sensor["focus_distance"] = float(cam.get("focus_distance", math.dist(origin, target)))

    d = {
        "type": "scene",
        "integrator": {
            "type": "path",
            "max_depth": args.max_depth + 1 if args.max_depth >= 0 else -1,
            "rr_depth": args.rr_depth,
            "hide_emitters": False,
        },
        "sensor": sensor,
    }

    # --- environment ----------------------------------------------------
    # We look texels up without interpolation (the radiance is then exactly the piecewise-
    # constant function our sampling pdf is built from); Mitsuba's envmap always interpolates
    # bilinearly. Replicating every texel ENV_UPSAMPLE x ENV_UPSAMPLE times confines the
    # difference to thin seams between texels.
    env = scene.get("environment", {}) or {}
    strength = float(env.get("strength", 1.0))
    color = vec3(env.get("color", [0.0, 0.0, 0.0]), "environment.color")
    if "map" in env:
        if any(color):
            die("environment: 'map' and a non-black 'color' are mutually exclusive")
        path = env["map"] if os.path.isabs(env["map"]) else os.path.join(base_dir, env["map"])
        path = nearest_upsampled(path, ENV_UPSAMPLE)
        d["environment"] = {
            "type": "envmap",
            "filename": path,
            "scale": strength,
            # ours: centre column = -z, u grows towards +x, row 0 = +y.
            # Mitsuba: u = 0 (left edge) at -z, u grows towards +x, row 0 = +y.
            # => rotate 180 degrees about +y.
            "to_world": mi.ScalarTransform4f().scale([-1.0, 1.0, -1.0]),
        }
    elif any(color) and strength > 0:
        d["environment"] = {"type": "constant",
                            "radiance": {"type": "rgb", "value": [c * strength for c in color]}}

    # --- materials --------------------------------------------------------
    mats = {}
    for m in scene.get("material", []):
        if "name" not in m:
            die("material without a name")
        mats[m["name"]] = m
    bsdfs = {}

    # --- geometry ---------------------------------------------------------
    n_emissive = 0
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for i, geo in enumerate(scene.get("geometry", [])):
        gname = str(geo.get("name", f"geometry{i}"))
        mname = geo.get("material")
        if mname is None:
            die(f"geometry {gname!r}: needs a 'material' (mesh-file materials unsupported)")
        if mname not in mats:
            die(f"geometry {gname!r}: unknown material {mname!r}")
        mat = mats[mname]
        if mname not in bsdfs:
            bsdfs[mname] = make_bsdf(mat, args.lenient)
        emission = mat.get("emission")
        if emission is not None:
            emission = vec3(emission, f"material {mname}.emission")
            if not any(emission):
                emission = None
        if emission is not None:
            if mat.get("two_sided", False):
                die(f"material {mname!r}: two_sided emission has no Mitsuba equivalent "
                    "(Mitsuba area lights are one-sided)")
            n_emissive += 1
        P, F, N = geometry_mesh(geo)
        if len(P):
            lo, hi = np.minimum(lo, P.min(0)), np.maximum(hi, P.max(0))
        d[f"shape_{i:05d}"] = make_mesh(gname, P, F, N, bsdfs[mname], emission)
    # Clip planes: our camera has none, so put them well outside the scene.
    o = np.asarray(origin)
    far = 1.0
    if np.all(np.isfinite(lo)):
        far = max(far, 4.0 * float(np.max(np.maximum(np.abs(lo - o), np.abs(hi - o)))) * 1.8)
    sensor["far_clip"] = far
    sensor["near_clip"] = far * 1e-7
    if n_emissive == 0 and "environment" not in d:
        warn("scene has no light source")
    return d


# ----------------------------------------------------------------------------
# rendering
# ----------------------------------------------------------------------------

def render(scene, args, variant: str):
    film = scene.sensors()[0].film()
    w, h = film.crop_size()
    spp = args.spp
    # Number of passes: enough so that one llvm wavefront stays below
    # --max-lanes, at least --passes (needed >= 2 for a variance estimate).
    passes = max(1, args.passes)
    if variant.startswith("llvm"):
        passes = max(passes, math.ceil(w * h * spp / args.max_lanes))
    passes = min(passes, spp)
    # spp per pass must be equal so the plain average is exact (box filter).
    while spp % passes:
        passes += 1
    spp_pass = spp // passes

    acc = np.zeros((h, w, 3), dtype=np.float64)
    acc2 = np.zeros((h, w, 3), dtype=np.float64) if args.var_out else None
    t0 = time.perf_counter()
    for p in range(passes):
        img = mi.render(scene, spp=spp_pass, seed=args.seed * 100003 + p)
        a = np.array(img, dtype=np.float64)[..., :3]
        acc += a
        if acc2 is not None:
            acc2 += a * a
        if args.verbose:
            print(f"  pass {p + 1}/{passes}: {spp_pass} spp, "
                  f"{time.perf_counter() - t0:.1f}s", file=sys.stderr)
    elapsed = time.perf_counter() - t0
    mean = acc / passes
    var = None
    if acc2 is not None:
        if passes < 2:
            die("--var-out needs at least 2 passes (use --passes N)")
        # Unbiased sample variance of the pass images, divided by #passes
        # = estimated variance of the final per-pixel mean.
        var = np.maximum(acc2 / passes - mean * mean, 0.0) / (passes - 1)
    return mean, var, elapsed, passes, spp_pass


def write_exr(path: str, rgb_img: np.ndarray):
    bmp = mi.Bitmap(np.ascontiguousarray(rgb_img, dtype=np.float32),
                    mi.Bitmap.PixelFormat.RGB)
    bmp.write(path)


ENV_UPSAMPLE = 8


def nearest_upsampled(path, k):
    """Writes a copy of an EXR with every texel repeated k x k times; returns its path."""
    import numpy as np
    import tempfile
    bmp = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    a = np.array(bmp)
    a = np.repeat(np.repeat(a, k, axis=0), k, axis=1)
    out = os.path.join(tempfile.mkdtemp(prefix="toml2mi-"), "env.exr")
    mi.Bitmap(a).write(out)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", help="scene .toml")
    ap.add_argument("-o", "--output", required=True, help="output .exr")
    ap.add_argument("--spp", type=int, default=None,
                    help="samples per pixel (default: [render] spp, else 64)")
    ap.add_argument("--max-depth", type=int, default=None,
                    help="max bounces as in our renderer (Mitsuba gets D+1); -1 = unlimited "
                         "(default: [render] max_depth, else 64)")
    ap.add_argument("--rr-depth", type=int, default=5,
                    help="Mitsuba Russian-roulette start depth (unbiased; default 5)")
    ap.add_argument("--camera", default=None, help="camera name (default: first)")
    ap.add_argument("--resolution", type=int, nargs=2, metavar=("W", "H"))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variant", default=None,
                    help="Mitsuba variant (default: llvm_ad_rgb, falling back to scalar_rgb)")
    ap.add_argument("--threads", type=int, default=None,
                    help="render threads (default: all cores)")
    ap.add_argument("--passes", type=int, default=1,
                    help="split the spp into at least this many independent passes")
    ap.add_argument("--max-lanes", type=int, default=1 << 23,
                    help="llvm: max pixels*spp per pass (memory bound; default 2^23)")
    ap.add_argument("--var-out", default=None,
                    help="also write the estimated variance of the per-pixel mean "
                         "(from the spread of the passes; default 16 passes)")
    ap.add_argument("--lenient", action="store_true",
                    help="approximate instead of failing: unsupported material types become "
                         "diffuse of their color, textures and [[assign]] are ignored "
                         "(for rough cross-checks only)")
    ap.add_argument("--print-dict", action="store_true", help="print the scene dict")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)

    with open(args.scene, "rb") as f:
        scene = tomllib.load(f)
    rt = scene.get("render", {}) or {}
    if args.spp is None:
        args.spp = int(rt.get("spp", 64))
    if args.max_depth is None:
        args.max_depth = int(rt.get("max_depth", 64))
    if args.spp < 1:
        die("--spp must be >= 1")
    if args.var_out and args.passes < 2:
        args.passes = min(16, args.spp)

    variant = pick_variant(args.variant)
    import drjit as dr
    default_threads = dr.thread_count()

    base_dir = os.path.dirname(os.path.abspath(args.scene))
    t_load = time.perf_counter()
    sd = build_scene_dict(scene, base_dir, args)
    if args.print_dict:
        for k, v in sd.items():
            print(f"{k}: {v}")
    # Load (this reads an envmap EXR) before restricting the thread pool.
    loaded = mi.load_dict(sd)
    if args.threads:
        dr.set_thread_count(args.threads)
    try:
        mean, var, elapsed, passes, spp_pass = render(loaded, args, variant)
    finally:
        # Mitsuba 3.9's EXR reader/writer deadlocks with a 1-thread pool.
        dr.set_thread_count(max(2, default_threads))
    write_exr(args.output, mean)
    if var is not None:
        write_exr(args.var_out, var)
    total = time.perf_counter() - t_load
    h, w = mean.shape[:2]
    print(f"toml_to_mitsuba: {variant} {w}x{h} spp={args.spp} ({passes}x{spp_pass}) "
          f"mitsuba_max_depth={sd['integrator']['max_depth']} "
          f"render={elapsed:.2f}s total={total:.2f}s -> {args.output}"
          + (f" (+ variance {args.var_out})" if var is not None else ""))
    m = mean.reshape(-1, 3).mean(axis=0)
    print(f"toml_to_mitsuba: mean RGB = {m[0]:.6g} {m[1]:.6g} {m[2]:.6g}")


if __name__ == "__main__":
    main()
