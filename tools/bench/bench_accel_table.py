#!/usr/bin/env python3
"""One Markdown table from `render bench-accel --csv` files (tools/bench/all.sh).

    bench_accel_table.py LABEL=A.csv LABEL=B.csv ...

Per input and structure: build ms, B/tri and Mrays/s per ray set with the speedup over the
first structure listed (the `speedup` of render's table), one thread.
"""
import csv
import sys

SETS = ["primary", "incoherent", "shadow", "uniform"]
first = True
for arg in sys.argv[1:]:
    label, path = arg.split("=", 1)
    with open(path) as f:
        rows = [r for r in csv.DictReader(f) if r["threads"] == "1"]
    sets = [s for s in SETS if any(r["rays"] == s for r in rows)]
    if first:
        print("| input (triangles) | structure | build ms | B/tri | " + " | ".join(sets) + " |")
        print("|---|---|---|---|" + "---|" * len(sets))
        first = False
    accels = []
    for r in rows:
        if r["accel"] not in accels:
            accels.append(r["accel"])
    get = {(r["accel"], r["rays"]): r for r in rows}
    base = accels[0]
    for i, a in enumerate(accels):
        r0 = get[(a, sets[0])]
        cells = []
        for s in sets:
            m = float(get[(a, s)]["mrays_per_s"])
            b = float(get[(base, s)]["mrays_per_s"])
            cells.append(f"{m:.2f}" + ("" if a == base else f" ({m / b:.2f}×)"))
        name = f"{label} ({int(r0['triangles']):,})" if i == 0 else ""
        print(f"| {name} | `{a}` | {float(r0['build_ms']):.0f} | {float(r0['bytes_per_tri']):.1f} | "
              + " | ".join(cells) + " |")
