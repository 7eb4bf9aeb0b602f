#!/usr/bin/env python3
"""What a render costs from Python against the CLI, counted in instructions (callgrind), which
a machine shared with other jobs does not disturb the way it disturbs times.

    python tools/bench/python_render_instructions.py [SCENE] [--spp 2 8] [--threads 1]
        [--repeat 1] [--passes-control] [--out DIR]

For each `--spp` value, runs under `valgrind --tool=callgrind`:
- the CLI, `render SCENE -q -o OUT.exr --spp N --threads T` (the whole process);
- with --passes-control, the same in passes of one sample per pixel (`--checkpoint CK
  --checkpoint-every 100000`, which writes no checkpoint);
- Python, `import numpy, rt_renderer as rt; rt.Scene.load(SCENE).render(spp=N, threads=T)`,
  minus `python -c "import numpy, rt_renderer"` (interpreter start and imports, counted once:
  NumPy is imported by any script that uses the arrays, and the module's first array would
  otherwise import it, 0.28 G instructions, inside the render).
Everything else is the scene's and the job's defaults on both sides. The totals are summed over
every thread. Needs valgrind, the module and target/release/render.

Under callgrind a render runs about 50 times slower, so an interruptible render (Python's) takes
passes of one sample per pixel (passes last about `INTERRUPTIBLE_PASS` of wall time); the
counts at two `--spp` values separate what a render from Python costs once (intercept) from what
it costs per pass (slope), and the script prints the overhead predicted for a render of the
scene's own samples in `--native-passes` passes.
"""

import argparse
import concurrent.futures
import os
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def instructions(cmd, out_dir, name):
    """Total instructions (Ir) of `cmd` under callgrind, over all its threads."""
    out = os.path.join(out_dir, f"callgrind.{name}")
    subprocess.run(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(out) as f:
        for line in f:
            m = re.match(r"(?:summary|totals):\s+(\d+)", line)
            if m:
                return int(m.group(1))
    raise RuntimeError(f"{out}: no totals line")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", default="scenes/cornell-box.toml")
    ap.add_argument("--spp", type=int, nargs="+", default=[2, 8])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1, help="runs of each measurement")
    ap.add_argument("--jobs", type=int, default=1,
                    help="measurements run at once (the counts do not depend on it)")
    ap.add_argument("--passes-control", action="store_true")
    ap.add_argument("--render", default=str(ROOT / "target/release/render"))
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--scene-spp", type=int, default=32,
                    help="the samples per pixel the prediction is made for (the scene's)")
    ap.add_argument("--native-passes", type=int, default=8,
                    help="passes an interruptible render of --scene-spp takes natively")
    ap.add_argument("--out", help="keep the callgrind files here")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        out_dir = args.out or tmp
        os.makedirs(out_dir, exist_ok=True)
        runs = {}  # (what, spp, k) -> command
        for k in range(args.repeat):
            runs[("import", 0, k)] = [args.python, "-c", "import numpy, rt_renderer"]
        for spp in args.spp:
            flags = ["--spp", str(spp), "--threads", str(args.threads)]
            for k in range(args.repeat):
                # Each CLI run writes its own file, so that runs at once do not share one.
                exr = os.path.join(tmp, f"cli-{spp}-{k}.exr")
                runs[("cli", spp, k)] = [args.render, args.scene, "-q", "-o", exr, *flags]
                if args.passes_control:
                    ck = os.path.join(tmp, f"ck-{spp}-{k}.rpart")
                    runs[("passes", spp, k)] = [
                        args.render, args.scene, "-q", "-o", exr + ".passes.exr", *flags,
                        "--checkpoint", ck, "--checkpoint-every", "100000"]
                code = (f"import numpy, rt_renderer as rt; "
                        f"rt.Scene.load({args.scene!r}).render(spp={spp}, "
                        f"threads={args.threads})")
                runs[("python", spp, k)] = [args.python, "-c", code]
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            futures = {key: pool.submit(instructions, cmd, out_dir, "-".join(map(str, key)))
                       for key, cmd in runs.items()}
            counts = {key: f.result() for key, f in futures.items()}

    def all_of(what, spp):
        return [counts[(what, spp, k)] for k in range(args.repeat)]

    imports = all_of("import", 0)
    base = min(imports)
    print(f"python -c 'import numpy, rt_renderer': {imports} instructions")
    rows = []
    for spp in args.spp:
        cli = all_of("cli", spp)
        py = [n - base for n in all_of("python", spp)]
        rows.append((spp, min(cli), min(py)))
        print(f"spp {spp}: CLI {cli}, Python render (minus the import) {py}; "
              f"Python / CLI {min(py) / min(cli):.4f}")
        if args.passes_control:
            passes = all_of("passes", spp)
            print(f"  CLI in passes of 1 spp {passes}; / CLI {min(passes) / min(cli):.4f}")
    if len(rows) >= 2:
        (s0, c0, p0), (s1, c1, p1) = rows[0], rows[-1]
        cli_per_spp = (c1 - c0) / (s1 - s0)
        cli_once = c0 - s0 * cli_per_spp
        # Python's extra in N passes (N = spp here) = once + N * per_pass, the CLI taking one.
        per_pass = ((p1 - c1) - (p0 - c0)) / (s1 - s0)
        once = (p0 - c0) - s0 * per_pass
        cli = cli_once + args.scene_spp * cli_per_spp
        extra = once + args.native_passes * per_pass
        print(f"CLI: {cli_once:.4g} instructions once + {cli_per_spp:.4g} per spp")
        print(f"Python's extra: {once:.4g} once + {per_pass:.4g} per pass "
              f"(the waiting thread's polls, which callgrind's slowness multiplies, count "
              f"per pass too)")
        print(f"predicted for {args.scene_spp} spp in {args.native_passes} passes: CLI "
              f"{cli:.4g}, Python's extra {extra:.4g} = {100 * extra / cli:.2f} %")


if __name__ == "__main__":
    main()
