#!/usr/bin/env bash
# demo.sh BIN: bakes the rock fixture at scale 64 into out/ (normal, ssbump,
# ao and bent normal as PNG), then renders the rivet panel sculpt's normal
# map and height and bakes ssbump and ao from that height, and ends by
# lighting the rock: the paper's comparison from its maps and a contact sheet.
# Says what it wrote. Exits non-zero on failure.
set -euo pipefail

bin=${1:?usage: tools/demo.sh path/to/bumpbake}
input=fixtures/rock06_height.png
if [ ! -f "$input" ]; then
  echo "demo: $input not found (run it from the checkout's top directory)" >&2
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

# DOOM 3's RenderBumpFlat, then the same sculpt's ssbump and ao: the model
# (made by tools/gensculpt) tiles with the unit square as its period.
model=fixtures/rivet_panel.obj
echo "demo: render bump of $model (512 x 512, tiled), then ssbump and ao of its height"
start=$(date +%s%N)
report=$("$bin" renderbumpflat -size 512 512 "$model" --rect 0 0 1 1 --tile \
  -o out/rivet_panel_local.tga --height out/rivet_panel_height.png)
echo "$report"
scale=$(printf '%s\n' "$report" | sed -n 's/^height scale \([^ ]*\) .*/\1/p')
if [ -z "$scale" ]; then
  echo "demo: renderbumpflat printed no height scale" >&2
  exit 1
fi
"$bin" bake out/rivet_panel_height.png --scale "$scale" \
  --normal out/rivet_panel_normal.png \
  --ssbump out/rivet_panel_ssbump.png \
  --ao out/rivet_panel_ao.png
ms=$((($(date +%s%N) - start) / 1000000))
printf 'demo: done in %d.%03d s; look at out/rivet_panel_local.tga and out/rivet_panel_ssbump.png\n' \
  $((ms / 1000)) $((ms % 1000))

# The rock lit: the paper's four panels from the maps baked above (no second
# bake), a low light from the right, on a 512 x 512 window; then the contact
# sheet of every map (this one bakes again).
"$bin" render --normal out/rock06_normal.png --ssbump out/rock06_ssbump.png \
  --ao out/rock06_ao.png --bent out/rock06_bent.png \
  --compare --light 0,20 --specular-strength 0.35 --crop 256,512,512,512 -o out/rock06_compare.png
"$bin" sheet "$input" --scale 64 -o out/rock06_sheet.png
echo "demo: look at out/rock06_compare.png and out/rock06_sheet.png"
