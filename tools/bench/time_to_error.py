#!/usr/bin/env python3
"""Time to error of our path tracer against Mitsuba 3 `llvm_ad_rgb` on the same scenes.

Run through tools/bench/time-to-error.sh (which documents what to install and the
environment variables); this is the helper it calls. Scenes come from
tools/reference/mitsuba_to_toml.py (`cbox` = mi.cornell_box() with a box filter and
unlimited depth, `dragon` = the same box with the Stanford dragon instead of the cubes).

For each scene:
 1. A Mitsuba `llvm_ad_rgb` reference at REF_SPP (16384) spp, rendered in passes of at most
    2^23 pixel-samples (memory bound) with seed REF_SEED, cached on disk under
    CACHE (default ${XDG_CACHE_HOME:-~/.cache}/rt-time-to-error/), keyed by scene, the SHA-256
    of our TOML text and of the mesh file, Mitsuba/Dr.Jit versions, variant, spp and seed.
    Its per-pixel variance (from the spread of the passes) is kept too.
 2. Mitsuba `llvm_ad_rgb` at MI_SPP (1024) spp, THREADS threads, seed MI_SEED (not the
    reference's), twice, each in a fresh process:
    * cold: an empty Dr.Jit kernel cache (DRJIT_CACHE_DIR = a new directory), so the time
      includes JIT compilation;
    * warm: the scene is loaded, a 4-spp warm-up render compiles the kernels, then the timed
      1024-spp render of the same scene (the kernels are size-independent: passes of other
      sizes reuse them). The warm time is the one the ratios use.
 3. Ours (`render SCENE.toml --spp N --threads THREADS --max-depth 10000 --integrator
    INTEGRATOR -o out.exr`) at each spp of the ladder SPP; INTEGRATOR is `wavefront` (the
    default) unless set (`path`: the scalar reference, the same image).

Timing, the same "honest" definition for both renderers, from scene description to image file:
  ours     wall time of the whole `render` command: process start, scene load (OBJ parse),
           BVH build, render, EXR write. (`render` also prints its render-only time; shown.)
  Mitsuba  mi.load_dict (OBJ parse, Embree build) + mi.render of all passes + reading the
           image back + EXR write, measured inside the process. Python start-up and
           `import mitsuba` (~1 s, a fixed cost of using Mitsuba from Python) are not counted;
           JIT compilation is excluded in the warm run and included in the cold one.
  CPU seconds (user + system) of the same interval are shown for both, to show how many cores
  each actually kept busy.

Error: relMSE of each image against the Mitsuba reference, by ONE definition for both renderers:
`render compare IMAGE REF --json` (mean over pixels and channels of (a-b)^2/(b^2+0.01),
docs/experiments.md). The reference's own noise adds about mean(var_ref/(ref^2+0.01)) to every
relMSE (for REF_SPP = 16 x MI_SPP about 1/16 of Mitsuba's 1024-spp relMSE): the same additive
bias for both renderers. It is printed ("reference floor") and the time-to-error ratio is also
given with the floor subtracted from both sides.

Time to error: the time ours needs to reach Mitsuba's 1024-spp relMSE, by log-log linear
interpolation of ours' (wall time, relMSE) ladder between the two bracketing rungs; outside
the ladder, by the fit relMSE = c / t (slope -1 in log-log, c from the least-squares fit over
the ladder), marked "(fit)". Ratio = that time / Mitsuba's warm time (target <= 0.5).
Throughput ratio = our samples/s / Mitsuba's samples/s, both at MI_SPP spp from the honest
times (target >= 1.0).
"""

from __future__ import annotations

import datetime
import hashlib
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "tools", "reference"))

EPS = 0.01  # render compare's default relMSE epsilon


def env(name: str, default: str) -> str:
    v = os.environ.get(name)
    return default if v is None or v == "" else v


