#!/usr/bin/env bash
# docs.sh BIN: regenerates the README's pictures in docs/ (small PNGs, kept
# in git): the contact sheet of the rock fixture and the paper's four-panel
# comparison on a 128 x 128 window where self-shadowing shows. Run by
# `make docs`, never by `make test`.
set -euo pipefail

bin=${1:?usage: tools/docs.sh path/to/bumpbake}
input=fixtures/rock06_height.png
mkdir -p docs
"$bin" sheet "$input" --scale 128 --panel-size 128 -o docs/rock06_sheet.png
# Light from the right at 20 degrees; the window (480, 896) is where the plain
# and ssbump renders differ most on this map (mean 0.15 over the window).
# The highlight at a third of the light: at full strength it saturates whole faces.
"$bin" render "$input" --scale 128 --compare --light 0,20 --specular-strength 0.35 --crop 480,896,128,128 \
  -o docs/rock06_compare.png
ls -l docs/rock06_sheet.png docs/rock06_compare.png
