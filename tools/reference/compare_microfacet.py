#!/usr/bin/env python3
"""Our microfacet BSDFs against Mitsuba 3's on random direction pairs: `f·|cos θi|` and the pdf,
as Mitsuba's `BSDF.eval` and `BSDF.pdf` return them (scalar_rgb, shading frame = identity).
Prints the largest relative differences per BSDF; exits 1 if any exceeds the tolerance. The pdfs
are compared for GGX only: Beckmann samples `D(m)·cos θm` here and its visible normals in
Mitsuba, so its pdfs differ by design (the images' expectations do not).

    pip install mitsuba numpy
    cargo build --release -p rt-core --example microfacet_eval
    python3 tools/reference/compare_microfacet.py [target/release/examples/microfacet_eval]
"""
import subprocess
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
mi.set_log_level(mi.LogLevel.Error)

EXAMPLE = sys.argv[1] if len(sys.argv) > 1 else "target/release/examples/microfacet_eval"
TOL = 2e-3  # relative; values below 1e-4 compared absolutely
# Rough plastic's tables are integrals each side computes its own way (Gauss-Legendre over
# visible normals there, a midpoint rule over our sampling of normals here).
TOL_TABLES = 1e-2
CASES = [
    ("conductor", "ggx", 0.3, 0.3, 0.2, 3.9),
    ("conductor", "beckmann", 0.2, 0.2, 1.5, 2.0),
    ("conductor", "ggx", 0.1, 0.5, 0.2, 3.9),
    ("dielectric", "ggx", 0.3, 0.3, 1.5, 0.0),
    ("dielectric", "beckmann", 0.4, 0.4, 1.33, 0.0),
    ("plastic", "smooth", 0.0, 0.0, 1.49, 0.7),
    ("roughplastic", "ggx", 0.1, 0.1, 1.49, 0.7),
    ("roughplastic", "ggx", 0.5, 0.5, 1.49, 1.0),
    ("roughplastic", "beckmann", 0.3, 0.3, 1.5, 0.5),
]


def mitsuba_bsdf(kind, dist, ax, ay, eta, k):
    if kind == "roughplastic":
        return mi.load_dict({"type": "roughplastic", "distribution": dist, "alpha": ax,
                             "int_ior": eta, "ext_ior": 1.0,
                             "diffuse_reflectance": {"type": "rgb", "value": [k, k, k]}})
    if kind == "plastic":
        return mi.load_dict({"type": "plastic", "int_ior": eta, "ext_ior": 1.0,
                             "diffuse_reflectance": {"type": "rgb", "value": [k, k, k]}})
    d = {"type": "rough" + kind, "distribution": dist}
    d.update({"alpha": ax} if ax == ay else {"alpha_u": ax, "alpha_v": ay})
    if kind == "conductor":
        d.update({"eta": eta, "k": k})
    else:
        d.update({"int_ior": eta, "ext_ior": 1.0})
    return mi.load_dict(d)


def main():
    rng = np.random.default_rng(1)
    worst = 0.0
    for case in CASES:
        bsdf = mitsuba_bsdf(*case)
        ctx = mi.BSDFContext()
        lines, ref = [], []
        for _ in range(2000):
            wo = rng.normal(size=3)
            wi = rng.normal(size=3)
            wo /= np.linalg.norm(wo)
            wi /= np.linalg.norm(wi)
            if case[0] in ("conductor", "plastic", "roughplastic"):
                wo[2], wi[2] = abs(wo[2]), abs(wi[2])
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*wo)
            si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
            v = bsdf.eval(ctx, si, mi.Vector3f(*wi))
            p = bsdf.pdf(ctx, si, mi.Vector3f(*wi))
            ref.append((float(v[0]), float(p)))
            lines.append(" ".join(map(str, [*case, *wo, *wi])))
        out = subprocess.run([EXAMPLE], input="\n".join(lines) + "\n", capture_output=True,
                             text=True, check=True).stdout.split("\n")
        rel = [0.0, 0.0]
        for (rv, rp), o in zip(ref, out):
            ov, op = map(float, o.split())
            for j, (a, b) in enumerate([(ov, rv), (op, rp)]):
                scale = max(abs(a), abs(b))
                d = abs(a - b) / scale if scale > 1e-4 else abs(a - b)
                rel[j] = max(rel[j], d)
        tol = TOL_TABLES if case[0] == "roughplastic" else TOL
        worst = max(worst, rel[0] * TOL / tol, (rel[1] if case[1] != "beckmann" else 0.0) * TOL / tol)
        print("%-40s largest difference: f·cos %.2e, pdf %.2e" % (" ".join(map(str, case)), *rel))
    sys.exit(0 if worst <= TOL else 1)


main()
