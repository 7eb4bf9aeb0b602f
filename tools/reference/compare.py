#!/usr/bin/env python3
"""Compare two EXR renders (e.g. ours vs the Mitsuba reference) robustly.

Cross-checking tool only: the project's own tests never need it.

Usage:
    python3 tools/reference/compare.py A.exr B.exr [--var VAR_A.exr] [--var-b VAR_B.exr]
        [--block 8] [--layer NAME] [--diff-out diff.exr] [--tol-mean 0.02]

Reports, per channel R,G,B:
  * mean of A and of B, relative difference of the means (A-B)/B, RMSE, RMSE/mean(B)
  * block comparison: both images averaged over KxK blocks (default 8x8) so
    per-pixel noise does not dominate; mean / 95th percentile / max of the
    relative block difference |a-b| / max((a+b)/2, 1% of the image mean)
  * if a variance is known (--var / --var-b files, or `variance.R/G/B` layers
    inside A or B): per-pixel z = (A-B)/sqrt(varA+varB): mean (bias), std
    (should be ~1), robust std (1.4826*MAD), fraction |z|>3 (Gaussian: 0.27%)
    and |z|>5, plus the z-score of the difference of the image means, which
    is the most sensitive test for a global bias.

The variance images must hold the variance of the per-pixel MEAN (as written by
toml_to_mitsuba.py --var-out).  If yours hold the per-sample variance, pass
--var-div-a SPP (resp. --var-div-b) to divide by the sample count.

RGB is taken from the channels R,G,B of the default (root) layer, or of
--layer NAME (channels NAME.R, NAME.G, NAME.B).  Other layers are ignored.
Exit status: 0, or 1 if a --tol-* threshold is exceeded, 2 on usage errors.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np


def die(msg: str) -> None:
    print(f"compare: error: {msg}", file=sys.stderr)
    sys.exit(2)


# ----------------------------------------------------------------------------
# EXR reading: Mitsuba's Bitmap if available, else the OpenEXR package.
# ----------------------------------------------------------------------------

def read_channels(path: str) -> dict[str, np.ndarray]:
    if not os.path.exists(path):
        die(f"{path}: no such file")
    try:
        import mitsuba as mi
        if mi.variant() is None:
            mi.set_variant("scalar_rgb")
        bmp = mi.Bitmap(path)
        names = [f.name for f in bmp.struct_()]
        arr = np.asarray(bmp)
        if arr.ndim == 2:
            arr = arr[..., None]
        arr = arr.astype(np.float64)
        return {n: arr[..., i] for i, n in enumerate(names)}
    except ImportError:
        pass
    try:
        import OpenEXR  # type: ignore
        import Imath  # type: ignore
    except ImportError:
        die("need either the 'mitsuba' or the 'OpenEXR' Python package to read EXR")
    f = OpenEXR.InputFile(path)
    hdr = f.header()
    dw = hdr["dataWindow"]
    w, h = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    out = {}
    for n in hdr["channels"]:
        buf = f.channel(n, pt)
        out[n] = np.frombuffer(buf, dtype=np.float32).reshape(h, w).astype(np.float64)
    return out


def pick_rgb(ch: dict[str, np.ndarray], layer: str | None, path: str) -> np.ndarray:
    prefix = f"{layer}." if layer else ""
    names = [prefix + c for c in "RGB"]
    if all(n in ch for n in names):
        return np.stack([ch[n] for n in names], -1)
    if not layer and "Y" in ch:  # luminance-only image
        return np.stack([ch["Y"]] * 3, -1)
    die(f"{path}: no channels {names} (have: {sorted(ch)})")
    raise AssertionError


def load_rgb(path: str, layer: str | None) -> tuple[np.ndarray, dict]:
    ch = read_channels(path)
    return pick_rgb(ch, layer, path), ch


def variance_from(ch: dict, path: str) -> np.ndarray | None:
    names = ["variance." + c for c in "RGB"]
    if all(n in ch for n in names):
        return np.stack([ch[n] for n in names], -1)
    return None


# ----------------------------------------------------------------------------
# statistics
# ----------------------------------------------------------------------------

def block_mean(img: np.ndarray, k: int) -> np.ndarray:
    h, w = img.shape[:2]
    hb, wb = h // k, w // k
    if hb == 0 or wb == 0:
        return img.reshape(1, 1, -1, img.shape[-1]).mean(axis=2)
    c = img[: hb * k, : wb * k]
    return c.reshape(hb, k, wb, k, -1).mean(axis=(1, 3))


def fmt3(v) -> str:
    return "  ".join(f"{x:>12.6g}" for x in v)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", help="image A (e.g. ours)")
    ap.add_argument("b", help="image B (e.g. reference)")
    ap.add_argument("--var", dest="var_a", help="variance of A's per-pixel mean (EXR, R,G,B)")
    ap.add_argument("--var-b", help="variance of B's per-pixel mean (EXR, R,G,B)")
    ap.add_argument("--var-div-a", type=float, default=1.0,
                    help="divide A's variance by this (e.g. spp, if it is per-sample)")
    ap.add_argument("--var-div-b", type=float, default=1.0)
    ap.add_argument("--no-auto-var", action="store_true",
                    help="ignore variance.R/G/B layers inside A and B")
    ap.add_argument("--layer", default=None, help="take RGB from layer NAME instead of the root")
    ap.add_argument("--block", type=int, default=8, help="block size for the block comparison")
    ap.add_argument("--diff-out", default=None,
                    help="write (A-B)/max((A+B)/2, eps) per pixel as an EXR (needs mitsuba)")
    ap.add_argument("--tol-mean", type=float, default=None,
                    help="fail if any |relative difference of channel means| exceeds this")
    ap.add_argument("--tol-block", type=float, default=None,
                    help="fail if the mean relative block difference exceeds this")
    ap.add_argument("--tol-zmean", type=float, default=None,
                    help="fail if |z of the image-mean difference| exceeds this (needs a variance)")
    args = ap.parse_args(argv)

    A, cha = load_rgb(args.a, args.layer)
    B, chb = load_rgb(args.b, args.layer)
    if A.shape != B.shape:
        die(f"size mismatch: {args.a} is {A.shape[1]}x{A.shape[0]}, "
            f"{args.b} is {B.shape[1]}x{B.shape[0]}")
    h, w = A.shape[:2]
    fail = []

    print(f"A = {args.a}\nB = {args.b}\nsize {w}x{h}, channels R G B"
          + (f" of layer {args.layer}" if args.layer else ""))
    for name, img in (("A", A), ("B", B)):
        bad = ~np.isfinite(img)
        if bad.any():
            print(f"WARNING: {name} has {int(bad.any(-1).sum())} pixels with NaN/Inf; "
                  "they are set to 0 below")
    A = np.nan_to_num(A, nan=0.0, posinf=0.0, neginf=0.0)
    B = np.nan_to_num(B, nan=0.0, posinf=0.0, neginf=0.0)

    # -- global statistics --------------------------------------------------
    ma, mb = A.mean(axis=(0, 1)), B.mean(axis=(0, 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(mb != 0, (ma - mb) / mb, np.where(ma == 0, 0.0, np.inf))
    rmse = np.sqrt(((A - B) ** 2).mean(axis=(0, 1)))
    with np.errstate(divide="ignore", invalid="ignore"):
        rrmse = np.where(mb != 0, rmse / np.abs(mb), np.inf)
    print(f"\n{'':24s}{'R':>12s}  {'G':>12s}  {'B':>12s}")
    print(f"{'mean A':24s}{fmt3(ma)}")
    print(f"{'mean B':24s}{fmt3(mb)}")
    print(f"{'rel diff of means':24s}{fmt3(rel)}")
    print(f"{'RMSE':24s}{fmt3(rmse)}")
    print(f"{'RMSE / mean B':24s}{fmt3(rrmse)}")
    if args.tol_mean is not None and np.any(np.abs(rel) > args.tol_mean):
        fail.append(f"|rel diff of means| {np.abs(rel).max():.4g} > {args.tol_mean}")

    # -- block comparison ---------------------------------------------------
    k = max(1, args.block)
    ba, bb = block_mean(A, k), block_mean(B, k)
    floor = 0.01 * np.maximum(np.abs(mb), 1e-12)
    denom = np.maximum(0.5 * (np.abs(ba) + np.abs(bb)), floor)
    brel = np.abs(ba - bb) / denom
    print(f"\nblock comparison ({k}x{k} blocks, {ba.shape[1]}x{ba.shape[0]} of them; "
          "|a-b| / max((a+b)/2, 1% of mean B)):")
    print(f"{'mean rel block diff':24s}{fmt3(brel.mean(axis=(0, 1)))}")
    print(f"{'95th percentile':24s}{fmt3(np.percentile(brel.reshape(-1, 3), 95, axis=0))}")
    print(f"{'max':24s}{fmt3(brel.max(axis=(0, 1)))}")
    for c in range(3):
        iy, ix = np.unravel_index(np.argmax(brel[..., c]), brel.shape[:2])
        print(f"  max {'RGB'[c]} at block ({ix},{iy}) = pixels x {ix * k}..{ix * k + k - 1}, "
              f"y {iy * k}..{iy * k + k - 1}: A={ba[iy, ix, c]:.6g} B={bb[iy, ix, c]:.6g}")
    if args.tol_block is not None and brel.mean() > args.tol_block:
        fail.append(f"mean rel block diff {brel.mean():.4g} > {args.tol_block}")

    # -- variance-based z-scores --------------------------------------------
    va = vb = None
    srcs = []
    if args.var_a:
        va = pick_rgb(read_channels(args.var_a), None, args.var_a) / args.var_div_a
        srcs.append(f"A: {args.var_a}")
    elif not args.no_auto_var and (v := variance_from(cha, args.a)) is not None:
        va = v / args.var_div_a
        srcs.append("A: variance.* layer")
    if args.var_b:
        vb = pick_rgb(read_channels(args.var_b), None, args.var_b) / args.var_div_b
        srcs.append(f"B: {args.var_b}")
    elif not args.no_auto_var and (v := variance_from(chb, args.b)) is not None:
        vb = v / args.var_div_b
        srcs.append("B: variance.* layer")
    for name, v in (("A", va), ("B", vb)):
        if v is not None and v.shape != A.shape:
            die(f"variance of {name} has size {v.shape[1]}x{v.shape[0]}, image is {w}x{h}")
    if va is None and vb is None:
        print("\n(no variance given: skipping z-scores; use --var VAR_A.exr)")
    else:
        var = np.zeros_like(A)
        for v in (va, vb):
            if v is not None:
                var += np.nan_to_num(np.maximum(v, 0.0))
        print(f"\nz-scores, z = (A-B)/sqrt(varA+varB)  [{'; '.join(srcs)}]"
              + ("" if (va is not None and vb is not None) else
                 "  (one image treated as exact)"))
        ok = var > 0
        diff = A - B
        zero_var_mismatch = (~ok) & (np.abs(diff) > 1e-6 * (np.abs(A) + np.abs(B) + 1e-30))
        z = np.where(ok, diff / np.sqrt(np.where(ok, var, 1.0)), 0.0)
        rows = {"mean z (bias)": [], "std z (~1)": [], "robust std z (~1)": [],
                "frac |z|>3 (0.0027)": [], "frac |z|>5 (~0)": [],
                "zero-var mismatches": [], "z of image-mean diff": []}
        for c in range(3):
            zc = z[..., c][ok[..., c]]
            if zc.size:
                med = np.median(zc)
                rows["mean z (bias)"].append(zc.mean())
                rows["std z (~1)"].append(zc.std())
                rows["robust std z (~1)"].append(1.4826 * np.median(np.abs(zc - med)))
                rows["frac |z|>3 (0.0027)"].append((np.abs(zc) > 3).mean())
                rows["frac |z|>5 (~0)"].append((np.abs(zc) > 5).mean())
            else:
                for key in ("mean z (bias)", "std z (~1)", "robust std z (~1)",
                            "frac |z|>3 (0.0027)", "frac |z|>5 (~0)"):
                    rows[key].append(np.nan)
            rows["zero-var mismatches"].append(int(zero_var_mismatch[..., c].sum()))
            se = np.sqrt(var[..., c].sum()) / (h * w)
            dm = diff[..., c].mean()
            rows["z of image-mean diff"].append(dm / se if se > 0 else (0.0 if dm == 0 else np.inf))
        for key, vals in rows.items():
            print(f"{key:24s}{fmt3(vals)}")
        zm = np.abs(np.array(rows["z of image-mean diff"]))
        if args.tol_zmean is not None and np.any(zm > args.tol_zmean):
            fail.append(f"|z of image-mean diff| {zm.max():.3g} > {args.tol_zmean}")

    if args.diff_out:
        import mitsuba as mi
        if mi.variant() is None:
            mi.set_variant("scalar_rgb")
        d = (A - B) / np.maximum(0.5 * (np.abs(A) + np.abs(B)), floor)
        mi.Bitmap(np.ascontiguousarray(d, dtype=np.float32),
                  mi.Bitmap.PixelFormat.RGB).write(args.diff_out)
        print(f"\nwrote relative difference image {args.diff_out}")

    if fail:
        print("\nFAIL: " + "; ".join(fail))
        return 1
    if any(t is not None for t in (args.tol_mean, args.tol_block, args.tol_zmean)):
        print("\nOK: within tolerances")
    return 0


if __name__ == "__main__":
    sys.exit(main())
