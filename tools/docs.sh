#!/usr/bin/env bash
# docs.sh BIN: regenerates the pictures of README.md and docs/ (small PNGs,
# kept in git): the contact sheet of the rock fixture, the paper's
# four-panel comparison on a 128 x 128 window where self-shadowing shows,
# the azimuth wedges of docs/accuracy.md and the page of `bumpbake serve`. Run by `make docs`, never by
# `make test`.
set -euo pipefail

bin=${1:?usage: tools/docs.sh path/to/bumpbake}
tools=$(dirname "$bin")/tools
input=fixtures/rock06_height.png
mkdir -p docs build/docs
"$bin" sheet "$input" --scale 128 --panel-size 128 -o docs/rock06_sheet.png
# Light from the right at 20 degrees; the window (480, 896) is where the plain
# and ssbump renders differ most on this map (mean 0.15 over the window).
# The highlight at a third of the light: at full strength it saturates whole faces.
"$bin" render "$input" --scale 128 --compare --light 0,20 --specular-strength 0.35 --crop 480,896,128,128 \
  -o docs/rock06_compare.png

# Azimuth wedges: the ao of small sharp cones on a flat plane at 16 and 32
# slices, a 64 x 64 window around one cone enlarged 3 times, as baked (top)
# and with the contrast above 0.9 stretched ten times (bottom).
"$tools/genheight" cones 128 128 build/docs/cones.png
panels=()
for slices in 16 32; do
  "$bin" bake build/docs/cones.png --scale 12 --filter-radius 0 --slices "$slices" \
    --ao "build/docs/cones_ao_$slices.exr" -q
  for view in plain stretched; do
    stretch=()
    label="$slices slices"
    if [ "$view" = stretched ]; then
      stretch=(--subc 0.9 --mulc 10 --clamp:min=0:max=1)
      label="$slices slices, x10 above 0.9"
    fi
    oiiotool "build/docs/cones_ao_$slices.exr" --cut 64x64+8+8 --ch 0,0,0 "${stretch[@]}" \
      --resize:filter=box 192x192 \
      --text:x=6:y=186:size=14:font=DejaVuSans:color=0.8,0,0 "$label" \
      -d uint8 -o "build/docs/wedges_${view}_$slices.png"
  done
  panels+=("build/docs/wedges_plain_$slices.png")
done
oiiotool "${panels[@]}" build/docs/wedges_stretched_16.png build/docs/wedges_stretched_32.png \
  --mosaic:pad=4 2x2 -d uint8 -o docs/azimuth_wedges.png
# The page of `bumpbake serve` (docs/commands/serve.md), in headless Chromium.
/usr/bin/python3 tools/serve_screenshot.py "$bin" docs/serve.png
ls -l docs/rock06_sheet.png docs/rock06_compare.png docs/azimuth_wedges.png docs/serve.png
