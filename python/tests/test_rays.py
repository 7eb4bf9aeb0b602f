"""Accel: ray queries over NumPy triangles answer as the Rust structures do."""

import csv

import numpy as np
import pytest

import rt_renderer as rt
from conftest import ROOT, run_cli


def random_mesh(n=300, seed=1):
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1, 1, (n, 1, 3))
    return (centres + rng.normal(0, 0.15, (n, 3, 3))).astype(np.float32)


def random_rays(n=5000, seed=2):
    rng = np.random.default_rng(seed)
    o = rng.uniform(-1.5, 1.5, (n, 3)).astype(np.float32)
    d = rng.normal(size=(n, 3)).astype(np.float32)
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def moller_trumbore(tris, o, d):
    """A NumPy closest-hit reference (float64), independent of the renderer."""
    tris, o, d = tris.astype(np.float64), o.astype(np.float64), d.astype(np.float64)
    best = np.full(len(o), np.inf)
    prim = np.full(len(o), rt.MISS, dtype=np.uint64)
    for i, (p0, p1, p2) in enumerate(tris):
        e1, e2 = p1 - p0, p2 - p0
        p = np.cross(d, e2)
        det = p @ e1
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - p0
            u = (s * p).sum(1) * inv
            q = np.cross(s, e1)
            v = (d * q).sum(1) * inv
            t = (q @ e2) * inv
        ok = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0) & (t < best)
        best[ok], prim[ok] = t[ok], i
    return best, prim


def test_closest_hits_match_an_independent_reference():
    tris = random_mesh()
    o, d = random_rays()
    hits = rt.Accel(tris, "bvh8").intersect(o, d)
    t_ref, prim_ref = moller_trumbore(tris, o, d)
    hit = hits["triangle"] != rt.MISS
    assert np.array_equal(hit, np.isfinite(t_ref))
    assert 0.2 < hit.mean() < 0.9
    same = hits["triangle"][hit] == prim_ref[hit]
    assert same.mean() > 0.999
    assert np.allclose(hits["t"][hit], t_ref[hit], rtol=1e-5)
    # The barycentrics place the hit point on the triangle.
    p = o[hit] + hits["t"][hit, None] * d[hit]
    tri = tris[hits["triangle"][hit].astype(np.int64)]
    u, v = hits["u"][hit, None], hits["v"][hit, None]
    q = (1 - u - v) * tri[:, 0] + u * tri[:, 1] + v * tri[:, 2]
    assert np.allclose(p, q, atol=1e-4)
    assert np.all(np.isinf(hits["t"][~hit]))


def test_the_reference_comparison_sees_a_wrong_answer():
    """Control: a structure over a mesh with one triangle moved gives answers the check refuses."""
    tris = random_mesh()
    o, d = random_rays()
    moved = tris.copy()
    moved[::7] += np.float32(0.05)
    hits = rt.Accel(moved, "bvh8").intersect(o, d)
    t_ref, prim_ref = moller_trumbore(tris, o, d)
    hit = np.isfinite(t_ref)
    assert not np.array_equal(hits["triangle"] != rt.MISS, hit) or not np.allclose(
        hits["t"][hit], t_ref[hit], rtol=1e-5)


@pytest.mark.parametrize("kind", rt.accel_kinds())
def test_every_structure_agrees_with_brute_force(kind):
    tris = random_mesh(200, seed=3)
    o, d = random_rays(3000, seed=4)
    ref = rt.Accel(tris, "brute-force").intersect(o, d)
    got = rt.Accel(tris, kind).intersect(o, d)
    assert np.array_equal(got["triangle"] != rt.MISS, ref["triangle"] != rt.MISS)
    assert np.allclose(got["t"], ref["t"], rtol=1e-5)
    occ = rt.Accel(tris, kind).occluded(o, d * 0.5)
    assert np.array_equal(occ, ref["t"] <= 0.5)


def test_indexed_vertices_equal_triangle_arrays_and_threads_do_not_matter():
    rng = np.random.default_rng(5)
    vertices = rng.uniform(-1, 1, (100, 3)).astype(np.float32)
    faces = rng.integers(0, 100, (150, 3))
    o, d = random_rays(2000, seed=6)
    a = rt.Accel(vertices, "qbvh", indices=faces, threads=1).intersect(o, d)
    b = rt.Accel(vertices[faces], "qbvh", threads=2).intersect(o, d)
    for k in ("t", "triangle", "u", "v"):
        assert np.array_equal(a[k], b[k]), k


def test_per_ray_tmax():
    tris = random_mesh()
    o, d = random_rays()
    accel = rt.Accel(tris)
    full = accel.intersect(o, d)
    tmax = np.where(np.arange(len(o)) % 2 == 0, np.inf, 0.1).astype(np.float32)
    part = accel.intersect(o, d, tmax)
    keep = full["t"] <= tmax
    assert np.array_equal(part["t"][keep], full["t"][keep])
    assert np.all(part["triangle"][~keep] == rt.MISS)


def test_uniform_rays_and_hits_equal_bench_accel(render_bin, tmp_path):
    """The uniform set is bench-accel's bit for bit, and tracing it over the scene's triangles
    hits as many rays as bench-accel's bvh8 reports."""
    scene = ROOT / "scenes" / "cornell-box.toml"
    table = tmp_path / "bench.csv"
    run_cli(render_bin, "bench-accel", scene, "-q", "--rays", "uniform", "--accel", "bvh8",
            "--width", "64", "--height", "64", "--repeat", "1", "--threads", "2",
            "--dump-rays", tmp_path, "--csv", table, "--check", "0")
    dumped = np.fromfile(tmp_path / "uniform.bin", dtype="<f4").reshape(-1, 6)
    tris = rt.Scene.load(scene).triangles()
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    o, d = rt.uniform_rays(lo, hi, len(dumped), seed=0)
    assert np.array_equal(o, dumped[:, :3]) and np.array_equal(d, dumped[:, 3:])
    hits = rt.Accel(tris, "bvh8").intersect(o, d)
    with open(table, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["rays"] == "uniform"]
    assert rows and all(int(r["hits"]) == int((hits["triangle"] != rt.MISS).sum()) for r in rows)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: rt.Accel(np.zeros((4, 3), np.float32)), "(n, 3, 3)"),
        (lambda: rt.Accel(np.full((1, 3, 3), np.nan, np.float32)), "finite"),
        (lambda: rt.Accel(random_mesh(), "octree"), "accel=octree"),
        (lambda: rt.Accel(np.zeros((3, 3)), indices=[[0, 1, 5]]), "out of range"),
        (lambda: rt.Accel(np.zeros((3, 3)), indices=[[0, 1, -1]]), "0..2^32"),
        (lambda: rt.Accel(np.zeros((3, 3)), indices=[[0.5, 1, 2]]), "integers"),
        (lambda: rt.Accel(random_mesh()).intersect(np.zeros((5, 3)), np.ones((4, 3))), "must match"),
        (lambda: rt.Accel(random_mesh()).intersect(np.zeros((5, 2)), np.ones((5, 2))), "(n, 3)"),
        (lambda: rt.Accel(random_mesh()).intersect(np.zeros((5, 3)), np.ones((5, 3)), [1, 2]),
         "tmax"),
        (lambda: rt.Accel(random_mesh()).occluded(np.zeros((1, 3)), np.ones((1, 3)), -1.0), "positive"),
        (lambda: rt.Accel(random_mesh(), threads=0), "threads"),
    ],
)
def test_bad_arguments_raise_clearly(call, message):
    with pytest.raises((rt.RtError, ValueError)) as e:
        call()
    assert message in str(e.value), str(e.value)
