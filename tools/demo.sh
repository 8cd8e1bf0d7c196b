#!/usr/bin/env bash
# demo.sh BIN: bakes the rock fixture at scale 64 into out/ (normal, ssbump,
# ao and bent normal as PNG) and says what it wrote. Exits non-zero on failure.
set -euo pipefail

bin=${1:?usage: tools/demo.sh path/to/bumpbake}
input=fixtures/rock06_height.png
# The fixture is copied into fixtures/ by the fixtures issue; until then the
# shared copy beside the checkout (or beside the worktrees) is used.
for alt in ../shared/fixtures ../../shared/fixtures; do
  [ -f "$input" ] || input=$alt/rock06_height.png
done
if [ ! -f "$input" ]; then
  echo "demo: rock06_height.png not found in fixtures/ or ../shared/fixtures/" >&2
  exit 1
fi

mkdir -p out
echo "demo: baking $input (scale 64) into out/"
start=$(date +%s%N)
"$bin" bake "$input" --scale 64 \
  --normal out/rock06_normal.png \
  --ssbump out/rock06_ssbump.png \
  --ao out/rock06_ao.png \
  --bent out/rock06_bent.png
ms=$((($(date +%s%N) - start) / 1000000))
printf 'demo: done in %d.%03d s; look at out/rock06_ssbump.png and out/rock06_ao.png\n' \
  $((ms / 1000)) $((ms % 1000))