def log(msg: str) -> None:
    print(f"[time-to-error {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def loadavg() -> str:
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


# ----------------------------------------------------------------------------
# Mitsuba worker (runs in its own process)
# ----------------------------------------------------------------------------

def worker(argv: list[str]) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="time_to_error.py mitsuba")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--threads", type=int, required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--var-out", default=None)
    ap.add_argument("--warmup", type=int, default=0, help="spp of a warm-up render first")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--dragon", default=None)
    a = ap.parse_args(argv)
    import mitsuba_to_toml as m2t
    import mitsuba as mi
    import drjit as dr
    import numpy as np
    mi.set_variant(a.variant)
    default_threads = dr.thread_count()
    dr.set_thread_count(a.threads)
    if a.scene.endswith(".xml"):
        load = lambda: mi.load_file(a.scene)  # noqa: E731
    else:
        d = m2t.mitsuba_dict(a.scene, a.dragon or m2t.DEFAULT_DRAGON)
        load = lambda: mi.load_dict(d)  # noqa: E731
    res = {"variant": a.variant, "threads": a.threads, "spp": a.spp, "seed": a.seed}
    cpu_load = 0.0
    if a.warmup:
        c0, t0 = cpu_self(), time.perf_counter()
        s = load()
        res["load_s"] = time.perf_counter() - t0
        cpu_load = cpu_self() - c0
        t1 = time.perf_counter()
        np.array(mi.render(s, spp=a.warmup, seed=a.seed + 999_983))
        res["warmup_s"] = time.perf_counter() - t1
        res["warmup_spp"] = a.warmup
        c0, t0 = cpu_self(), time.perf_counter()
        t1 = t0
    else:
        c0, t0 = cpu_self(), time.perf_counter()
        s = load()
        t1 = time.perf_counter()
        res["load_s"] = t1 - t0
    mean, var, n, per = m2t.render_passes(
        s, a.spp, a.seed, passes=16 if a.var_out else None, want_var=bool(a.var_out),
        log=(lambda msg: log(f"mitsuba {a.scene} {a.spp} spp: {msg}")) if a.spp > 4096 else None)
    t2 = time.perf_counter()
    if a.threads < 2:  # Mitsuba 3.9's EXR writer deadlocks with a 1-thread pool
        dr.set_thread_count(max(2, default_threads))
    m2t.write_exr(a.out, mean)
    t3 = time.perf_counter()
    res["cpu_s"] = cpu_self() - c0 + cpu_load
    if a.var_out:
        m2t.write_exr(a.var_out, var)
    res.update({"passes": n, "spp_per_pass": per, "render_s": t2 - t1, "write_s": t3 - t2,
                "total_s": (t3 - t0) + (res["load_s"] if a.warmup else 0.0),
                "mitsuba": mi.__version__, "drjit": dr.__version__})
    print("RESULT " + json.dumps(res), flush=True)
    return 0


