#!/usr/bin/env python3
"""Rays per second of closest-hit queries from NumPy through rt_renderer.Accel, against
`render bench-accel` on the same rays and against embreex (Embree 4 from Python), in one run.

    python tools/bench/python_rays.py [MESH] [--rays 1000000] [--accel bvh8] [--repeat 3] [--rounds 3]

The rays are bench-accel's uniform set (origins uniform in the mesh's bounds, directions
uniform on the sphere): bench-accel writes them with --dump-rays and this script traces that
file, so all three trace the same rays. Each is timed on one thread by CPU time (bench-accel's
--cpu-time; on a shared machine wall time also counts waiting for a core) and on all cores by
wall time (embreex's `run` traces on the calling thread only), best of --repeat, and the three
are measured in interleaved rounds, the median round reported. The NumPy-side times include everything a caller pays: reading the arrays and
allocating the result arrays. Hit counts are compared, so a faster wrong answer shows.
Needs: the module (pip install ./python), numpy, embreex, and target/release/render.
"""

import argparse
import csv
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]


def best_of(repeat, f, clock):
    """The shortest of `repeat` calls of `f` by `clock`, and the last result."""
    best, result = float("inf"), None
    for _ in range(repeat):
        t = clock()
        result = f()
        best = min(best, clock() - t)
    return best, result


def bench_accel(args, side, tmp):
    """One `render bench-accel` run: {threads: seconds} (one thread by CPU time, all cores by
    wall time, as --cpu-time does) and the hit count."""
    table = os.path.join(tmp, "bench.csv")
    cmd = [args.render, "bench-accel", args.mesh, "-q", "--rays", "uniform", "--cpu-time",
           "--accel", args.accel, "--width", str(side), "--height", str(side), "--check", "0",
           "--repeat", str(args.repeat), "--dump-rays", tmp, "--csv", table]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(table, newline="") as f:
        rows = list(csv.DictReader(f))
    return {int(r["threads"]): float(r["seconds"]) for r in rows}, int(rows[0]["hits"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", nargs="?", default=str(ROOT.parent / "shared/data/models/stanford-dragon.obj"))
    ap.add_argument("--rays", type=int, default=1_000_000, help="number of rays (a square count)")
    ap.add_argument("--accel", default="bvh8")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per measurement; the fastest counts")
    ap.add_argument("--rounds", type=int, default=3,
                    help="rounds of all three, interleaved; the median round counts")
    ap.add_argument("--render", default=str(ROOT / "target/release/render"))
    args = ap.parse_args()

    import rt_renderer as rt

    try:
        from embreex import mesh_construction, rtcore_scene
    except ImportError:
        rtcore_scene = None
        print("embreex: not installed (pip install embreex); measuring without it")

    side = int(round(args.rays ** 0.5))
    threads = os.cpu_count()
    tris = rt.Scene.load(args.mesh).triangles()
    ours = {1: rt.Accel(tris, args.accel, threads=1), threads: rt.Accel(tris, args.accel, threads=threads)}
    if rtcore_scene:
        e_scene = rtcore_scene.EmbreeScene()
        mesh_construction.TriangleMesh(e_scene, tris.astype(np.float32))
    rates = {}  # (who, threads) -> list of rays per second, one per round

    def note(key, n, seconds):
        rates.setdefault(key, []).append(n / seconds)

    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            cli, cli_hits = bench_accel(args, side, tmp)
            rays = np.fromfile(os.path.join(tmp, "uniform.bin"), dtype="<f4").reshape(-1, 6)
            o, d = np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:])
            n = len(rays)
            for t, seconds in cli.items():
                note(("render bench-accel", t), n, seconds)
            # One thread by the process's CPU time (the worker's, and the caller's waiting),
            # all cores by wall time, as bench-accel times them.
            for t, clock in ((1, time.process_time), (threads, time.perf_counter)):
                seconds, hits = best_of(args.repeat, lambda: ours[t].intersect(o, d), clock)
                note(("rt_renderer.Accel.intersect", t), n, seconds)
                got = int((hits["triangle"] != rt.MISS).sum())
                if got != cli_hits:
                    sys.exit(f"hit counts differ: {got} from Python, {cli_hits} from bench-accel")
            if rtcore_scene:
                # embreex traces on the calling thread: CPU time and wall time of one thread.
                for label, clock in (("cpu", time.process_time), ("wall", time.perf_counter)):
                    seconds, out = best_of(args.repeat, lambda: e_scene.run(o, d, output=1), clock)
                    note((f"embreex EmbreeScene.run(output=1) [{label}]", 1), n, seconds)
                e_hits = int((out["primID"] >= 0).sum())
                if e_hits != cli_hits:
                    print(f"note: embreex hits {e_hits} rays, bench-accel {cli_hits}")
            print(f"round {r + 1}/{args.rounds}: load {os.getloadavg()[0]:.1f}", file=sys.stderr)

    median = {k: statistics.median(v) for k, v in rates.items()}
    print(f"mesh {args.mesh}: {len(tris)} triangles, {n} uniform rays (bench-accel's), "
          f"{args.accel}, best of {args.repeat}, median of {args.rounds} rounds")
    for (who, t), rate in median.items():
        print(f"{who:45s} {t} thread(s): {rate / 1e6:7.3f} Mrays/s")
    for t in (1, threads):
        ratio = median[("rt_renderer.Accel.intersect", t)] / median[("render bench-accel", t)]
        print(f"rt_renderer / bench-accel, {t} thread(s): {ratio:.3f}x")
    if rtcore_scene:
        e = median[("embreex EmbreeScene.run(output=1) [wall]", 1)]
        e_cpu = median[("embreex EmbreeScene.run(output=1) [cpu]", 1)]
        print(f"rt_renderer ({threads} threads) / embreex (wall): "
              f"{median[('rt_renderer.Accel.intersect', threads)] / e:.2f}x")
        print(f"rt_renderer / embreex, one thread each (CPU time): "
              f"{median[('rt_renderer.Accel.intersect', 1)] / e_cpu:.2f}x")


if __name__ == "__main__":
    main()
