"""Shared fixtures: the repository, the `render` binary the images are compared with, small
scenes and an EXR reader independent of the module (OpenEXR when installed)."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import rt_renderer as rt

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def render_bin():
    """The CLI (`RT_RENDER`, else target/release/render; .ci/python builds it)."""
    path = pathlib.Path(os.environ.get("RT_RENDER", ROOT / "target" / "release" / "render"))
    if not path.exists():
        pytest.fail(f"{path}: no render binary (cargo build --release -p rt-cli)")
    return path


def run_cli(render_bin, *args):
    """Runs `render ARGS...` from the repository root; fails the test with its stderr."""
    r = subprocess.run([str(render_bin), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.fixture(scope="session")
def small_cornell(tmp_path_factory):
    """The Cornell box at 48x40 pixels (its [render] table kept: 32 spp, NL-means)."""
    text = (ROOT / "scenes" / "cornell-box.toml").read_text()
    assert "resolution = [512, 512]" in text
    path = tmp_path_factory.mktemp("scenes") / "cornell-small.toml"
    path.write_text(text.replace("resolution = [512, 512]", "resolution = [48, 40]"))
    return path


def read_exr_independent(path):
    """Every channel of an EXR as name -> (height, width) float32 array, read by OpenEXR when
    installed (a reader that is not the module's), else by the module."""
    try:
        import OpenEXR
    except ImportError:
        frame = rt.read_exr(path)
        out = {}
        for key, a in frame.items():
            if a.ndim == 2:
                out["depth.Z" if key == "depth" else key] = a
            else:
                comps = "XYZ" if key in ("normal", "position", "normal_variance",
                                         "position_variance") else "RGB"
                for k, c in enumerate(comps):
                    out[c if key == "image" else f"{key}.{c}"] = a[:, :, k]
        return out
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {name: np.asarray(ch.pixels, dtype=np.float32)
                for name, ch in f.channels().items()}


def frame_channels(frame):
    """A frame dict split into the EXR's channel names."""
    out = {}
    for key, a in frame.items():
        if a.ndim == 2:
            out[f"{key}.Z" if key in ("depth", "depth_variance") else key] = a
            continue
        comps = "XYZ" if key in ("normal", "position", "normal_variance",
                                 "position_variance") else "RGB"
        for k, c in enumerate(comps):
            out[c if key == "image" else f"{key}.{c}"] = a[:, :, k]
    return out


def assert_same_bits(frame, exr_path):
    """Every channel of `frame` equals the file's bit for bit, and they have the same names."""
    theirs = read_exr_independent(exr_path)
    ours = frame_channels(frame)
    assert sorted(ours) == sorted(theirs)
    for name, a in ours.items():
        b = theirs[name]
        assert a.dtype == np.float32 and a.shape == b.shape, name
        assert np.array_equal(a.view(np.uint32), b.view(np.uint32)), f"channel {name} differs"
