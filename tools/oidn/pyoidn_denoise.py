#!/usr/bin/env python3
"""Denoise one of our EXR frames with Open Image Denoise through pyoidn, and time it.

The peer measurement for the denoiser benchmark: the same input our denoisers get (a frame
written by `NoisyFrame::write_exr` or `render --aov ... -o F.exr`: colour in R,G,B, first-hit
albedo in albedo.{R,G,B}, normal in normal.{X,Y,Z}), denoised by OIDN's RT filter, written as
an EXR with R,G,B (float32), and one JSON line on stdout with the times.

Inputs are sanitised as `rt_denoise::Oidn` does (non-finite -> 0, colour >= 0 (or in [0,1]
with --ldr), albedo in [0,1], normal in [-1,1]), so both paths give OIDN the same buffers.

Times: `load_s` is importing pyoidn (loading libOpenImageDenoise), `first_s` the first call
(creates the device, builds the network, denoises), `runs_s` each further call (cached device
and filter), `median_s` their median: compare `median_s` with our warm per-frame time.

Usage: pyoidn_denoise.py IN.exr OUT.exr [--quality high|balanced|fast] [--aux on|off]
                         [--clean-aux] [--ldr] [--repeat N]
"""

import argparse
import json
import statistics
import sys
import time

import numpy as np
import OpenEXR


def read_frame(path):
    """Colour, albedo and normal (or None) as float32 (H, W, 3) arrays."""
    with OpenEXR.File(path, separate_channels=True) as f:
        ch = f.channels()

        def group(names):
            found = [n for n in names if n in ch]
            if not found:
                return None
            if len(found) != 3:
                sys.exit(f"{path}: channel group {names} is incomplete (has {found})")
            return np.ascontiguousarray(
                np.stack([np.asarray(ch[n].pixels, dtype=np.float32) for n in names], axis=-1)
            )

        colour = group(["R", "G", "B"])
        if colour is None:
            sys.exit(f"{path}: no R, G, B channels")
        return (
            colour,
            group(["albedo.R", "albedo.G", "albedo.B"]),
            group(["normal.X", "normal.Y", "normal.Z"]),
        )


def sanitise(img, lo, hi):
    out = np.where(np.isfinite(img), img, 0.0).astype(np.float32)
    return np.ascontiguousarray(np.clip(out, lo, hi))


def write_rgb(path, img):
    chans = {c: np.ascontiguousarray(img[..., i], dtype=np.float32) for i, c in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, chans) as f:
        f.write(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--quality", choices=["fast", "balanced", "high"], default="high")
    ap.add_argument("--aux", choices=["on", "off"], default="on")
    ap.add_argument("--clean-aux", action="store_true")
    ap.add_argument("--ldr", action="store_true", help="colour is in [0,1] (hdr=off)")
    ap.add_argument("--repeat", type=int, default=3, help="warm calls timed after the first")
    a = ap.parse_args()

    colour, albedo, normal = read_frame(a.input)
    colour = sanitise(colour, 0.0, 1.0 if a.ldr else np.finfo(np.float32).max)
    if a.aux == "off":
        albedo = normal = None
    albedo = None if albedo is None else sanitise(albedo, 0.0, 1.0)
    # OIDN takes a normal image only together with albedo.
    normal = None if normal is None or albedo is None else sanitise(normal, -1.0, 1.0)

    t = time.perf_counter()
    import pyoidn  # loads libOpenImageDenoise lazily, on the first call below

    load_s = time.perf_counter() - t

    def run():
        return pyoidn.denoise(
            colour, albedo, normal, hdr=not a.ldr, clean_aux=a.clean_aux, quality=a.quality
        )

    t = time.perf_counter()
    out = run()
    first_s = time.perf_counter() - t
    runs = []
    for _ in range(max(a.repeat, 0)):
        t = time.perf_counter()
        out = run()
        runs.append(time.perf_counter() - t)
    write_rgb(a.output, out)
    h, w = colour.shape[:2]
    print(
        json.dumps(
            {
                "denoiser": "pyoidn",
                "input": a.input,
                "width": w,
                "height": h,
                "quality": a.quality,
                "aux": [n for n, v in (("albedo", albedo), ("normal", normal)) if v is not None],
                "hdr": not a.ldr,
                "clean_aux": a.clean_aux,
                "load_s": load_s,
                "first_s": first_s,
                "runs_s": runs,
                "median_s": statistics.median(runs) if runs else first_s,
            }
        )
    )


if __name__ == "__main__":
    main()
