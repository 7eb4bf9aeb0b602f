#!/usr/bin/env bash
# Thread scaling: renders SCENE with 1 thread and with N threads (default: every core), the two
# interleaved ROUNDS times, and prints the median render time of each, the speed-up and the
# load average before every run. A busy second core shows up as load above 1 before the
# one-thread runs; say so next to the number.
#
#   tools/bench/threads.sh [SCENE] [SPP]     (default: scenes/cornell-box.toml, 64 spp)
#
# Environment: THREADS (default nproc), ROUNDS (default 3), RENDER (default
# ${CARGO_TARGET_DIR:-target}/release/render, built if missing).
set -euo pipefail
cd "$(dirname "$0")/../.."
scene=${1:-scenes/cornell-box.toml}
spp=${2:-64}
threads=${THREADS:-$(nproc)}
rounds=${ROUNDS:-3}
bin=${RENDER:-${CARGO_TARGET_DIR:-target}/release/render}
[[ -x $bin ]] || cargo build --release -p rt-cli -q
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# `render`'s summary: "...: 12.34 s render (...)": the render alone, without load and build.
render_seconds() {
    "$bin" "$scene" -o "$out/x.exr" --spp "$spp" --threads "$1" --denoiser none |
        sed -E 's/.*: ([0-9.]+) s render.*/\1/'
}
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; commit $(git rev-parse --short HEAD); $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "scene: $scene, $spp spp"
one=() many=()
for r in $(seq "$rounds"); do
    echo "round $r: load $(cut -d' ' -f1-3 /proc/loadavg) before 1 thread"
    one+=("$(render_seconds 1)")
    echo "round $r: load $(cut -d' ' -f1-3 /proc/loadavg) before $threads threads"
    many+=("$(render_seconds "$threads")")
done
t1=$(printf '%s\n' "${one[@]}" | median)
tn=$(printf '%s\n' "${many[@]}" | median)
echo "| threads | render s (median of $rounds) | speed-up |"
echo "|---|---|---|"
echo "| 1 | $t1 | 1.00 |"
echo "| $threads | $tn | $(awk -v a="$t1" -v b="$tn" 'BEGIN {printf "%.2f", a / b}') |"