def run_worker(args: list[str], extra_env: dict | None = None) -> dict:
    e = dict(os.environ)
    e.update(extra_env or {})
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, os.path.abspath(__file__), "mitsuba"] + args,
                       env=e, stdout=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit(f"Mitsuba worker failed ({p.returncode}): {' '.join(args)}")
    line = [ln for ln in p.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    r = json.loads(line[7:])
    r["process_wall_s"] = wall
    return r


# ----------------------------------------------------------------------------
# helpers of the driver
# ----------------------------------------------------------------------------

def compare(render: str, img: str, ref: str) -> dict:
    p = subprocess.run([render, "compare", img, ref, "--json"], check=True,
                       stdout=subprocess.PIPE, text=True)
    return json.loads(p.stdout)


def sha256_file(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def reference_floor(ref: str, var: str) -> float:
    """Expected relMSE contribution of the reference's own noise, same epsilon."""
    import mitsuba_to_toml as m2t
    b = m2t.read_exr(ref)
    v = m2t.read_exr(var)
    return float((v / (b * b + EPS)).mean())


SUMMARY = re.compile(r"([0-9.]+) s render \(([0-9.]+) s load, ([0-9.]+) s (\S+) build\)")


def run_ours(render: str, toml: str, spp: int, threads: int, out: str) -> dict:
    la = loadavg()
    # A Mitsuba scene file keeps its own depth (its integrator's max_depth).
    depth = [] if toml.endswith(".xml") else ["--max-depth", "10000"]
    c0, t0 = cpu_children(), time.perf_counter()
    p = subprocess.run([render, toml, "--spp", str(spp), "--threads", str(threads)] + depth +
                       ["--integrator", env("INTEGRATOR", "wavefront"), "-o", out],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    cpu = cpu_children() - c0
    if p.returncode != 0:
        raise SystemExit(f"render failed: {p.stderr.strip().splitlines()[-1:]}")
    m = SUMMARY.search(p.stdout)
    r = {"spp": spp, "wall_s": wall, "cpu_s": cpu, "loadavg": la, "summary": p.stdout.strip()}
    if m:
        r.update({"render_s": float(m.group(1)), "load_s": float(m.group(2)),
                  "build_s": float(m.group(3)), "accel": m.group(4)})
    return r


def scene_dir(scene: str) -> str:
    """Folder (and cache) name of a scene: a built-in name, or `folder-stem` of an XML file."""
    if not scene.endswith(".xml"):
        return scene
    p = os.path.abspath(scene)
    return f"{os.path.basename(os.path.dirname(p))}-{os.path.splitext(os.path.basename(p))[0]}"


def mi_scene(scene: str, ours: str) -> str:
    """What the Mitsuba worker loads: a built-in name, or the patched copy of an XML file."""
    return ours if scene.endswith(".xml") else scene


def time_to_error(ladder: list[tuple[float, float]], target: float):
    """(time, how) at which relMSE(t) reaches target, from (t, relMSE) points."""
    pts = sorted(ladder)
    lt = [math.log(t) for t, _ in pts]
    le = [math.log(e) for _, e in pts]
    lg = math.log(target)
    for i in range(len(pts) - 1):
        e0, e1 = le[i], le[i + 1]
        if (e0 - lg) * (e1 - lg) <= 0 and e0 != e1:
            f = (lg - e0) / (e1 - e0)
            return math.exp(lt[i] + f * (lt[i + 1] - lt[i])), "interpolated"
    logc = sum(a + b for a, b in zip(lt, le)) / len(pts)  # relMSE = c / t
    return math.exp(logc - lg), "fit c/t"


def loglog_slope(ladder: list[tuple[float, float]]) -> float:
    x = [math.log(t) for t, _ in ladder]
    y = [math.log(e) for _, e in ladder]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sxx = sum((a - mx) ** 2 for a in x)
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / sxx if sxx > 0 else float("nan")


# ----------------------------------------------------------------------------
# driver
# ----------------------------------------------------------------------------

def main() -> int:
    scenes = env("SCENES", "cbox dragon").split()
    ladder = [int(x) for x in env("SPP", "64 128 256 512 1024").replace(",", " ").split()]
    threads = int(env("THREADS", "2"))
    render = os.path.abspath(env("RENDER", os.path.join(REPO, "target", "release", "render")))
    out = os.path.abspath(env("OUT", "/tmp/rt-time-to-error"))
    ref_spp = int(env("REF_SPP", "16384"))
    mi_spp = int(env("MI_SPP", "1024"))
    ref_seed = int(env("REF_SEED", "7"))
    mi_seed = int(env("MI_SEED", "1"))
    ref_threads = int(env("REF_THREADS", str(os.cpu_count() or 1)))
    variant = env("VARIANT", "llvm_ad_rgb")
    dragon = os.path.abspath(env("DRAGON", os.path.join(REPO, "..", "shared", "data", "models",
                                                         "stanford-dragon.obj")))
    cache = os.path.abspath(env("CACHE", os.path.join(
        env("XDG_CACHE_HOME", os.path.join(os.path.expanduser("~"), ".cache")),
        "rt-time-to-error")))
    if not os.access(render, os.X_OK):
        raise SystemExit(f"no render binary at {render} (cargo build --release -p rt-cli, "
                         "or set RENDER)")
    os.makedirs(out, exist_ok=True)
    os.makedirs(cache, exist_ok=True)

    import mitsuba_to_toml as m2t
    import mitsuba as mi
    import drjit as dr
    m2t.ensure_variant(variant)
    versions = f"mitsuba{mi.__version__}-drjit{dr.__version__}"

    def sh(*cmd):
        try:
            return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                  text=True, cwd=REPO).stdout.strip()
        except OSError:
            return "?"
    model = next((ln.split(":", 1)[1].strip() for ln in sh("lscpu").splitlines()
                  if ln.startswith("Model name")), "?")
    # COMMIT: the commit RENDER was built from, when that is not the checkout's HEAD.
    commit = env("COMMIT", "") or sh("git", "rev-parse", "--short", "HEAD")
    render_version = sh(render, "--version")
    meta = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": f"{model}, nproc {os.cpu_count()}",
        "commit": commit, "render": render, "render_version": render_version,
        "mitsuba": f"Mitsuba {mi.__version__}, Dr.Jit {dr.__version__}, {variant}",
        "threads": threads, "ladder": ladder, "ref_spp": ref_spp, "mi_spp": mi_spp,
        "uptime_start": sh("uptime"),
    }
    results = {"meta": meta, "scenes": {}}
    # Phase 1: every reference (untimed, cached), so that the timed runs of phase 2 follow
    # each other closely.
    refs = {}
    import mitsuba_copy
    for scene in scenes:
        sd = os.path.join(out, scene_dir(scene))
        os.makedirs(sd, exist_ok=True)
        if scene.endswith(".xml"):
            # Both renderers read one copy of the file, at 256x256 (mitsuba_copy.py).
            toml = str(mitsuba_copy.write_copy(scene, 256, os.path.join(sd, "scene.xml")))
            key_src = sha256_file(toml)
        else:
            toml = os.path.join(sd, f"{scene}.toml")
            text_sha = m2t.write_toml(scene, toml, dragon)
            key_src = text_sha + (sha256_file(dragon) if scene == "dragon" else "")
        key = hashlib.sha256(key_src.encode()).hexdigest()[:12]
        stem = f"{scene_dir(scene)}-{versions}-{variant}-{ref_spp}spp-seed{ref_seed}-{key}"
        ref = os.path.join(cache, stem + ".exr")
        ref_var = os.path.join(cache, stem + "-var.exr")
        ref_json = os.path.join(cache, stem + ".json")
        if os.path.exists(ref) and os.path.exists(ref_var) and os.path.exists(ref_json):
            with open(ref_json) as f:
                ref_info = json.load(f)
            ref_info["cached"] = True
            log(f"{scene}: reference from the cache: {ref}")
        else:
            log(f"{scene}: rendering the Mitsuba reference, {ref_spp} spp, {ref_threads} "
                f"threads (load {loadavg()}) -> {ref}")
            tmp = ref + f".{os.getpid()}.tmp.exr"
            tmpv = ref_var + f".{os.getpid()}.tmp.exr"
            ref_info = run_worker(["--scene", mi_scene(scene, toml), "--spp", str(ref_spp), "--seed",
                                   str(ref_seed), "--threads", str(ref_threads), "--out", tmp,
                                   "--var-out", tmpv, "--variant", variant, "--dragon", dragon])
            ref_info["loadavg_before"] = loadavg()
            os.replace(tmp, ref)
            os.replace(tmpv, ref_var)
            with open(ref_json, "w") as f:
                json.dump(ref_info, f, indent=1)
            ref_info["cached"] = False
        refs[scene] = (toml, ref, ref_var, ref_info)

    if env("REF_ONLY", "") == "1":
        log("REF_ONLY=1: the references are in the cache; no timed renders")
        return 0

    # Phase 2: the timed renders.
    meta["date"] = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    meta["uptime_start"] = sh("uptime")
    for scene in scenes:
        sd = os.path.join(out, scene_dir(scene))
        toml, ref, ref_var, ref_info = refs[scene]
        floor = reference_floor(ref, ref_var)

        # Mitsuba, cold (empty kernel cache) and warm.
        mi_runs = {}
        for mode in ("cold", "warm"):
            img = os.path.join(sd, f"mitsuba-{mi_spp}-{mode}.exr")
            la = loadavg()
            log(f"{scene}: Mitsuba {mode}, {mi_spp} spp, {threads} threads (load {la})")
            args = ["--scene", mi_scene(scene, toml), "--spp", str(mi_spp), "--seed", str(mi_seed),
                    "--threads", str(threads), "--out", img, "--variant", variant,
                    "--dragon", dragon]
            if mode == "cold":
                jit_dir = tempfile.mkdtemp(prefix="tte-drjit-cache-")
                try:
                    r = run_worker(args, {"DRJIT_CACHE_DIR": jit_dir})
                finally:
                    shutil.rmtree(jit_dir, ignore_errors=True)
            else:
                r = run_worker(args + ["--warmup", "4"])
            r["loadavg"] = la
            r["relmse"] = compare(render, img, ref)["relmse"]
            mi_runs[mode] = r
            log(f"{scene}: Mitsuba {mode}: {r['total_s']:.2f} s, relMSE {r['relmse']:.5g}")

        # Ours, the ladder.
        ours = []
        for spp in ladder:
            img = os.path.join(sd, f"ours-{spp}.exr")
            log(f"{scene}: ours {spp} spp (load {loadavg()})")
            r = run_ours(render, toml, spp, threads, img)
            r["relmse"] = compare(render, img, ref)["relmse"]
            ours.append(r)
            log(f"{scene}: ours {spp} spp: {r['wall_s']:.2f} s, relMSE {r['relmse']:.5g}")

        warm = mi_runs["warm"]
        target = warm["relmse"]
        pts = [(r["wall_s"], r["relmse"]) for r in ours]
        t_star, how = time_to_error(pts, target)
        pts_c = [(t, e - floor) for t, e in pts if e - floor > 0]
        t_star_c, how_c = (time_to_error(pts_c, target - floor) if pts_c and target > floor
                           else (float("nan"), "n/a"))
        # The same with CPU seconds instead of wall seconds: on a loaded machine the two
        # renderers get different shares of the cores, CPU time is robust to that.
        t_cpu, how_cpu = time_to_error([(r["cpu_s"], r["relmse"]) for r in ours], target)
        at = next((r for r in ours if r["spp"] == mi_spp), max(ours, key=lambda r: r["spp"]))
        w, h = 256, 256
        ours_sps = w * h * at["spp"] / at["wall_s"]
        mi_sps = w * h * mi_spp / warm["total_s"]
        results["scenes"][scene] = {
            "toml": toml, "reference": ref, "reference_info": ref_info, "floor": floor,
            "mitsuba": mi_runs, "ours": ours,
            "time_to_error_s": t_star, "tte_how": how, "tte_ratio": t_star / warm["total_s"],
            "tte_ratio_floor_corrected": t_star_c / warm["total_s"], "tte_how_corrected": how_c,
            "slope": loglog_slope(pts),
            "throughput_ratio": ours_sps / mi_sps, "throughput_spp": at["spp"],
            "ours_msamples_s": ours_sps / 1e6, "mitsuba_msamples_s": mi_sps / 1e6,
            "time_to_error_cpu_s": t_cpu, "tte_cpu_how": how_cpu,
            "tte_ratio_cpu": t_cpu / warm["cpu_s"],
            "throughput_ratio_cpu": (at["spp"] / at["cpu_s"]) / (mi_spp / warm["cpu_s"]),
        }
        with open(os.path.join(out, "results.json"), "w") as f:
            json.dump(results, f, indent=1)
    meta["uptime_end"] = sh("uptime")
    meta["date_end"] = datetime.datetime.now(datetime.timezone.utc).strftime("%H:%M UTC")
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    md = markdown(results)
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(md)
    print(md)
    return 0


def markdown(res: dict) -> str:
    m = res["meta"]
    L = [f"- Commit `{m['commit']}` ({m['render_version']}, `{m['render']}`); "
         f"{m['mitsuba']}; {m['threads']} threads each.",
         f"- Machine: {m['machine']}. Date: {m['date']} to {m.get('date_end', '?')} (timed part).",
         f"- Load: `{m['uptime_start']}` at the start of the timed part, "
         f"`{m.get('uptime_end', '?')}` at its end; "
         "per render in the table (1-, 5-, 15-minute load averages just before it).",
         f"- 256x256, box filter, unlimited depth (Mitsuba `max_depth = -1`, ours "
         f"`--max-depth 10000`; a Mitsuba .xml scene keeps its own filter and depth); reference: Mitsuba {m['ref_spp']} spp. Times: ours = whole "
         "`render` command (load, BVH build, render, EXR write; render-only in brackets); "
         "Mitsuba = `load_dict` + render + EXR write in-process, without Python start-up and "
         "import; warm = JIT excluded (4-spp warm-up first), cold = empty kernel cache. "
         "CPU s = user + system time of the same interval.",
         "",
         "| scene | renderer | spp | load avg before | time s | CPU s | relMSE |",
         "|---|---|---|---|---|---|---|"]
    for name, s in res["scenes"].items():
        for mode in ("cold", "warm"):
            r = s["mitsuba"][mode]
            L.append(f"| {name} | Mitsuba {mode} | {r['spp']} | {r['loadavg']} | "
                     f"{r['total_s']:.2f} (load {r['load_s']:.2f}, render {r['render_s']:.2f}) | "
                     f"{r['cpu_s']:.1f} | {r['relmse']:.3e} |")
        for r in s["ours"]:
            L.append(f"| {name} | ours | {r['spp']} | {r['loadavg']} | {r['wall_s']:.2f} "
                     f"({r.get('render_s', float('nan')):.2f}) | {r['cpu_s']:.1f} | "
                     f"{r['relmse']:.3e} |")
    L += ["",
          f"| scene | Mitsuba relMSE ({m['mi_spp']} spp, warm s) | reference floor | "
          "ours' time to it | time-to-error ratio (≤ 0.5) | same, floor subtracted | "
          "Msamples/s ours / Mitsuba | throughput ratio (≥ 1.0) | by CPU s: time-to-error "
          "ratio, throughput ratio |",
          "|---|---|---|---|---|---|---|---|---|"]
    for name, s in res["scenes"].items():
        w = s["mitsuba"]["warm"]
        cpu = (f"{s['tte_ratio_cpu']:.2f}, {s['throughput_ratio_cpu']:.2f}"
               if "tte_ratio_cpu" in s else "–")
        L.append(f"| {name} | {w['relmse']:.3e} ({w['total_s']:.2f} s) | {s['floor']:.2e} | "
                 f"{s['time_to_error_s']:.2f} s ({s['tte_how']}) | {s['tte_ratio']:.2f} | "
                 f"{s['tte_ratio_floor_corrected']:.2f} | "
                 f"{s['ours_msamples_s']:.3f} / {s['mitsuba_msamples_s']:.3f} | "
                 f"{s['throughput_ratio']:.2f} | {cpu} |")
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "mitsuba":
        sys.exit(worker(sys.argv[2:]))
    if len(sys.argv) > 1 and sys.argv[1] == "table":  # re-print from results.json
        with open(sys.argv[2]) as f:
            print(markdown(json.load(f)))
        sys.exit(0)
    sys.exit(main())
