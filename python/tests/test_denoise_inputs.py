"""Every denoiser runs on bare NumPy arrays: a render hands over what its denoiser read
(`inputs=True`), and `rt.denoise` / `rt.denoise_sequence` on those arrays, saved and loaded
back, give the render's images bit for bit; bad arrays raise naming the array."""

import copy

import numpy as np
import pytest

import rt_renderer as rt
from conftest import ROOT


def small(tmp_path_factory, name, size=(64, 48)):
    """A copy of scenes/NAME.toml with every camera at `size` (sequences render at the
    camera's resolution)."""
    text = (ROOT / "scenes" / f"{name}.toml").read_text()
    assert "resolution = [256, 256]" in text
    path = tmp_path_factory.mktemp("scenes") / f"{name}.toml"
    path.write_text(text.replace("resolution = [256, 256]", f"resolution = [{size[0]}, {size[1]}]"))
    return path


def through_a_file(tmp_path, inputs):
    """The inputs saved as .npz files and loaded back: plain arrays, nothing of the render."""
    def flatten(d, prefix=""):
        for k, v in d.items():
            if isinstance(v, dict):
                yield from flatten(v, f"{prefix}{k}/")
            elif isinstance(v, list):
                for j, e in enumerate(v):
                    yield from flatten(e, f"{prefix}{k}/{j}/")
            else:
                yield f"{prefix}{k}", v

    def unflatten(arrays):
        out = {}
        for key, v in arrays.items():
            *path, last = key.split("/")
            d = out
            for p in path:
                d = d.setdefault(p, {})
            d[last] = v
        return fix_lists(out)

    def fix_lists(d):
        if isinstance(d, dict) and d and all(k.isdigit() for k in d):
            return [fix_lists(d[str(j)]) for j in range(len(d))]
        return {k: fix_lists(v) for k, v in d.items()} if isinstance(d, dict) else d

    back = []
    for k, frame in enumerate(inputs):
        path = tmp_path / f"input_{k}.npz"
        np.savez(path, **dict(flatten(frame)))
        with np.load(path) as f:
            back.append(unflatten({key: f[key] for key in f.files}))
    return back


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(
        a.view(np.uint32), b.view(np.uint32))


@pytest.fixture(scope="module")
def mirror_hall(tmp_path_factory):
    """Three frames of the mirror hall's fly-through at 2 spp denoised by SVGF, with the
    denoiser's inputs: mirrors (reflected guides), a moving camera, further samples."""
    scene = small(tmp_path_factory, "hall-mirror")
    frames = rt.Scene.load(scene).render(frames=range(0, 3), spp=2, denoiser="svgf",
                                         inputs=True)
    return scene, frames


@pytest.fixture(scope="module")
def dynamic(tmp_path_factory):
    """Three frames of the dynamic room at 1 spp (moving objects: object ids and motion)."""
    scene = small(tmp_path_factory, "dynamic-small", (48, 40))
    return rt.Scene.load(scene).render(frames=range(4, 7), spp=1, denoiser="svgf",
                                       inputs=True)


def test_svgf_on_arrays_equals_svgf_through_a_scene(mirror_hall, dynamic, tmp_path):
    for frames, spp in ((mirror_hall[1], 2), (dynamic, 1)):
        inputs = [f["input"] for f in frames]
        g = inputs[1]["guides"]
        assert sorted(g) == sorted(["depth", "position", "normal", "albedo", "emission",
                                    "motion", "previous_depth", "object", "instance",
                                    "roughness", "reflected"])
        assert g["motion"].shape == (*frames[0]["image"].shape[:2], 2)
        assert g["object"].dtype == np.uint32
        assert np.any(g["motion"] != 0), "the scene moves: motion vectors are not all zero"
        assert len(inputs[0].get("extra", [])) == spp - 1
        ours = rt.denoise_sequence(through_a_file(tmp_path, inputs), "svgf")
        assert len(ours) == len(frames)
        for k, (a, f) in enumerate(zip(ours, frames)):
            assert same_bits(a, f["image"]), f"frame {k} differs"
    assert np.any(mirror_hall[1][1]["input"]["guides"]["reflected"]["distance"] > 0), \
        "the mirror hall has mirror pixels"


def test_svgf_on_arrays_carries_its_history_and_reads_every_guide(mirror_hall):
    frames = mirror_hall[1]
    inputs = [f["input"] for f in frames]
    last = frames[2]["image"]
    alone = rt.denoise_sequence(inputs[2:], "svgf")[0]
    assert not same_bits(alone, last), "frame 2 without its history gave the same image"
    # The guides SVGF reads change its output when they change (each would also break the
    # test above if the arrays went through the wrong way).
    for key in ("motion", "normal", "depth", "previous_depth", "object"):
        spoilt = copy.deepcopy(inputs)
        a = spoilt[2]["guides"][key]
        spoilt[2]["guides"][key] = (a[::-1] if key != "motion" else a[..., ::-1]).copy()
        assert not same_bits(rt.denoise_sequence(spoilt, "svgf")[2], last), key
    spoilt = copy.deepcopy(inputs)
    for f in spoilt:
        del f["extra"]
    assert not same_bits(rt.denoise_sequence(spoilt, "svgf")[2], last), "extra"


