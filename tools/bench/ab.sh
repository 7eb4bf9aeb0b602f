#!/usr/bin/env bash
# Two settings of one binary, alternating, one thread: prints the minimum and median render
# time of each (render-only, from `render --stats`) and their ratios. For changes whose effect
# is smaller than the machine's noise between separate runs (e.g. `--integrator path` against
# `--integrator wavefront`, or `wavefront:lanes=N`).
#
#   tools/bench/ab.sh ROUNDS SCENE SPP -- ARGS_A... -- ARGS_B...
#
# Environment: R (the binary, default target/release/render); RB (B's binary, default R: set it to
# time two builds, e.g. before and after a change, with the same arguments).
set -euo pipefail
n=$1; scene=$2; spp=$3; shift 3; shift
a=(); while [[ $1 != -- ]]; do a+=("$1"); shift; done; shift; b=("$@")
R=${R:-target/release/render}
RB=${RB:-$R}
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
echo "$(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; $(git rev-parse --short HEAD); $(date -u '+%Y-%m-%d %H:%M UTC'); load $(cut -d' ' -f1-3 /proc/loadavg)"
for _ in $(seq "$n"); do
  for w in A B; do
    if [[ $w == A ]]; then args=("${a[@]}"); bin=$R; else args=("${b[@]}"); bin=$RB; fi
    "$bin" "$scene" --spp "$spp" --max-depth 10000 --threads 1 -o "$out/$w.exr" -q --stats "${args[@]}" |
      awk -v w=$w '/^render  /{print w, $3}'
  done
done | python3 -c "
import sys, statistics
d = {}
for l in sys.stdin:
    w, t = l.split(); d.setdefault(w, []).append(float(t))
for w in sorted(d): print(w, 'min %.0f ms, median %.0f ms, n %d' % (min(d[w]), statistics.median(d[w]), len(d[w])))
print('B/A: min %.3f, median %.3f' % (min(d['B']) / min(d['A']), statistics.median(d['B']) / statistics.median(d['A'])))
"
