#!/usr/bin/env python3
"""Embree 4 (through the `embreex` wheel) on the same OBJ and ray files as accel-peers.

    pip install embreex numpy
    python3 tools/bench/embree_bench.py MESH.obj --rays DIR [--threads N] [--csv OUT.csv]
        [--hits DIR] [--check N]

Ray files (DIR/primary.bin, incoherent.bin, shadow.bin) hold six little-endian f32 per ray
(origin xyz, direction xyz); primary and incoherent are closest-hit queries over (0, inf),
shadow is occlusion over (0, 1). Triangles are read in our loader's order (every face in file
order, polygons fanned as tobj does), so triangle ids agree with ours.

What is measured, and how it differs from the Rust tools:
- build: the scene commit (Embree's default BVH build; the copy of the mesh into Embree's
  buffers by `TriangleMesh(...)` before it is reported separately). Embree builds
  with TBB, which sizes its thread pool from the process's CPU affinity, so the 1-thread rows
  run in a child process pinned to one CPU (`os.sched_setaffinity`, before embreex is
  imported); the N-thread rows in one allowed N CPUs. embreex creates its device with
  `rtcNewDevice(NULL)` and this wheel ignores `.embree4` config files, so "threads=1" cannot be
  passed through the device config; the affinity mask has the same effect on TBB.
- tracing: `EmbreeScene.run(origins, directions, dists, query, output)`, a Cython loop of
  `rtcIntersect1` / `rtcOccluded1` (single rays; Embree's packet and stream APIs are not
  exposed by embreex). It holds the GIL, so N-thread rows fork N worker processes after the
  build (sharing the scene copy-on-write), each tracing a contiguous 1/N of the rays; Mrays/s
  is all rays over the slowest worker's time. Times include embreex's per-ray Python/NumPy
  bookkeeping; the `embree-overhead` line measures it with rays that miss the scene's bounds.
- check: with --hits DIR (written by `accel-peers --dump-hits DIR`), Embree's closest-hit t is
  compared with our `bvh`'s for the first --check rays of each set (same hit/miss and t within
  1e-4 relative) and shadow answers are compared one to one.
- bytes: Embree does not report its memory through embreex; the column is left empty.
- mrays_per_cpu_s and build_cpu_ms (1-thread rows): the same work over CPU time rather than wall
  time (`time.thread_time()` around the trace, `time.process_time()` around the commit), which
  on a shared machine leaves out the time spent waiting for a core.
"""

import argparse
import multiprocessing as mp
import os
import sys
import time

import numpy as np

SETS = [("primary", False), ("incoherent", False), ("shadow", True)]
COLUMNS = ("accel,rays,threads,build_ms,bytes,mrays_per_s,hits,boxes_per_ray,leaves_per_ray,"
           "tris_per_ray,mrays_per_cpu_s,build_cpu_ms")


def load_obj(path):
    """Triangles (n, 3, 3) float32 in our loader's order: tobj with triangulate=True."""
    pos = []
    tris = []
    with open(path, "rb") as f:
        for raw in f:
            words = raw.decode("utf-8", "replace").split()
            if not words:
                continue
            key = words[0]
            if key == "v":
                x, y, z = (float(w) for w in words[1:4])
                if len(words) == 5:  # homogeneous w
                    w = float(words[4])
                    x, y, z = x / w, y / w, z / w
                pos.append((x, y, z))
            elif key in ("f", "l"):  # tobj parses `l` lines as faces too
                n = len(pos)
                idx = []
                for w in words[1:]:
                    i = int(w.split("/")[0])
                    idx.append(n + i if i < 0 else i - 1)
                if len(idx) < 3:
                    continue  # points and lines are ignored
                # tobj: triangle as is, quad (a,b,c),(a,c,d), polygon fanned around the first.
                for k in range(1, len(idx) - 1):
                    tris.append((idx[0], idx[k], idx[k + 1]))
    pos = np.asarray(pos, dtype=np.float32)
    return pos[np.asarray(tris, dtype=np.int64)]


