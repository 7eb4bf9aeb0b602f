#!/usr/bin/env bash
# Time to error of our path tracer against Mitsuba 3 `llvm_ad_rgb` on the same scenes
# (Mitsuba's Cornell box and the box with the Stanford dragon, built by
# tools/reference/mitsuba_to_toml.py). Prints a Markdown table (also written to $OUT/table.md,
# with every number in $OUT/results.json). Method and definitions: tools/bench/time_to_error.py
# and docs/benchmarks.md, "Time to error against Mitsuba 3 `llvm_ad_rgb`".
#
# Installs nothing. Needs:
#   pip install mitsuba numpy                  # Mitsuba 3 (tested: 3.9.1, Dr.Jit 1.5.0)
#   apt-get install libllvm19                  # for Mitsuba's llvm_* variants
#   cargo build --release -p rt-cli            # our `render` (or set RENDER)
#   ../shared/data/models/stanford-dragon.obj  # for the dragon scene (or set DRAGON)
# DRJIT_LIBLLVM_PATH is set to /usr/lib/x86_64-linux-gnu/libLLVM-19.so when that file exists and
# the variable is unset.
#
# Environment (defaults in brackets):
#   SCENES       scenes to run: cbox, dragon, or paths to ["cbox dragon"]
#                Mitsuba .xml files (rendered at 256x256 from one patched copy, both at the
#                file's own depth; tools/reference/mitsuba_copy.py)
#   SPP          our spp ladder                        ["64 128 256 512 1024"]
#   THREADS      threads of both renderers             [2]
#   RENDER       our binary                            [target/release/render]
#   OUT          output directory (images, TOML, json) [/tmp/rt-time-to-error]
#   MI_SPP       Mitsuba's timed spp                   [1024]
#   REF_SPP      Mitsuba reference spp                 [16384]
#   REF_THREADS  threads for the (untimed) reference   [nproc]
#   CACHE        reference cache  [${XDG_CACHE_HOME:-~/.cache}/rt-time-to-error]
#   DRAGON       the dragon OBJ                        [../shared/data/models/stanford-dragon.obj]
#   MI_SEED, REF_SEED, VARIANT                         [1, 7, llvm_ad_rgb]
#   INTEGRATOR   our integrator                        [wavefront]
#   COMMIT       commit RENDER was built from          [git rev-parse --short HEAD]
#   REF_ONLY     1: render (or find) the references and stop, so that a later timed run
#                can start on a quiet machine                           [unset]
#
# A cold reference takes long (16384 spp at 256x256: about 10 min for the box, more for the
# dragon, on 2 cores); it is rendered once per scene and Mitsuba version and then cached.
# Example: CARGO_TARGET_DIR=/tmp/t cargo build --release -p rt-cli &&
#          RENDER=/tmp/t/release/render OUT=/tmp/tte tools/bench/time-to-error.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
llvm=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
if [[ -z "${DRJIT_LIBLLVM_PATH:-}" && -e $llvm ]]; then
  export DRJIT_LIBLLVM_PATH=$llvm
fi
python3 -c 'import mitsuba, numpy' 2>/dev/null || {
  echo "error: needs Python packages mitsuba and numpy (pip install mitsuba numpy)" >&2
  exit 1
}
render=${RENDER:-target/release/render}
[[ -x $render ]] || {
  echo "error: no render binary at $render (cargo build --release -p rt-cli, or set RENDER)" >&2
  exit 1
}
export RENDER=$render
exec python3 tools/bench/time_to_error.py
