"""Scenes built from TOML text and arrays, and changed in place between renders."""

import numpy as np
import pytest

import rt_renderer as rt
from conftest import ROOT, assert_same_bits, run_cli


def test_set_camera_renders_what_a_file_with_that_camera_renders(render_bin, small_cornell, tmp_path):
    text = small_cornell.read_text()
    scene = rt.Scene.load(small_cornell)
    cam = scene.camera()
    moved = [cam["position"][0] + 0.5, cam["position"][1], cam["position"][2]]
    target = [0.5 + cam["position"][0] + cam["forward"][0], cam["position"][1] + cam["forward"][1],
              cam["position"][2] + cam["forward"][2]]
    before = scene.render(spp=2, denoiser="none")["image"]
    scene.set_camera(position=moved, look_at=target, up=cam["up"])
    after = scene.render(spp=2, denoiser="none")
    assert not np.array_equal(before, after["image"])
    # The same camera written into the file, rendered by the CLI.
    import re
    block = re.search(r"\[\[camera\]\].*?(?=\n\[)", text, re.S).group(0)
    new_block = re.sub(r"position = \[[^\]]*\]", f"position = {moved!r}", block)
    new_block = re.sub(r"look_at = \[[^\]]*\]", f"look_at = {target!r}", new_block)
    new_block = re.sub(r"up = \[[^\]]*\]", f"up = {list(cam['up'])!r}", new_block)
    if "up =" not in new_block:
        new_block += f"\nup = {list(cam['up'])!r}"
    path = tmp_path / "moved.toml"
    path.write_text(text.replace(block, new_block))
    out = tmp_path / "moved.exr"
    run_cli(render_bin, path, "-q", "--spp", "2", "--denoiser", "none", "-o", out)
    assert_same_bits(after, out)


def test_set_camera_refuses_bad_values(small_cornell):
    scene = rt.Scene.load(small_cornell)
    pos = scene.camera()["position"]
    for kwargs, message in [
        (dict(look_at=pos), "look_at equals position"),
        (dict(fov=200.0), "fov"),
        (dict(resolution=(0, 10)), "resolution"),
        (dict(name="nowhere"), "nowhere"),
        (dict(position=[float("nan"), 0, 0]), "finite"),
    ]:
        with pytest.raises((rt.RtError, ValueError), match=message):
            scene.set_camera(**kwargs)


MESH_SCENE = """
[environment]
color = [1.0, 1.0, 1.0]

[[camera]]
name = "main"
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov = 40.0
resolution = [32, 24]

[[material]]
name = "grey"
color = [0.5, 0.5, 0.5]

[[geometry]]
name = "tri"
material = "grey"
positions = {positions}
indices = {indices}
"""


def mesh_scene(positions, indices):
    return rt.Scene.from_toml(MESH_SCENE.format(positions=positions.tolist(), indices=indices.tolist()))


def test_an_inline_mesh_from_arrays_and_a_transform():
    positions = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32)
    indices = np.array([[0, 1, 2]])
    scene = mesh_scene(positions, indices)
    assert np.array_equal(scene.triangles()[0], positions)
    image = scene.render(spp=1)["image"]
    assert image[12, 16].max() < image[0, 0].max(), "the triangle is in front of the sky"
    m = np.eye(4, dtype=np.float32)
    m[:3, 3] = [5, 0, 0]
    scene.transform("tri", m)
    assert np.allclose(scene.triangles()[0], positions + [5, 0, 0])
    moved = scene.render(spp=1)["image"]
    assert np.allclose(moved, moved[0, 0]), "the triangle left the view"
    with pytest.raises(ValueError, match="no object"):
        scene.transform("nothing", m)
    with pytest.raises(ValueError, match="affine"):
        scene.transform("tri", np.ones((4, 4)))


def test_bad_toml_text_raises_with_the_line():
    with pytest.raises(rt.RtError, match="<python>.toml"):
        rt.Scene.from_toml("[[camera]]\nname = 1\n")
