#!/usr/bin/env python3
"""Issue 31's criterion at equal sample counts, on a Mitsuba scene file: our N-spp render's
relMSE against Mitsuba 3's high-spp reference over Mitsuba's own N-spp render's (about 1 when
both converge to the same image with the same noise; issue 31 asks <= 1.2).

Reuses the reference `mitsuba_scene_check.py --out DIR` saved (DIR/mitsuba_ref.npy) and edits
the scene as that script does (the `<lookAt>`/`high_quality_edges` fixes, the film resized), so
both read the same scene. Averages over `--seeds` (each seed one N-spp render of each).

Usage: tools/reference/equal_spp_check.py SCENE.xml --ref DIR/mitsuba_ref.npy [--size 256]
       [--spp 64] [--seeds 1 2 3] [--render target/release/render]
"""
import argparse, os, re, subprocess, tempfile
from pathlib import Path

p = argparse.ArgumentParser()
p.add_argument("scene")
p.add_argument("--ref", required=True)
p.add_argument("--size", type=int, default=256)
p.add_argument("--spp", type=int, default=64)
p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
p.add_argument("--render", default="target/release/render")
a = p.parse_args()

llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm):
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm
import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")
src = Path(a.scene).resolve()
ref = np.load(a.ref)
text = src.read_text()
text = text.replace("<lookAt", "<lookat").replace("</lookAt>", "</lookat>")
text = re.sub(r'<boolean name="high_?[qQ]uality_?[eE]dges"[^>]*/>', "", text)
text = re.sub(r'(<integer name="width" value=")\d+(")', rf"\g<1>{a.size}\2", text)
text = re.sub(r'(<integer name="height" value=")\d+(")', rf"\g<1>{a.size}\2", text)
copy = src.parent / f".check-{os.getpid()}.xml"  # beside the original: relative paths resolve
copy.write_text(text)
out = Path(tempfile.mkdtemp(prefix="equal-spp-"))


def relmse(x, r):
    return float(np.mean((x - r) ** 2 / (r ** 2 + 1e-2)))


theirs, ours = [], []
try:
    scene = mi.load_file(str(copy))
    for seed in a.seeds:
        m = np.array(mi.render(scene, spp=a.spp, seed=seed))[:, :, :3].astype(np.float64)
        theirs.append(relmse(m, ref))
        path = out / f"ours-{seed}.exr"
        cmd = [a.render, str(copy), "--spp", str(a.spp), "--seed", str(seed), "-q", "-o", str(path)]
        subprocess.run(cmd, check=True)
        o = np.array(mi.Bitmap(str(path)), dtype=np.float64)[:, :, :3]
        ours.append(relmse(o, ref))
finally:
    copy.unlink()
print(f"scene {src}  size {a.size}x{a.size}  {a.spp} spp  seeds {a.seeds}")
print(f"relMSE vs Mitsuba's reference: ours {np.mean(ours):.6g} {ours}")
print(f"                               Mitsuba {np.mean(theirs):.6g} {theirs}")
print(f"ratio ours/Mitsuba = {np.mean(ours) / np.mean(theirs):.4f}   (issue 31: <= 1.2)")