def test_a_single_frame_spec_in_a_sequence_is_the_frame_denoised_alone(mirror_hall):
    inputs = [f["input"] for f in mirror_hall[1]]
    for spec in ("box", "atrous:iterations=2"):
        if spec.startswith("atrous"):
            g = "albedo", "normal", "position"
            inputs = [dict(i, **{k: i["guides"][k] for k in g}) for i in inputs]
        ours = rt.denoise_sequence(iter(inputs), spec)
        for a, i in zip(ours, inputs):
            assert same_bits(a, rt.denoise(i, spec))


@pytest.mark.parametrize("kind", rt.denoisers())
def test_every_denoiser_on_its_render_input_gives_the_render(small_cornell, kind):
    frame = rt.Scene.load(small_cornell).render(spp=4, denoiser=kind, inputs=True)
    ours = rt.denoise(frame["input"], kind)
    assert same_bits(ours, frame["image"])
    assert not same_bits(ours, frame["input"]["image"]), "the denoiser changed nothing"
    if kind == "sbmf":
        s = frame["input"]["samples"]
        n = len(s["pixel"])
        assert s["pixel"].dtype == np.uint32 and 0.9 * 4 * 48 * 40 <= n <= 4 * 48 * 40
        assert s["radiance"].shape == (n, 3) and s["coc"].shape == (n,)


def test_bad_sequence_arguments_raise_naming_the_array(mirror_hall):
    good = [f["input"] for f in mirror_hall[1]][:2]

    def spoilt(change):
        frames = copy.deepcopy(good)
        change(frames[1])
        return frames

    def raises(kind, match, frames, spec="svgf"):
        with pytest.raises(kind, match=match):
            rt.denoise_sequence(frames, spec)

    raises(rt.RtError, r"frames\[1\]: .*svgf needs the frame's guide buffers",
           spoilt(lambda f: f.pop("guides")))
    raises(ValueError, r'frames\[1\]\["guides"\]: no "motion" array \(expected shape \[48, 64, 2\]\)',
           spoilt(lambda f: f["guides"].pop("motion")))
    raises(ValueError, r'frames\[1\]\["guides"\]\["motion"\]: shape \[48, 64, 3\], expected \[48, 64, 2\]',
           spoilt(lambda f: f["guides"].update(motion=np.zeros((48, 64, 3), np.float32))))
    raises(ValueError, r'frames\[1\]\["guides"\]\["reflected"\]\["distance"\]: shape \[40, 64\]',
           spoilt(lambda f: f["guides"]["reflected"].update(
               distance=f["guides"]["reflected"]["distance"][:40])))
    raises(ValueError, r'frames\[1\]\["guides"\]: unknown array "moton"',
           spoilt(lambda f: f["guides"].update(moton=f["guides"]["motion"])))
    raises(ValueError, r'frames\[1\]\["guides"\]\["object"\]: values must be in 0..2\^32',
           spoilt(lambda f: f["guides"].update(object=-np.ones((48, 64), np.int64))))
    raises(ValueError, r'frames\[1\]\["guides"\]\["object"\]: expected integers',
           spoilt(lambda f: f["guides"].update(object=np.zeros((48, 64), np.float32))))
    raises(rt.RtError, r"frames\[1\]: .*not finite",
           spoilt(lambda f: f["guides"]["depth"].__setitem__((3, 4), np.nan)))
    raises(rt.RtError, r"frames\[1\]: .*needs the direct channel",
           spoilt(lambda f: f.pop("direct")))
    raises(rt.RtError, r'frames\[1\]\["extra"\]\[0\]: svgf needs the albedo channel',
           spoilt(lambda f: f["extra"][0].pop("albedo")))
    raises(ValueError, r'frames\[1\]\["extra"\]\[0\]\["normal"\]: 32x48 pixels',
           spoilt(lambda f: f["extra"][0].update(normal=f["extra"][0]["normal"][:, :32].copy())))
    raises(ValueError, r'frames\[1\]\["extra"\]: expected a list', spoilt(lambda f: f.update(extra=3)))
    raises(ValueError, r'frames\[1\]\["guides"\]: expected a dict', spoilt(lambda f: f.update(guides=[])))
    raises(ValueError, r"frames\[0\]: expected a dict", [good[0]["image"]])
    raises(ValueError, "frames: expected a list", 3)
    raises(rt.RtError, "denoiser=svgf:alpha=3: .*alpha", good, "svgf:alpha=3")
    raises(rt.RtError, "denoiser=blur", good, "blur")


def test_bad_sample_records_and_inputs_requests_raise(small_cornell):
    scene = rt.Scene.load(small_cornell)
    frame = scene.render(spp=1, denoiser="sbmf", inputs=True)["input"]

    def raises(match, change):
        f = copy.deepcopy(frame)
        change(f["samples"])
        with pytest.raises(ValueError, match=match):
            rt.denoise(f, "sbmf")

    raises(r'frame\["samples"\]: no "coc" array', lambda s: s.pop("coc"))
    raises(r'frame\["samples"\]\["radiance"\]: shape \[\d+, 2\], expected \[\d+, 3\]',
           lambda s: s.update(radiance=s["radiance"][:, :2]))
    raises(r'frame\["samples"\]: sample 0: pixel 1920 is outside the 48x40 image',
           lambda s: s["pixel"].__setitem__(0, 1920))
    with pytest.raises(ValueError, match="inputs=True .* no denoiser"):
        scene.render(spp=1, denoiser="none", inputs=True)
    assert "input" not in scene.render(spp=1, denoiser="box")