def read_rays(path):
    a = np.fromfile(path, dtype="<f4")
    if a.size % 6:
        sys.exit(f"{path}: size is not a multiple of six f32")
    a = a.reshape(-1, 6)
    return np.ascontiguousarray(a[:, :3]), np.ascontiguousarray(a[:, 3:])


def trace(scene, o, d, shadow):
    """One pass of `run`; returns (answers, hits). Closest: tfar (inf on a miss); shadow: bool."""
    if shadow:
        ids = scene.run(o, d, dists=np.ones(len(o), np.float32), query="OCCLUDED")
        occ = ids != -1
        return occ, int(occ.sum())
    out = scene.run(o, d, output=1)
    hit = out["primID"] != -1
    t = np.where(hit, out["tfar"], np.inf).astype(np.float32)
    return t, int(hit.sum())


def worker(conn, barrier, scene, o, d, shadow, runs):
    """Forked tracer: wait for the others, trace its slice `runs` times, send the best time."""
    best = float("inf")
    for _ in range(runs):
        barrier.wait()
        start = time.perf_counter()
        _, hits = trace(scene, o, d, shadow)
        best = min(best, time.perf_counter() - start)
    conn.send((best, hits))
    conn.close()


def traced_parallel(scene, o, d, shadow, threads, runs):
    """Best-of-`runs` Mrays over N forked processes (each run synchronised by a barrier)."""
    ctx = mp.get_context("fork")
    barrier = ctx.Barrier(threads)
    parts = np.array_split(np.arange(len(o)), threads)
    procs = []
    for part in parts:
        parent, child = ctx.Pipe(duplex=False)
        p = ctx.Process(target=worker, args=(child, barrier, scene, o[part], d[part], shadow, runs))
        p.start()
        procs.append((p, parent))
    results = [conn.recv() for _, conn in procs]
    for p, _ in procs:
        p.join()
    # The slowest worker's best time bounds the run (each run starts at a barrier).
    return max(r[0] for r in results), sum(r[1] for r in results)


def bench(args, threads, queue):
    """Runs in a child process whose CPU affinity is `threads` CPUs, before embreex loads."""
    cpus = sorted(os.sched_getaffinity(0))[:threads]
    os.sched_setaffinity(0, cpus)
    from embreex import mesh_construction, rtcore_scene

    tris = load_obj(args.mesh)
    tasks = len(os.listdir("/proc/self/task"))
    start = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    mesh_construction.TriangleMesh(scene, tris)  # copies the vertices into Embree's buffers
    upload_ms = (time.perf_counter() - start) * 1e3
    start, cpu = time.perf_counter(), time.process_time()
    scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))  # commits the scene
    build_ms = (time.perf_counter() - start) * 1e3
    build_cpu_ms = (time.process_time() - cpu) * 1e3  # all threads of the process
    # CPU time over wall time shows how many threads the build really kept busy.
    busy = build_cpu_ms / build_ms

    rows, notes = [], []
    for name, shadow in SETS:
        path = os.path.join(args.rays, f"{name}.bin")
        if not os.path.exists(path):
            continue
        o, d = read_rays(path)
        cpu_mrays = build_cpu = ""
        if threads == 1:
            best = best_cpu = float("inf")
            for _ in range(args.runs):
                start, cpu = time.perf_counter(), time.thread_time()
                answers, hits = trace(scene, o, d, shadow)
                best = min(best, time.perf_counter() - start)
                best_cpu = min(best_cpu, time.thread_time() - cpu)
            cpu_mrays = f"{len(o) / best_cpu / 1e6:.4f}"
            build_cpu = f"{build_cpu_ms:.2f}"
            if args.hits:
                notes.append(check(args, name, shadow, answers))
        else:
            best, hits = traced_parallel(scene, o, d, shadow, threads, args.runs)
        rows.append(f"embree,{name},{threads},{build_ms:.2f},,{len(o) / best / 1e6:.4f},{hits},,,,"
                    f"{cpu_mrays},{build_cpu}")
    if threads == 1:
        # Per-ray cost of embreex itself: rays that start outside the bounds and point away.
        lo = tris.reshape(-1, 3).min(axis=0)
        n = 200_000
        o = np.tile(lo - 1.0, (n, 1)).astype(np.float32)
        d = np.tile(np.float32([-1.0, -1.0, -1.0]), (n, 1))
        start = time.perf_counter()
        trace(scene, o, d, False)
        notes.append(f"embree-overhead: {(time.perf_counter() - start) / n * 1e9:.0f} ns per "
                     "missing ray (embreex's loop and output arrays, no traversal)")
    notes.append(f"embree build with TBB allowed {threads} CPU(s): {build_ms:.1f} ms commit "
                 f"(the BVH build; {busy:.2f} CPUs busy on average, CPU time / wall time), "
                 f"after {upload_ms:.1f} ms copying the mesh in; the process has "
                 f"{len(os.listdir('/proc/self/task')) - tasks} more threads after it (TBB's workers)")
    queue.put((len(tris), rows, notes))


