#!/bin/bash
# Fuzzing campaigns outside CI (docs/testing.md, "Fuzzing"): each argument is a group of
# targets run at the same time, groups one after another, each target for $SECS seconds
# (default 3600) at nice 19, on a copy of the committed corpus in $OUT/corpus (the committed
# one is left alone: minimize and cut before committing). Logs: $OUT/fuzz-<target>.log;
# start and exit times: $OUT/done.log; crashes: $OUT/artifacts-<target>-*.
#   fuzz/campaign.sh "scene_toml obj" "gltf glb" ...
set -u
cd "$(dirname "$0")"
OUT=${OUT:-/tmp/rt-fuzz}
mkdir -p "$OUT"
secs=${SECS:-3600}
run() {
  local t=$1
  mkdir -p "$OUT/corpus/$t"
  cp -n corpus/"$t"/* "$OUT/corpus/$t/" 2>/dev/null
  echo "$t start $(date -u +%FT%TZ) $(git rev-parse --short HEAD)" >> "$OUT/done.log"
  nice -n 19 cargo +nightly fuzz run -O "$t" "$OUT/corpus/$t" "seeds/$t" -- \
    -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$OUT/artifacts-$t-" > "$OUT/fuzz-$t.log" 2>&1
  echo "$t exit $? $(date -u +%FT%TZ)" >> "$OUT/done.log"
}
for group in "$@"; do
  for t in $group; do run "$t" & done
  wait
done
echo ALLDONE >> "$OUT/done.log"
