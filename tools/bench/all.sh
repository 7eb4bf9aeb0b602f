#!/usr/bin/env bash
# Reproduces every table of docs/benchmarks.md in one run and prints them in the page's format
# (Markdown), each after the load average at its start. Takes about half an hour on 2 vCPUs.
#
#   tools/bench/all.sh [OUT_DIR]        # e.g. nohup tools/bench/all.sh /tmp/bench-all > all.log 2>&1 &
#
# Needs ../shared/data (the Stanford meshes and the rooms), `pip install embreex` (Embree 4's
# library for the native peer; or EMBREE_LIB) and, for the Mitsuba section, `pip install
# mitsuba` (skipped with a note when absent). Environment as for tools/bench/accel.sh (RUNS,
# REPS, PEERS_TARGET_DIR, CARGO_TARGET_DIR).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
out=${1:-$(mktemp -d /tmp/bench-all.XXXXXX)}
mkdir -p "$out"
D=${DATA:-../shared/data}
target=${CARGO_TARGET_DIR:-target}
render="$target/release/render"
load() { echo; echo "Load average at the start: $(cut -d' ' -f1-3 /proc/loadavg) ($(date -u +%H:%M) UTC)"; echo; }

echo "# docs/benchmarks.md, all tables"
echo
echo "- Date: $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "- Commit: $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . ':!docs' || echo ' (with local changes)')"
echo "- Machine: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1), $(nproc) vCPUs, $(free -g | awk '/^Mem:/{print $2}') GiB, $(rustc --version)"
echo "- Output: $out"
cargo build --release -q -p rt-cli

echo; echo "## Shipped scenes"
load
echo '```sh'; echo 'tools/bench/scenes.sh 64 2'; echo '```'; echo
tools/bench/scenes.sh 64 2

echo; echo "## Side by side with Mitsuba 3"
load
cornell=scenes/cornell-box.toml
line=$("$render" "$cornell" -o "$out/o64.exr" --spp 64 --threads 1 --max-depth 16 --denoiser none)
ours=$(sed -E 's/.*: ([0-9.]+) s render.*/\1/' <<<"$line")
echo "render: $line"
if python3 -c "import mitsuba" 2>/dev/null; then
    echo; echo "| renderer | render time | relative to ours |"; echo "|---|---|---|"
    echo "| ours (\`$(sed -E 's/^[^:]+: [0-9]+x[0-9]+ [0-9]+ spp [a-z]+ ([^ ]+) \(.*/\1/' <<<"$line")\`, 1 thread) | ${ours} s ($(sed -E 's/.* ([0-9.]+ Msamples\/s), ([0-9.]+ Mrays\/s).*/\1, \2/' <<<"$line")) | 1.00 |"
    for variant in scalar_rgb llvm_ad_rgb; do
        if m=$(python3 tools/reference/toml_to_mitsuba.py "$cornell" -o "$out/m64-$variant.exr" --spp 64 \
            --max-depth 16 --threads 1 --variant "$variant" 2>"$out/mitsuba-$variant.log"); then
            secs=$(grep -m1 'render=' <<<"$m" | sed -E 's/.* render=([0-9.]+)s.*/\1/')
            echo "| Mitsuba $(python3 -c 'import mitsuba; print(mitsuba.__version__)') \`$variant\` | ${secs} s | $(python3 -c "print(f'{$secs / $ours:.2f}')") |"
        else
            echo "| Mitsuba \`$variant\` | failed here: $(grep -m1 -E 'Error|ERROR' "$out/mitsuba-$variant.log" | cut -c1-80) | |"
        fi
    done
else
    echo "note: mitsuba is not installed (pip install mitsuba); no Mitsuba rows"
fi

echo; echo "## Scanned meshes (not shipped)"
load
echo '```sh'; echo 'tools/bench/meshes.sh 16 2'; echo '```'; echo; echo '```'
tools/bench/meshes.sh 16 2 2>&1
echo '```'

echo; echo "## Against the Rust peers and Embree 4 (native), one thread"
for mesh in "$D/models/stanford-bunny.obj" "$D/models/stanford-dragon.obj" "$D/scenes/conference/conference.obj"; do
    name=$(basename "$mesh" .obj)
    echo; echo '```sh'; echo "tools/bench/accel.sh ${mesh/#$D/\$D}"; echo '```'
    OUT="$out/peers-$name" tools/bench/accel.sh "$mesh"
done
python3 - "$out" <<'PYEOF'
import csv, glob, statistics, sys
out = sys.argv[1]
print("\n### bvh8 ÷ Embree 4, one thread (median and range of the within-process ratios)\n")
print("| mesh | primary | incoherent (diffuse bounce) | shadow | uniform random | bvh8 ÷ obvhs-cwbvh, uniform |")
print("|---|---|---|---|---|---|")
for name in ["stanford-bunny", "stanford-dragon", "conference"]:
    runs = []
    for p in sorted(glob.glob(f"{out}/peers-{name}/peers-*.csv")):
        with open(p) as f:
            runs.append({(r["accel"], r["rays"]): float(r["mrays_per_s"]) for r in csv.DictReader(f) if r["threads"] == "1"})
    def cell(a, b, s):
        v = sorted(r[(a, s)] / r[(b, s)] for r in runs)
        return f"{statistics.median(v):.2f} ({v[0]:.2f}–{v[-1]:.2f})"
    print(f"| {name} | " + " | ".join(cell("bvh8", "embree", s) for s in ["primary", "incoherent", "shadow", "uniform"])
          + f" | {cell('bvh8', 'obvhs-cwbvh', 'uniform')} |")
PYEOF

echo; echo "## render bench-accel: bvh8 and qbvh against bvh, one thread"
load
cmd='render bench-accel INPUT --accel bvh,qbvh,bvh8 --rays primary,incoherent,shadow,uniform --threads 1 --repeat 5 -q --csv OUT.csv'
echo '```sh'; echo "$cmd"; echo "#   INPUT: \$D/models/stanford-{bunny,dragon}.obj, \$D/scenes/{conference,sibenik,kitchen}/*.obj --view inside, gen:million"; echo '```'; echo
tables=()
for spec in "bunny|$D/models/stanford-bunny.obj|outside" "dragon|$D/models/stanford-dragon.obj|outside" \
    "conference, inside|$D/scenes/conference/conference.obj|inside" \
    "Sibenik, inside|$D/scenes/sibenik/sibenik.obj|inside" \
    "kitchen, inside|$D/scenes/kitchen/kitchen.obj|inside" "gen:million|gen:million|"; do
    IFS='|' read -r label input v <<<"$spec"
    view=()
    [[ -n $v ]] && view=(--view "$v")
    csvf="$out/bench-accel-$(tr -c 'a-zA-Z0-9\n' _ <<<"$label").csv"
    "$render" bench-accel "$input" "${view[@]}" --accel bvh,qbvh,bvh8 --rays primary,incoherent,shadow,uniform \
        --threads 1 --repeat 5 -q --csv "$csvf" >/dev/null
    tables+=("$label=$csvf")
done
python3 tools/bench/bench_accel_table.py "${tables[@]}"
echo; echo "Done at $(date -u '+%Y-%m-%d %H:%M UTC'), load average $(cut -d' ' -f1-3 /proc/loadavg)."
