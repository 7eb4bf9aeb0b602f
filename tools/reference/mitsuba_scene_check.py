#!/usr/bin/env python3
"""Does our renderer converge to Mitsuba 3's image on a Mitsuba scene file?

For one scene file: writes a copy Mitsuba 3 accepts (the edits ../shared/data/mitsuba/README.md
lists: `<lookAt>` -> `<lookat>`, `high_quality_edges` removed) at a smaller size, renders it with
Mitsuba 3 `llvm_ad_rgb` at N spp (twice, different seeds) and at a reference spp, and with our
`render` (reading the same XML file) at our reference spp. Prints

    ratio = relMSE(Mitsuba N spp, our reference) / relMSE(Mitsuba N spp, Mitsuba reference)

which is about 1 when both renderers converge to the same image (issue 31 asks <= 1.2), and the
relMSE between the two references (how far apart the converged images are, against the noise of
the second N-spp render, printed as the floor).

Usage: tools/reference/mitsuba_scene_check.py SCENE.xml [--size 256] [--spp 64]
       [--ref-spp 4096] [--our-spp 4096] [--render target/release/render] [--out DIR]
With --out, Mitsuba's renders are kept there and reused by the next run with the same size and
spp (unless the scene file is newer).
Needs `pip install mitsuba numpy` and (for llvm_ad_rgb) Debian's libllvm19.
"""
import argparse, os, re, shutil, subprocess, sys, tempfile, time
from pathlib import Path

p = argparse.ArgumentParser()
p.add_argument("scene")
p.add_argument("--size", type=int, default=256)
p.add_argument("--spp", type=int, default=64)
p.add_argument("--ref-spp", type=int, default=4096)
p.add_argument("--our-spp", type=int, default=4096)
p.add_argument("--render", default="target/release/render")
p.add_argument("--out", default=None)
a = p.parse_args()

llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm):
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm
import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")
src = Path(a.scene).resolve()
out = Path(a.out or tempfile.mkdtemp(prefix="mi-check-"))
out.mkdir(parents=True, exist_ok=True)
text = src.read_text()
text = text.replace("<lookAt", "<lookat").replace("</lookAt>", "</lookat>")
text = re.sub(r'<boolean name="high_?[qQ]uality_?[eE]dges"[^>]*/>', "", text)
# Both dialects: width/height parameters of the film.
text = re.sub(r'(<integer name="width" value=")\d+(")', rf"\g<1>{a.size}\2", text)
text = re.sub(r'(<integer name="height" value=")\d+(")', rf"\g<1>{a.size}\2", text)
copy = src.parent / f".check-{os.getpid()}.xml"  # beside the original: relative paths resolve
copy.write_text(text)
try:
    scene = mi.load_file(str(copy))

    def mitsuba(spp, seed):
        t = time.time()
        img = np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3].astype(np.float64)
        return img, time.time() - t

    # Mitsuba's images depend only on the scene and these settings: kept in --out, so a
    # second run (our renderer changed) renders only ours.
    cache = out / f"mitsuba-{a.size}-{a.spp}-{a.ref_spp}.npz"
    if cache.exists() and cache.stat().st_mtime > src.stat().st_mtime:
        c = np.load(cache)
        m1, m2, ref, t1 = c["m1"], c["m2"], c["ref"], float(c["t1"])
        print(f"Mitsuba's renders from {cache}")
    else:
        m1, t1 = mitsuba(a.spp, 1)
        m2, _ = mitsuba(a.spp, 2)
        # The reference in slices of at most 1024 spp (Dr.Jit's wavefront holds every sample).
        ref = np.zeros_like(m1)
        left, seed = a.ref_spp, 100
        while left > 0:
            n = min(left, 1024)
            img, _ = mitsuba(n, seed)
            ref += img * n
            left -= n
            seed += 1
        ref /= a.ref_spp
        np.savez(cache, m1=m1, m2=m2, ref=ref, t1=t1)
    ours_path = out / "ours.exr"
    t = time.time()
    subprocess.run([a.render, str(copy), "--spp", str(a.our_spp), "-q", "-o", str(ours_path)], check=True)
    t_ours = time.time() - t
finally:
    copy.unlink()
ours = np.array(mi.Bitmap(str(ours_path)), dtype=np.float64)[:, :, :3]


def relmse(x, r):
    return float(np.mean((x - r) ** 2 / (r ** 2 + 1e-2)))


e_ours = relmse(m1, ours)
e_ref = relmse(m1, ref)
print(f"scene {src}  size {a.size}x{a.size}  Mitsuba {mi.__version__} llvm_ad_rgb")
print(f"relMSE(Mitsuba {a.spp} spp vs our {a.our_spp} spp)      = {e_ours:.6g}")
print(f"relMSE(Mitsuba {a.spp} spp vs Mitsuba {a.ref_spp} spp)  = {e_ref:.6g}")
print(f"ratio = {e_ours / e_ref:.4f}   (issue 31: <= 1.2)")
print(f"relMSE(our reference vs Mitsuba's)       = {relmse(ours, ref):.6g}")
print(f"relMSE(second Mitsuba {a.spp}-spp render) = {relmse(m2, ref):.6g} (noise floor)")
print(f"mean RGB: Mitsuba ref {ref.mean(axis=(0, 1))}, ours {ours.mean(axis=(0, 1))}")
print(f"times: Mitsuba {a.spp} spp {t1:.1f} s, ours {a.our_spp} spp {t_ours:.1f} s")
np.save(out / "mitsuba_ref.npy", ref)
