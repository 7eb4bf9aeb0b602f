#!/usr/bin/env python3
"""What a render costs from Python against the CLI, on the default scene.

    python tools/bench/python_render.py [SCENE] [--rounds 5] [--spp N] [--denoiser D] [--threads T]
        [--passes-control]

Each round runs `render SCENE -q -o OUT.exr FLAGS` (wall time of the whole process: load,
build, render, denoise, write) and, in this process, `rt_renderer.Scene.load(SCENE)` followed
by `scene.render(**flags)` (wall time of both calls: the same work, with the image handed over
as arrays instead of written; in passes, as renders from Python are interruptible),
alternating which goes first. Prints every round, the median of each and their ratio; a
CPU-time ratio too (the child's user+system time against this process's), which a
machine shared with other jobs disturbs less. --spp, --denoiser and --threads go to both;
--passes-control adds a CLI run in passes of one sample per pixel (`--checkpoint` with no
checkpoint written), to see what passes cost. Needs the module and target/release/render.
Instruction counts, which the machine's load does not disturb: python_render_instructions.py.
"""

import argparse
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def self_cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", default="scenes/cornell-box.toml")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--render", default=str(ROOT / "target/release/render"))
    ap.add_argument("--spp", type=int)
    ap.add_argument("--denoiser")
    ap.add_argument("--threads", type=int)
    ap.add_argument("--passes-control", action="store_true")
    args = ap.parse_args()
    flags, kwargs = [], {}
    for name in ("spp", "denoiser", "threads"):
        value = getattr(args, name)
        if value is not None:
            flags += [f"--{name}", str(value)]
            kwargs[name] = value

    import rt_renderer as rt

    rt.Scene.load(args.scene).render(spp=1)  # warm the module and the page cache
    cli_wall, cli_cpu, py_wall, py_cpu, ck_wall, ck_cpu = [], [], [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cli.exr")

        def run_cli(extra, wall, cpu):
            c, t = child_cpu(), time.perf_counter()
            subprocess.run([args.render, args.scene, "-q", "-o", out, *flags, *extra], check=True)
            wall.append(time.perf_counter() - t)
            cpu.append(child_cpu() - c)

        def cli():
            run_cli([], cli_wall, cli_cpu)

        def passes():
            ck = os.path.join(tmp, "ck.rpart")
            run_cli(["--checkpoint", ck, "--checkpoint-every", "100000"], ck_wall, ck_cpu)

        def py():
            c, t = self_cpu(), time.perf_counter()
            rt.Scene.load(args.scene).render(**kwargs)
            py_wall.append(time.perf_counter() - t)
            py_cpu.append(self_cpu() - c)

        order = [cli, py] + ([passes] if args.passes_control else [])
        for r in range(args.rounds):
            for f in order if r % 2 == 0 else order[::-1]:
                f()
            print(f"round {r + 1}: CLI {cli_wall[-1]:.2f} s ({cli_cpu[-1]:.2f} s CPU), "
                  f"Python {py_wall[-1]:.2f} s ({py_cpu[-1]:.2f} s CPU), "
                  f"load {os.getloadavg()[0]:.1f}", file=sys.stderr)
    m = statistics.median
    print(f"{args.scene}, {args.rounds} rounds, median: CLI {m(cli_wall):.3f} s wall "
          f"{m(cli_cpu):.3f} s CPU; Python {m(py_wall):.3f} s wall {m(py_cpu):.3f} s CPU")
    print(f"Python / CLI: wall {m(py_wall) / m(cli_wall):.3f}x, CPU {m(py_cpu) / m(cli_cpu):.3f}x")
    if ck_cpu:
        print(f"CLI in passes of 1 spp / CLI: wall {m(ck_wall) / m(cli_wall):.3f}x, "
              f"CPU {m(ck_cpu) / m(cli_cpu):.3f}x")


if __name__ == "__main__":
    main()
