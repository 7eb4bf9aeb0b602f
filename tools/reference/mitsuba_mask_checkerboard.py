#!/usr/bin/env python3
"""What our `mask`, `checkerboard` and textured roughness claim of Mitsuba 3, checked in Mitsuba
(scalar_rgb). Our side of each claim is a Rust test; this script checks that the claim is
Mitsuba's behaviour. Exits 1 if one does not hold.

1. checkerboard (rt_core::texture::Texture::checkerboard): color0 where frac(u') > 1/2 equals
   frac(v') > 1/2, edges in the lower half, (u', v') = to_uv's 2-D part m00 m01 m03 / m10 m11 m13.
2. mask (rt_core::material::Bsdf): eval and pdf are opacity x the nested BSDF's; sampling
   passes through (wo -> -wo, weight 1) with probability 1 - opacity.
3. a roughness texture (checkerboard, constant colour c) evaluates as the constant alpha = c.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so python3 tools/reference/mitsuba_mask_checkerboard.py
"""
import math
import random
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")
mi.set_log_level(mi.LogLevel.Error)
T = mi.ScalarTransform4f
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


# 1. checkerboard
to_uv = T().translate([0.3, -0.2, 0]) @ T().rotate([0, 0, 1], 20) @ T().scale([3, 5, 1])
m = to_uv.matrix
tex = mi.load_dict({"type": "checkerboard", "color0": {"type": "rgb", "value": [1, 0, 0]},
                    "color1": {"type": "rgb", "value": [0, 0, 1]}, "to_uv": to_uv})
si = mi.SurfaceInteraction3f()
rng = random.Random(1)
bad = 0
for _ in range(2000):
    u, v = rng.uniform(-2, 2), rng.uniform(-2, 2)
    up = m[0, 0] * u + m[0, 1] * v + m[0, 3]
    vp = m[1, 0] * u + m[1, 1] * v + m[1, 3]
    fu, fv = up - math.floor(up), vp - math.floor(vp)
    if min(abs(fu - 0.5), abs(fv - 0.5), fu, fv) < 1e-4:
        continue
    si.uv = mi.Point2f(u, v)
    want0 = (fu > 0.5) == (fv > 0.5)
    got0 = tex.eval(si)[0] > 0.5
    bad += want0 != got0
check(bad == 0, f"checkerboard rule with to_uv's m03, m13 ({bad} mismatches of 2000)")
plain = mi.load_dict({"type": "checkerboard", "color0": {"type": "rgb", "value": [1, 0, 0]},
                      "color1": {"type": "rgb", "value": [0, 0, 1]}})
edges = []
for uv, want0 in [((0.5, 0.5), True), ((0.0, 0.0), True), ((0.5, 0.7), False), ((1.0, 0.3), True)]:
    si.uv = mi.Point2f(*uv)
    edges.append((plain.eval(si)[0] > 0.5) == want0)
check(all(edges), f"checkerboard edges 0 and 1/2 in the lower half {edges}")
d = mi.load_dict({"type": "checkerboard"})
si.uv = mi.Point2f(0.1, 0.1)
c0 = d.eval(si)[0]
si.uv = mi.Point2f(0.6, 0.1)
c1 = d.eval(si)[0]
check(abs(c0 - 0.4) < 1e-6 and abs(c1 - 0.2) < 1e-6, f"checkerboard defaults {c0}, {c1}")

# 2. mask
inner = {"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": 0.3}
for opacity in [0.3, 0.8]:
    mask = mi.load_dict({"type": "mask", "opacity": opacity, "b": inner})
    nested = mi.load_dict(inner)
    ctx = mi.BSDFContext()
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f([0, 0, 1])
    si.wi = mi.Vector3f(0.6, 0, 0.8)
    wo = mi.Vector3f(-0.3, 0.2, 0.9)
    wo = wo / math.sqrt(0.09 + 0.04 + 0.81)
    fm, fn = mask.eval(ctx, si, wo)[0], nested.eval(ctx, si, wo)[0]
    pm, pn = mask.pdf(ctx, si, wo), nested.pdf(ctx, si, wo)
    check(abs(fm - opacity * fn) < 1e-6 * fn and abs(pm - opacity * pn) < 1e-6 * pn,
          f"mask {opacity}: eval {fm:.6f} = {opacity} x {fn:.6f}, pdf {pm:.6f} = {opacity} x {pn:.6f}")
    through, n = 0, 20000
    for i in range(n):
        bs, w = mask.sample(ctx, si, rng.random(), mi.Point2f(rng.random(), rng.random()))
        if mi.has_flag(bs.sampled_type, mi.BSDFFlags.Null):
            through += 1
            ok = abs(bs.wo[2] + 0.8) < 1e-6 and abs(w[0] - 1) < 1e-6 and abs(bs.pdf - (1 - opacity)) < 1e-6
            if not ok:
                check(False, f"pass-through sample {bs.wo} weight {w} pdf {bs.pdf}")
                break
    sd = math.sqrt(n * opacity * (1 - opacity))
    check(abs(through - n * (1 - opacity)) < 4 * sd,
          f"mask {opacity}: {through} of {n} samples pass through (expected {n * (1 - opacity):.0f})")

# 3. textured roughness
for c in [0.05, 0.3]:
    tex = {"type": "checkerboard", "color0": c, "color1": c}
    a = mi.load_dict({"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": tex})
    b = mi.load_dict({"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": c})
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f([0, 0, 1])
    si.wi = mi.Vector3f(0.6, 0, 0.8)
    wo = mi.Vector3f(-0.5, 0.1, 0.86)
    wo = wo / math.sqrt(0.25 + 0.01 + 0.86 ** 2)
    fa, fb = a.eval(mi.BSDFContext(), si, wo)[0], b.eval(mi.BSDFContext(), si, wo)[0]
    check(abs(fa - fb) <= 1e-6 * fb, f"alpha texture {c}: eval {fa:.6f} = constant's {fb:.6f}")

sys.exit(1 if failures else 0)
