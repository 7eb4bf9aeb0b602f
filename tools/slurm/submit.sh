#!/usr/bin/env bash
# Submits a plan to Slurm: a job array with one task per part, and a merge job that runs
# after every task succeeded. Prints the two job ids. Usage:
#   render plan scene.toml --tiles 64x64 --sample-splits 4 -o plan.json -- --spp 1024 -o out.exr
#   tools/slurm/submit.sh plan.json parts/ [extra sbatch options...]
# RENDER names the renderer binary (default: `render` on PATH). Add --wait to block until the
# merge is done.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
plan="$(realpath "$1")"
parts="$(realpath -m "$2")"
shift 2
export RENDER="${RENDER:-$(command -v render)}" PLAN="$plan" PARTS="$parts"
mkdir -p "$parts"
count="$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["parts"]))' "$plan")"
wait=()
extra=()
for a in "$@"; do
    if [ "$a" = "--wait" ]; then wait=(--wait); else extra+=("$a"); fi
done
array="$(sbatch --parsable --export=ALL --array="0-$((count - 1))" "${extra[@]}" "$here/part.sbatch")"
merge="$(sbatch --parsable --export=ALL --dependency="afterok:${array}" --kill-on-invalid-dep=yes \
    "${wait[@]}" "${extra[@]}" "$here/merge.sbatch")"
echo "array $array ($count parts), merge $merge"
