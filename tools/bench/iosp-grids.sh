#!/usr/bin/env bash
# Issue 12's IOSP and grid benchmarks (docs/benchmarks.md, "IOSP and the grids on four
# meshes"): `render bench-accel` on the bunny, Sponza, the conference room and the dragon, for
# bvh8, bvh, iosp0, iosp4, iosp2, grid and irregular-grid, on uniform, primary and incoherent
# (diffuse bounce) rays, one thread timed by its CPU time. Every mesh runs twice, the second
# time with the structures after bvh8 in reverse order, so that ratios to bvh8 come from two
# processes that met the machine's load in different orders. Then prints the tables.
#
#   tools/bench/iosp-grids.sh [OUT_DIR]
#
# Needs ../shared/data (or DATA) and the release binary (`cargo build --release -p rt-cli`).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
out=${1:-$(mktemp -d /tmp/iosp-grids.XXXXXX)}
mkdir -p "$out"
D=${DATA:-../shared/data}
render=${CARGO_TARGET_DIR:-target}/release/render
forward=bvh8,bvh,iosp0,iosp4,iosp2,grid,irregular-grid
reverse=bvh8,irregular-grid,grid,iosp2,iosp4,iosp0,bvh
echo "commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . ':!docs' || echo ' (dirty)')"
for run in 1 2; do
  accels=$forward
  [ "$run" = 2 ] && accels=$reverse
  for mesh in bunny:models/stanford-bunny.obj:outside sponza:scenes/sponza-dabrovic/sponza.obj:inside \
    conference:scenes/conference/conference.obj:inside dragon:models/stanford-dragon.obj:outside; do
    IFS=: read -r name path view <<< "$mesh"
    echo "$name run $run: start $(date -u +%H:%M:%S), load $(cut -d' ' -f1-3 /proc/loadavg)"
    "$render" bench-accel "$D/$path" --view "$view" --accel "$accels" \
      --rays uniform,primary,incoherent --threads 1 --cpu-time --repeat 3 \
      --csv "$out/$name-$run.csv" 2> "$out/$name-$run.err" > "$out/$name-$run.txt"
    echo "$name run $run: end $(date -u +%H:%M:%S), load $(cut -d' ' -f1-3 /proc/loadavg)"
  done
done
python3 tools/bench/iosp_grids_table.py "$out"
