"""Denoising, metrics and experiments on NumPy arrays give what the CLI gives."""

import json

import numpy as np
import pytest

import rt_renderer as rt
from conftest import ROOT, read_exr_independent, run_cli


@pytest.fixture(scope="module")
def noisy(render_bin, small_cornell, tmp_path_factory):
    """A frame with every channel a denoiser reads, from the module and as the CLI's EXR."""
    out = tmp_path_factory.mktemp("noisy") / "noisy.exr"
    run_cli(render_bin, small_cornell, "-q", "--spp", "4", "--denoiser", "none",
            "--aov", "denoise", "-o", out)
    frame = rt.Scene.load(small_cornell).render(spp=4, denoiser="none", aovs=["denoise"])
    return frame, out


@pytest.mark.parametrize("kind", [k for k in rt.denoisers() if k != "sbmf"])
def test_denoise_equals_render_denoise(render_bin, noisy, tmp_path, kind):
    frame, exr = noisy
    out = tmp_path / "clean.exr"
    run_cli(render_bin, "denoise", exr, "--denoiser", kind, "-o", out)
    theirs = read_exr_independent(out)
    ours = rt.denoise(frame, kind)
    assert ours.shape == frame["image"].shape and ours.dtype == np.float32
    for k, c in enumerate("RGB"):
        assert np.array_equal(ours[:, :, k].view(np.uint32), theirs[c].view(np.uint32)), c
    assert not np.array_equal(ours, frame["image"]), "the denoiser changed nothing"


def test_sbmf_needs_sample_records_and_says_so(noisy):
    with pytest.raises(rt.RtError, match="samples"):
        rt.denoise(noisy[0], "sbmf")


def test_denoise_refuses_bad_frames_and_specs(noisy):
    frame = noisy[0]
    with pytest.raises(rt.RtError, match="denoiser=blur"):
        rt.denoise(frame, "blur")
    with pytest.raises(rt.RtError, match="radius"):
        rt.denoise(frame, "box:radius=-3")
    with pytest.raises(rt.RtError, match="needs the normal channel"):
        rt.denoise({"image": frame["image"]}, "atrous")
    with pytest.raises(ValueError, match="pixels"):
        rt.denoise({"image": frame["image"], "albedo": frame["albedo"][:10]}, "atrous")
    with pytest.raises(ValueError, match="shape"):
        rt.denoise({"image": frame["image"][:, :, :2]}, "box")


def test_compare_equals_render_compare(render_bin, noisy, tmp_path):
    frame, exr = noisy
    ref = tmp_path / "ref.exr"
    run_cli(render_bin, "denoise", exr, "--denoiser", "nlm", "-o", ref)
    theirs = json.loads(run_cli(render_bin, "compare", exr, ref, "--json", "--epsilon", "0.02"))
    ours = rt.compare(frame["image"], rt.read_exr(ref)["image"], epsilon=0.02)
    for k in ("mse", "relmse", "rmse", "psnr", "ssim"):
        assert ours[k] == theirs[k], k
    same = rt.compare(frame["image"], frame["image"])
    assert same["mse"] == 0.0 and same["psnr"] == float("inf") and same["ssim"] == 1.0


def test_compare_refuses_mismatched_images():
    a = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(rt.RtError):
        rt.compare(a, np.zeros((4, 5, 3), np.float32))
    with pytest.raises(ValueError, match="height, width, 3"):
        rt.compare(a, np.zeros((4, 4), np.float32))


EXPERIMENT = """
name = "tiny"

[[scene]]
name = "cornell"
path = "{scene}"
scale = 0.25
reference = {{ spp = 8, integrator = "path", max_depth = 3 }}

[[method]]
name = "path"
integrator = "path"
max_depth = 3
spp = [1, 2]

[[method]]
name = "direct"
integrator = "direct"
spp = [1, 2]
"""


def test_an_experiment_returns_the_rows_of_its_results_csv(small_cornell, tmp_path):
    config = tmp_path / "tiny.toml"
    config.write_text(EXPERIMENT.format(scene=small_cornell))
    out = tmp_path / "out"
    rows = rt.run_experiment(config, out=out, cache=tmp_path / "cache", as_frame=False)
    assert len(rows) == 4
    assert sorted((r["method"], r["budget"]) for r in rows) == [
        ("direct", 1), ("direct", 2), ("path", 1), ("path", 2)]
    assert all(r["relmse"] > 0 for r in rows)
    lines = (out / "results.csv").read_text().splitlines()
    assert len(lines) == 1 + len(rows)
    pandas = pytest.importorskip("pandas")
    frame = rt.run_experiment(config, out=tmp_path / "out2", cache=tmp_path / "cache")
    assert isinstance(frame, pandas.DataFrame) and len(frame) == 4


def test_a_bad_experiment_raises_naming_the_file(tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text('name = "x"\n[[scene]]\nname = "a"\n')
    with pytest.raises(rt.RtError, match="bad.toml"):
        rt.run_experiment(config, out=tmp_path / "out")
