"""rt_renderer: the rt renderer's library crates from Python, over NumPy arrays.

Render a scene (the same bits as ``render SCENE -o OUT.exr``)::

    import rt_renderer as rt
    scene = rt.Scene.load("scenes/cornell-box.toml")
    frame = scene.render(spp=16, denoiser="none", aovs=["albedo", "normal"], progress=print)
    frame["image"]          # (height, width, 3) float32: the EXR's R, G, B
    frame["albedo"]         # the AOVs, one entry per channel group of the EXR

Denoise, compare, run an experiment, trace rays::

    clean = rt.denoise(frame, "atrous")
    seq = scene.render(frames=range(3), denoiser="svgf", inputs=True)   # + what SVGF read
    again = rt.denoise_sequence([f["input"] for f in seq], "svgf")     # the same bits
    rt.compare(clean, reference)                  # mse, relmse, rmse, psnr, ssim
    rows = rt.run_experiment("configs/convergence.toml")   # a DataFrame with pandas
    accel = rt.Accel(triangles, "bvh8")           # (n, 3, 3) float32
    hits = accel.intersect(origins, directions)   # t, triangle, u, v arrays

A frame is a dict: ``"image"`` and one ``(height, width, 3)`` array per three-component
channel group of the EXR (``"albedo"``, ``"normal"``, ``"variance"``, ``"even"``, ...), one
``(height, width)`` array per single channel (``"depth"``). Errors of the library raise
:class:`RtError` with its one-line message. docs/python.md walks through each.
"""

from __future__ import annotations

import csv
import os

from ._native import (  # noqa: F401  (re-exported)
    Accel,
    RtError,
    Scene,
    __version__,
    accel_kinds,
    compare,
    denoise,
    denoise_sequence,
    denoisers,
    read_exr,
    uniform_rays,
)
from ._native import run_experiment as _run_experiment

#: ``Accel.intersect``'s triangle index of a ray that hit nothing.
MISS = 2**32 - 1

__all__ = [
    "Accel",
    "MISS",
    "RtError",
    "Scene",
    "accel_kinds",
    "compare",
    "denoise",
    "denoise_sequence",
    "denoisers",
    "load_scene",
    "read_exr",
    "run_experiment",
    "uniform_rays",
]


def load_scene(path, defines=None, confine=None) -> Scene:
    """``Scene.load``: a TOML scene, a Mitsuba XML scene or ``gen:NAME``."""
    return Scene.load(os.fspath(path), defines, confine)


def run_experiment(config, out=None, cache=None, threads=None, confine=None, as_frame=None):
    """Runs a TOML experiment as ``render experiment CONFIG`` does and returns its rows (those
    of ``results.csv``, one per run): a pandas DataFrame when pandas is installed (or
    ``as_frame=True``), else a list of dicts with numbers converted. The output folder (images,
    plots, reports) is ``out``, or the config's own."""
    folder = _run_experiment(os.fspath(config), out, cache, threads, confine)
    results = os.path.join(folder, "results.csv")
    if as_frame is None or as_frame:
        try:
            import pandas
        except ImportError:
            if as_frame:
                raise
        else:
            return pandas.read_csv(results)
    with open(results, newline="") as f:
        return [{k: _number(v) for k, v in row.items()} for row in csv.DictReader(f)]


def _number(text: str):
    """A CSV field as an int or float when it is one, else the text."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
