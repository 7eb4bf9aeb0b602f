#!/usr/bin/env bash
# Every acceleration structure on the same rays, on one thread: ours (bvh8, qbvh, bvh, through
# `AccelSpec`), obvhs' BVH2 and CWBVH, the bvh crate and Embree 4 (its C API, loaded from the
# libembree4 that the `embreex` wheel carries), all in tools/accel-peers, on the four ray sets
# that `render bench-accel --dump-rays` writes (primary, incoherent, shadow, uniform).
#
#   tools/bench/accel.sh MESH.obj [VIEW]
#
# VIEW: outside or inside (render bench-accel --view); default inside for meshes under a
# `scenes/` directory (rooms), outside otherwise (scanned objects).
# Environment: ACCEL (our specs, default bvh8,qbvh,bvh), PEERS (default
# obvhs-bvh2,obvhs-cwbvh,bvh-crate,embree), THREADS (default 1), RUNS (interleaved rounds per
# process, median reported, default 5), REPS (processes, one after the other, default 3),
# OUT (output directory, default a new /tmp/accel-bench.*), EMBREE_LIB (default: found in the
# installed embreex wheel), PEERS_TARGET_DIR (accel-peers' build, default /tmp/target-peers;
# render builds in CARGO_TARGET_DIR or target/).
#
# Prints the machine, commit and date, the load before each process, and a Markdown table per
# mesh: medians over the REPS processes of each structure's median-round Mrays/s, and the
# median (range) over the processes of its within-process ratio to Embree.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
mesh=${1:?usage: tools/bench/accel.sh MESH.obj [VIEW]}
view=${2:-}
if [[ -z $view ]]; then
    case $(realpath "$mesh") in */scenes/*) view=inside ;; *) view=outside ;; esac
fi
accel=${ACCEL:-bvh8,qbvh,bvh}
peers=${PEERS:-obvhs-bvh2,obvhs-cwbvh,bvh-crate,embree}
threads=${THREADS:-1}
runs=${RUNS:-5}
reps=${REPS:-3}
out=${OUT:-$(mktemp -d /tmp/accel-bench.XXXXXX)}
mkdir -p "$out"
root_target=${CARGO_TARGET_DIR:-$root/target}
peers_target=${PEERS_TARGET_DIR:-/tmp/target-peers}
if [[ -z ${EMBREE_LIB:-} ]]; then
    EMBREE_LIB=$(python3 -c 'import embreex, pathlib; print(*pathlib.Path(embreex.__file__).parent.parent.glob("embreex.libs/libembree4*"))' 2>/dev/null || true)
fi
if [[ $peers == *embree* && -z $EMBREE_LIB ]]; then
    echo "error: no Embree library: pip install embreex, or set EMBREE_LIB" >&2
    exit 1
fi
export EMBREE_LIB

echo "# accel benchmark, $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "# machine: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1), $(nproc) CPUs, $(free -g | awk '/^Mem:/{print $2}') GiB"
echo "# commit: $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- . ':!docs' || echo ' (with local changes)'), $(rustc --version)"
echo "# mesh: $mesh (view $view), threads $threads, $reps processes of $runs interleaved rounds, output: $out"

(cd "$root" && CARGO_TARGET_DIR=$root_target cargo build --release -q -p rt-cli)
CARGO_TARGET_DIR=$peers_target cargo build --release -q --manifest-path "$root/tools/accel-peers/Cargo.toml"
render="$root_target/release/render"
peer_bin="$peers_target/release/accel-peers"

rays="$out/rays"
"$render" bench-accel "$mesh" --view "$view" --accel bvh --rays primary --check 0 --repeat 1 -q \
    --dump-rays "$rays" >/dev/null
for set in primary incoherent shadow uniform; do
    echo "#   $set: $(($(stat -c %s "$rays/$set.bin") / 24)) rays"
done

csvs=()
for rep in $(seq 1 "$reps"); do
    echo "# process $rep: load average $(cut -d' ' -f1-3 /proc/loadavg) at $(date -u +%H:%M:%S)"
    "$peer_bin" "$mesh" --rays "$rays" --accel "$accel" --peers "$peers" --threads "$threads" \
        --runs "$runs" --csv "$out/peers-$rep.csv" >"$out/peers-$rep.txt" 2>"$out/peers-$rep.log"
    grep -E "differ" "$out/peers-$rep.txt" | awk '$3 != 0 {print "#   check: " $0}' || true
    csvs+=("$out/peers-$rep.csv")
done
python3 "$root/tools/bench/summarize_peers.py" "$(basename "$mesh" .obj)" "$threads" "${csvs[@]}" | tee "$out/summary.md"
