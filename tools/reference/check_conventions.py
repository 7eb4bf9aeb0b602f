#!/usr/bin/env python3
"""Self-check of the conventions toml_to_mitsuba.py relies on (runs in a few seconds).

    python3 tools/reference/check_conventions.py [--variant scalar_rgb|llvm_ad_rgb]

Checks, by rendering tiny scenes through toml_to_mitsuba.py:
  1. emitter sidedness: a quad that is CCW as seen from the camera emits
     towards it; the same quad with reversed winding is black;
  2. image orientation: +x of the world (forward x up) is image right, +up is row 0 side;
  3. fov is vertical: a quad spanning half the vertical view covers exactly
     the middle half of the rows of a 2:1 image;
  4. envmap orientation: an equirect map written in OUR convention (+y up, row 0 =
     zenith, centre column = -z, u grows towards +x) is seen the right way round
     in all six axis directions and one oblique one.
Cross-checking tool only: not part of the project's test suite.
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(_LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM19
import mitsuba as mi  # noqa: E402

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "toml_to_mitsuba.py")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--variant", default="scalar_rgb")
    args = ap.parse_args()
    mi.set_variant("scalar_rgb")
    tmp = tempfile.mkdtemp(prefix="mitsuba-conv-")

    def run(toml: str, name: str) -> np.ndarray:
        scene = os.path.join(tmp, "t.toml")
        out = os.path.join(tmp, name)
        with open(scene, "w") as f:
            f.write(toml)
        subprocess.run([sys.executable, TOOL, scene, "-o", out, "--spp", "16",
                        "--variant", args.variant, "--threads", "1"],
                       check=True, stdout=subprocess.DEVNULL)
        return np.asarray(mi.Bitmap(out), dtype=np.float64)[..., :3]

    def cam(pos, at, up, fov, res):
        return (f'[[camera]]\nname="c"\nposition={pos}\nlook_at={at}\nup={up}\n'
                f'fov={fov}\nresolution={res}\n')

    def quad(vs):
        return f'[[geometry]]\nname="q"\nshape="quad"\nvertices={vs}\nmaterial="L"\n'

    light = '[[material]]\nname="L"\ntype="diffuse"\ncolor=[0,0,0]\nemission=[1,2,3]\n'
    ok = True

    def check(cond, msg):
        nonlocal ok
        print(("ok   " if cond else "FAIL ") + msg)
        ok &= bool(cond)

    # 1. sidedness
    c = cam([0, 0, 3], [0, 0, 0], [0, 1, 0], 30, [8, 8])
    a = run(c + light + quad([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]), "front.exr")
    b = run(c + light + quad([[-1, 1, 0], [1, 1, 0], [1, -1, 0], [-1, -1, 0]]), "back.exr")
    check(np.allclose(a[4, 4], [1, 2, 3], atol=1e-4) and np.allclose(b[4, 4], 0),
          f"emitter sidedness: CCW-facing {a[4, 4]}, CW-facing {b[4, 4]}")

    # 2. orientation: small light at (+0.6, +0.3) must land right of centre, above centre
    s, cx, cy = 0.1, 0.6, 0.3
    img = run(cam([0, 0, 3], [0, 0, 0], [0, 1, 0], 40, [64, 48]) + light +
              quad([[cx - s, cy - s, 0], [cx + s, cy - s, 0], [cx + s, cy + s, 0], [cx - s, cy + s, 0]]),
              "orient.exr")
    ys, xs = np.nonzero(img[..., 0] > 0.5)
    check(xs.size > 0 and xs.min() > 32 and ys.max() < 24,
          f"orientation: light at (+x,+y) covers cols {xs.min()}..{xs.max()}, rows {ys.min()}..{ys.max()} of 64x48")

    # 3. vertical fov
    fov = 40.0
    h = float(np.tan(np.radians(fov / 2)) * 3.0)  # half of the visible height at distance 3
    img = run(cam([0, 0, 3], [0, 0, 0], [0, 1, 0], fov, [128, 64]) + light +
              quad([[-0.2, -h / 2, 0], [0.2, -h / 2, 0], [0.2, h / 2, 0], [-0.2, h / 2, 0]]), "fov.exr")
    rows = np.nonzero(img[:, 64, 0] > 0.5)[0]
    check(rows.size > 0 and rows.min() == 16 and rows.max() == 47,
          f"vertical fov: quad spanning half the view height covers rows {rows.min()}..{rows.max()} (expect 16..47)")

    # 4. envmap orientation, colour = (d + 1) / 2 in our convention
    W, H = 256, 128
    u = (np.arange(W) + 0.5) / W
    v = (np.arange(H) + 0.5) / H
    th = (v * np.pi)[:, None]
    ph = (2 * np.pi * (u - 0.5))[None, :]
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th) * np.ones_like(ph),
                  -np.sin(th) * np.cos(ph)], -1)
    env = os.path.join(tmp, "env.exr")
    mi.Bitmap(np.ascontiguousarray((d + 1) / 2, dtype=np.float32),
              mi.Bitmap.PixelFormat.RGB).write(env)
    dummy = '[[material]]\nname="x"\ntype="diffuse"\ncolor=[0,0,0]\n'
    for dirn, up in [([1, 0, 0], [0, 1, 0]), ([-1, 0, 0], [0, 1, 0]), ([0, 0, -1], [0, 1, 0]),
                     ([0, 0, 1], [0, 1, 0]), ([0, 1, 0], [0, 0, -1]), ([0, -1, 0], [0, 0, -1]),
                     ([0.6, 0.48, -0.64], [0, 1, 0])]:
        img = run(f'[environment]\nmap="{env}"\n' + cam([0, 0, 0], dirn, up, 1.0, [3, 3]) + dummy,
                  "env_out.exr")
        exp = (np.array(dirn) / np.linalg.norm(dirn) + 1) / 2
        check(np.allclose(img[1, 1], exp, atol=0.02),
              f"envmap: looking along {dirn}: got {np.round(img[1, 1], 3)}, expected {np.round(exp, 3)}")

    print("all convention checks passed" if ok else "SOME CONVENTION CHECKS FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
