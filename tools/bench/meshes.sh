#!/usr/bin/env bash
# Load, BVH build and render throughput on real scanned meshes (Stanford bunny, 69k triangles;
# Stanford dragon, 871k) from ../shared/data, which is not part of the repository: skips with a
# message when it is absent. Usage: tools/bench/meshes.sh [SPP] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/../.."
if [ ! -d ../shared/data/models ]; then
  echo "../shared/data/models not found: skipping the mesh benchmarks" >&2
  exit 0
fi
spp=${1:-16}
threads=${2:-$(nproc)}
cargo build --release -p rt-cli -q
bin=${CARGO_TARGET_DIR:-target}/release/render
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for scene in tools/bench/bunny.toml tools/bench/dragon.toml; do
  for integrator in ao path; do
    "$bin" "$scene" -o "$out/x.exr" --spp "$spp" --threads "$threads" --integrator "$integrator" 2>/dev/null
  done
done
