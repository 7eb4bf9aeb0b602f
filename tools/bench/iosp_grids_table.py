"""Tables of tools/bench/iosp-grids.sh: per mesh and structure, the structure's own bytes,
the build time, Mrays/s on one thread and its share of bvh8's in the same process (the mean
over the runs, each run in brackets), and node and triangle tests per ray.

    python3 tools/bench/iosp_grids_table.py OUT_DIR
"""

import csv
import sys

MESHES = ["bunny", "dragon", "sponza", "conference"]
ACCELS = ["bvh8", "bvh", "iosp0", "iosp4", "iosp2", "grid", "irregular-grid"]
SETS = ["uniform", "primary", "incoherent"]


def main(out):
    for mesh in MESHES:
        runs = []
        for run in (1, 2):
            try:
                with open(f"{out}/{mesh}-{run}.csv") as f:
                    runs.append({(r["accel"], r["rays"]): r for r in csv.DictReader(f)})
            except FileNotFoundError:
                pass
        if not runs:
            continue
        tris = int(next(iter(runs[0].values()))["triangles"])
        print(f"\n{mesh}: {tris:,} triangles, {len(runs)} runs\n")
        print("| structure | own bytes (B/triangle) | build ms | "
              + " | ".join(f"{s}: Mrays/s, share of bvh8" for s in SETS)
              + " | nodes / triangles per ray, uniform | primary |")
        print("|---|---|---|" + "---|" * len(SETS) + "---|---|")
        for accel in ACCELS:
            if (accel, "uniform") not in runs[0]:
                continue
            first = runs[0][(accel, "uniform")]
            own = first["structure_bytes"]
            cells = [f"{int(own):,} ({float(first['structure_bytes_per_tri']):.2f})" if own else "-",
                     " / ".join(f"{float(r[(accel, 'uniform')]['build_ms']):.0f}" for r in runs)]
            for s in SETS:
                mrays = [float(r[(accel, s)]["mrays_per_s"]) for r in runs]
                share = [m / float(r[("bvh8", s)]["mrays_per_s"]) for m, r in zip(mrays, runs)]
                each = " / ".join(f"{100 * x:.0f}" for x in share)
                cells.append(f"{sum(mrays) / len(mrays):.2f}, **{100 * sum(share) / len(share):.0f} %** ({each})")
            for s in ("uniform", "primary"):
                r = runs[0][(accel, s)]
                cells.append(f"{float(r['boxes_per_ray']):.1f} / {float(r['tris_per_ray']):.1f}")
            print(f"| `{accel}` | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1])
