#!/usr/bin/env bash
# Every acceleration structure on the same rays in one run: ours (through `render bench-accel`
# when it exists, and through tools/accel-peers), the Rust peers obvhs and bvh
# (tools/accel-peers), and Embree 4 (tools/bench/embree_bench.py, needs `pip install embreex
# numpy`). Prints the machine and date, each tool's own table, then one combined table.
#
#   tools/bench/accel.sh MESH.obj [THREADS] [VIEW]
#
# THREADS: threads of the multi-threaded rows (default: all CPUs; every tool also runs 1).
# VIEW (only when this script generates the rays): outside or inside; default inside for
# meshes under a `scenes/` directory (rooms), outside otherwise (scanned objects).
# Environment: ACCEL (our specs, default bvh8,qbvh,bvh), PEERS (accel-peers --peers), RUNS (timed
# runs, best reported, default 3), OUT (output directory, default a new /tmp/accel-bench.*),
# PEERS_TARGET_DIR for accel-peers' build (default /tmp/target-peers; render builds in the
# usual CARGO_TARGET_DIR or target/), RUSTFLAGS as usual.
#
# RAYS=auto|render|peers picks the ray generator: `render bench-accel MESH --dump-rays DIR`
# (auto: when it exists and VIEW is outside; its mesh mode looks at the mesh from outside) or
# `accel-peers MESH --gen-rays --view VIEW` (primary camera rays, cosine bounces from their
# hits, shadow rays to a small light; same file format). `render bench-accel` then traces each
# file with --ray-file (shadow.bin with --ray-file-occlusion).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
mesh=${1:?usage: tools/bench/accel.sh MESH.obj [THREADS] [VIEW]}
threads=${2:-$(nproc)}
view=${3:-}
if [[ -z $view ]]; then
    case $(realpath "$mesh") in */scenes/*) view=inside ;; *) view=outside ;; esac
fi
accel=${ACCEL:-bvh8,qbvh,bvh}
runs=${RUNS:-3}
out=${OUT:-$(mktemp -d /tmp/accel-bench.XXXXXX)}
mkdir -p "$out"
root_target=${CARGO_TARGET_DIR:-$root/target}
peers_target=${PEERS_TARGET_DIR:-/tmp/target-peers}

echo "# accel benchmark, $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "# machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) CPUs, $(free -g | awk '/^Mem:/{print $2}') GiB; load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# commit: $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)$(git -C "$root" diff --quiet 2>/dev/null || echo ' (with local changes)'), $(rustc --version)"
echo "# mesh: $mesh, threads: 1 and $threads, output: $out"

# Builds (quietly; their errors are shown).
render="$root_target/release/render"
if ! (cd "$root" && CARGO_TARGET_DIR=$root_target cargo build --release -q -p rt-cli) \
    >"$out/render-build.log" 2>&1; then
    echo "note: building render failed (see $out/render-build.log); no render rows" >&2
    render=""
fi
CARGO_TARGET_DIR=$peers_target cargo build --release -q \
    --manifest-path "$root/tools/accel-peers/Cargo.toml"
peers="$peers_target/release/accel-peers"

bench_accel=false
if [[ -n $render ]] && "$render" bench-accel --help >/dev/null 2>&1; then
    bench_accel=true
fi

# 1. The rays: render's generator for objects seen from outside, accel-peers' for rooms (the
# mesh mode of `render bench-accel` looks at a mesh from outside, which for a room is a box).
help=""
$bench_accel && help=$("$render" bench-accel --help 2>&1)
has() { grep -q -- "$1" <<<"$help"; }
source=${RAYS:-auto}
if [[ $source == auto ]]; then
    if $bench_accel && has --dump-rays && [[ $view == outside ]]; then source=render; else source=peers; fi
fi
rays="$out/rays"
if [[ $source == render ]]; then
    echo "# rays: render bench-accel --dump-rays (its mesh camera and light)"
    dump=(--dump-rays "$rays" --accel bvh)
    has --repeat && dump+=(--repeat 1)
    "$render" bench-accel "$mesh" "${dump[@]}" >"$out/dump-rays.log" 2>&1
else
    echo "# rays: accel-peers --gen-rays --view $view"
    "$peers" "$mesh" --rays "$rays" --gen-rays --view "$view" 2>"$out/gen-rays.log"
fi
for set in primary incoherent shadow; do
    [[ -f $rays/$set.bin ]] && echo "#   $set: $(($(stat -c %s "$rays/$set.bin") / 24)) rays"
done

# 2. render bench-accel on the same rays (--ray-file; shadow.bin needs --ray-file-occlusion).
csvs=()
if $bench_accel; then
    for set in primary incoherent shadow; do
        [[ -f $rays/$set.bin ]] || continue
        args=(--accel "$accel" --ray-file "$rays/$set.bin" --threads "$threads"
            --csv "$out/render-$set.csv")
        if [[ $set == shadow ]]; then
            has --ray-file-occlusion || continue
            args+=(--ray-file-occlusion)
        fi
        has --repeat && args+=(--repeat "$runs")
        echo; echo "## render bench-accel --ray-file $set.bin"
        if "$render" bench-accel "$mesh" "${args[@]}" 2>"$out/render-$set.log"; then
            # Its `rays` column says `file`: name the set.
            awk -F, -v OFS=, -v s="$set" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "rays") c = i }
                NR > 1 && c && $c == "file" { $c = s } { print }' \
                "$out/render-$set.csv" >"$out/render-$set.named.csv"
            csvs+=("render=$out/render-$set.named.csv")
        else
            echo "note: render bench-accel failed on $set.bin (see $out/render-$set.log)" >&2
        fi
    done
else
    echo; echo "note: render bench-accel is not available; our structures are measured by accel-peers only"
fi

# 3. accel-peers: ours through AccelSpec, obvhs, bvh.
echo; echo "## accel-peers"
peer_args=(--rays "$rays" --accel "$accel" --threads "$threads" --runs "$runs"
    --csv "$out/accel-peers.csv" --dump-hits "$out/hits")
[[ -n ${PEERS:-} ]] && peer_args+=(--peers "$PEERS")
"$peers" "$mesh" "${peer_args[@]}" 2>"$out/accel-peers.log"
csvs+=("accel-peers=$out/accel-peers.csv")

# 4. Embree through embreex.
echo; echo "## embree (embreex)"
if python3 -c "import embreex, numpy" 2>/dev/null; then
    python3 "$root/tools/bench/embree_bench.py" "$mesh" --rays "$rays" --threads "$threads" \
        --runs "$runs" --hits "$out/hits" --csv "$out/embree.csv" 2>"$out/embree.log"
    csvs+=("embreex=$out/embree.csv")
else
    echo "note: embreex is not installed (pip install embreex numpy); no Embree rows"
fi

# 5. One table: every structure, grouped by ray set and thread count, fastest first.
echo; echo "## all structures (Mrays/s: wall clock, best of $runs; CPU: per CPU-second of the tracing thread, 1-thread rows)"
python3 - "$out/all.csv" "${csvs[@]}" <<'EOF'
import csv, sys
cols = ["accel", "rays", "threads", "build_ms", "bytes", "mrays_per_s", "hits", "boxes_per_ray",
        "leaves_per_ray", "tris_per_ray", "mrays_per_cpu_s", "build_cpu_ms"]
rows = []
for arg in sys.argv[2:]:
    tool, path = arg.split("=", 1)
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append({"tool": tool, **{c: r.get(c, "") or "" for c in cols}})
with open(sys.argv[1], "w", newline="") as f:
    w = csv.DictWriter(f, ["tool"] + cols)
    w.writeheader()
    w.writerows(rows)
num = lambda s: float(s) if s else float("nan")
order = {"primary": 0, "incoherent": 1, "shadow": 2}
rows.sort(key=lambda r: (order.get(r["rays"], 9), int(r["threads"]), -num(r["mrays_per_s"])))
print(f"{'rays':<10} {'thr':>3} {'tool':<11} {'accel':<24} {'Mrays/s':>8} {'(CPU)':>8} "
      f"{'build ms':>9} {'(CPU)':>8} {'MB':>7} {'hits':>8} {'boxes':>6} {'leaves':>6} {'tris':>6}")
last = None
for r in rows:
    if last and (r["rays"], r["threads"]) != last:
        print()
    last = (r["rays"], r["threads"])
    f = lambda c, d: f"{num(r[c]):.{d}f}" if r[c] else ""
    mb = f"{int(r['bytes']) / 2**20:.1f}" if r["bytes"] else ""
    print(f"{r['rays']:<10} {r['threads']:>3} {r['tool']:<11} {r['accel']:<24} "
          f"{f('mrays_per_s', 3):>8} {f('mrays_per_cpu_s', 3):>8} {f('build_ms', 1):>9} "
          f"{f('build_cpu_ms', 1):>8} {mb:>7} {r['hits']:>8} {f('boxes_per_ray', 1):>6} "
          f"{f('leaves_per_ray', 1):>6} {f('tris_per_ray', 1):>6}")
print(f"\nwrote {sys.argv[1]}")
EOF
