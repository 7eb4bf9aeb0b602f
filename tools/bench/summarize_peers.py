#!/usr/bin/env python3
"""Summarises accel-peers CSVs of repeated processes (tools/bench/accel.sh).

    summarize_peers.py LABEL THREADS A.csv B.csv ...

Per structure and ray set: the median over the processes of the median-round Mrays/s, and the
median (min-max) over the processes of the within-process ratio to Embree (`embree`); build ms
and MiB are medians over the processes. Prints Markdown.
"""
import csv
import statistics
import sys

label, threads, paths = sys.argv[1], sys.argv[2], sys.argv[3:]
SETS = ["primary", "incoherent", "shadow", "uniform"]
runs = []
for p in paths:
    with open(p) as f:
        runs.append([r for r in csv.DictReader(f) if r["threads"] == threads])
order = []
for r in runs[0]:
    if r["accel"] not in order:
        order.append(r["accel"])
sets = [s for s in SETS if any(r["rays"] == s for r in runs[0])]


def val(run, accel, s, col="mrays_per_s"):
    for r in run:
        if r["accel"] == accel and r["rays"] == s:
            return float(r[col]) if r[col] else None
    return None


ref = "embree" if "embree" in order else order[0]
print(f"\n{label}: Mrays/s, {threads} thread(s); median of {len(runs)} processes "
      f"(each the median of its interleaved rounds); (× {ref}: median and range of the "
      "within-process ratios)\n")
print("| structure | build ms | MiB | " + " | ".join(sets) + " |")
print("|---|---|---|" + "---|" * len(sets))
for a in order:
    build = statistics.median(val(r, a, sets[0], "build_ms") for r in runs)
    b = val(runs[0], a, sets[0], "bytes")
    cells = []
    for s in sets:
        m = statistics.median(val(r, a, s) for r in runs)
        ratios = sorted(val(r, a, s) / val(r, ref, s) for r in runs)
        rng = f", {ratios[0]:.2f}–{ratios[-1]:.2f}" if len(ratios) > 1 else ""
        cells.append(f"{m:.2f} ({statistics.median(ratios):.2f}×{rng})")
    mib = f"{b / 2**20:.1f}" if b else "–"
    print(f"| {a} | {build:.0f} | {mib} | " + " | ".join(cells) + " |")
