#!/usr/bin/env bash
# Writes scenes/shared-data/mitsuba-*.toml: `render convert` of the Mitsuba scenes in
# ../shared/data/mitsuba, each under a header naming its source and licence. They read their
# meshes and textures from ../shared/data (nothing is copied into the repository);
# crates/scene/tests/scenes.rs checks that each still equals a fresh conversion.
# Usage: cargo build --release -p rt-cli && tools/scenes/convert-mitsuba.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
render=${RENDER:-target/release/render}
data=../shared/data/mitsuba
convert() { # name, source folder, header lines...
  local name=$1 folder=$2
  shift 2
  local tmp
  tmp=$(mktemp scenes/shared-data/.convert.XXXXXX.toml)
  if ! "$render" convert "$data/$folder/scene.xml" -o "$tmp" 2>/dev/null; then
    rm -f "$tmp"
    echo "skipped $name: $("$render" convert "$data/$folder/scene.xml" -o "$tmp" 2>&1 | grep -v '^warning' | head -1)"
    rm -f "$tmp"
    return 0
  fi
  { printf '# %s\n' "$@"; echo; cat "$tmp"; } > "scenes/shared-data/$name.toml"
  rm -f "$tmp"
  echo "scenes/shared-data/$name.toml"
}
source_line="From jgarciapueyo/mitsuba2-transient-scenes (commit ab67c4c), as copied into ../shared/data/mitsuba (its README)."
convert mitsuba-cbox cbox \
  "The Cornell box with measured spectral reflectances (Cornell University Program of Computer Graphics)." \
  "$source_line"
convert mitsuba-cbox-point-light cbox-point-light \
  "The Cornell box lit by a point light (Cornell University Program of Computer Graphics)." \
  "$source_line"
convert mitsuba-staircase staircase \
  "\"The Wooden Staircase\" by Wig42, in Benedikt Bitterli's Mitsuba conversion; licence CC BY 3.0" \
  "(https://creativecommons.org/licenses/by/3.0/): credit Wig42. The meshes and textures stay in" \
  "../shared/data/mitsuba/staircase (LICENSE.txt there). $source_line"