def check(args, name, shadow, answers):
    n = min(args.check, len(answers))
    if shadow:
        ours = np.fromfile(os.path.join(args.hits, f"{name}.occluded.u8"), np.uint8)[:n] != 0
        differ = int((ours != answers[:n]).sum())
    else:
        ours = np.fromfile(os.path.join(args.hits, f"{name}.t.f32"), "<f4")[:n]
        t = answers[:n]
        both = np.isfinite(ours) & np.isfinite(t)
        with np.errstate(invalid="ignore"):
            close = np.abs(t - ours) <= 1e-4 * np.abs(ours)
        differ = int((np.isfinite(ours) != np.isfinite(t)).sum() + (both & ~close).sum())
    return (f"  {'embree':<28} {name:<10} {differ:>6} of {n:>6} differ from ours (bvh) "
            "(hit/miss or t beyond 1e-4 relative)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("--rays", required=True, help="directory of primary/incoherent/shadow.bin")
    ap.add_argument("--threads", type=int, default=len(os.sched_getaffinity(0)))
    ap.add_argument("--csv", help="write the rows here (accel-peers' columns)")
    ap.add_argument("--hits", help="accel-peers --dump-hits directory to check against")
    ap.add_argument("--check", type=int, default=10_000, help="rays per set to check")
    ap.add_argument("--runs", type=int, default=3, help="timed runs; the best is reported")
    args = ap.parse_args()

    import embreex  # noqa: F401  (fail early, with pip's name, if the wheel is missing)

    rows, notes, ntris = [], [], 0
    for threads in sorted({1, max(1, args.threads)}):
        # A fresh process per thread count: TBB fixes its pool size when it first starts.
        queue = mp.get_context("fork").Queue()
        p = mp.get_context("fork").Process(target=bench, args=(args, threads, queue))
        p.start()
        ntris, r, n = queue.get()
        p.join()
        rows += r
        notes += n

    print(f"\n{args.mesh} ({ntris} triangles), Embree {embreex_version()} via embreex, "
          "single-ray rtcIntersect1/rtcOccluded1")
    print(f"{'accel':<10} {'rays':<10} {'thr':>3} {'build ms':>9} {'(CPU)':>9} {'Mrays/s':>9} "
          f"{'(CPU)':>9} {'hits':>8}")
    for row in rows:
        f = row.split(",")
        a, rays, thr, build, mrays, hits, cpu_mrays, build_cpu = f[:4] + f[5:7] + f[10:12]
        print(f"{a:<10} {rays:<10} {thr:>3} {float(build):>9.1f} {build_cpu:>9} {float(mrays):>9.3f} "
              f"{cpu_mrays:>9} {hits:>8}")
    print("\n" + "\n".join(notes))
    if args.csv:
        with open(args.csv, "w") as f:
            f.write(COLUMNS + "\n" + "".join(r + "\n" for r in rows))
        print(f"wrote {args.csv}", file=sys.stderr)


def embreex_version():
    try:
        from importlib.metadata import version

        return f"4 (embreex {version('embreex')})"
    except Exception:  # noqa: BLE001
        return "4"


if __name__ == "__main__":
    main()
