#!/usr/bin/env bash
# Renders every shipped scene with fixed settings and prints a Markdown table of throughput (the
# `render` summary line, parsed), with render's default structure (the `accel` column).
# Usage: tools/bench/scenes.sh [SPP] [THREADS]
# Numbers from a shared machine are noisy: compare rows of one run, not across runs.
set -euo pipefail
cd "$(dirname "$0")/../.."
spp=${1:-64}
threads=${2:-$(nproc)}
cargo build --release -p rt-cli -q
bin=${CARGO_TARGET_DIR:-target}/release/render
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| scene | resolution | triangles | spp | integrator | accel | render s | Msamples/s | Mrays/s |"
echo "|---|---|---|---|---|---|---|---|---|"
for scene in scenes/*.toml; do
  for integrator in path ao; do
    line=$("$bin" "$scene" -o "$out/x.exr" --spp "$spp" --threads "$threads" --integrator "$integrator")
    # scenes/x.toml: 512x512 64 spp path bvh (32 tris, 2 threads): 14.22 s render (...), 1.18 Msamples/s, 6.27 Mrays/s -> ...
    res=$(sed -E 's/^[^:]+: ([0-9]+x[0-9]+) .*/\1/' <<<"$line")
    tris=$(sed -E 's/.*\(([0-9]+) tris.*/\1/' <<<"$line")
    accel=$(sed -E 's/^[^:]+: [0-9]+x[0-9]+ [0-9]+ spp [a-z]+ ([^ ]+) \(.*/\1/' <<<"$line")
    secs=$(sed -E 's/.*: ([0-9.]+) s render.*/\1/' <<<"$line")
    msps=$(sed -E 's/.* ([0-9.]+) Msamples\/s.*/\1/' <<<"$line")
    mrps=$(sed -E 's/.* ([0-9.]+) Mrays\/s.*/\1/' <<<"$line")
    echo "| $(basename "$scene" .toml) | $res | $tris | $spp | $integrator | $accel | $secs | $msps | $mrps |"
  done
done
