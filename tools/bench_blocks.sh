#!/bin/sh
# bench_blocks.sh: what block compression costs the engine textures, and how
# long writing them takes.
#
#   tools/bench_blocks.sh [BIN] [OUTDIR]     (after `make all`)
#
# BIN is bumpbake (default build/bumpbake); OUTDIR keeps every file made
# (default: a temporary directory, removed at the end). Bakes
# fixtures/rock06_height.png at scale 64 (1024 x 1024: normal, ssbump, ao as
# float EXR, the uncompressed reference), writes each map in each block
# format with build/tools/texture_quality, reads it back (DDS through
# OpenImageIO, VTF through the tests' own decoder) and prints PSNR and the
# worst error in 8-bit codes against the float map (normal maps compared as
# 0.5 + 0.5 N; 8-bit rounding alone gives ~58.9 dB and 0.5). For normal maps
# also the mean and worst angle between decoded and true normals. Then the
# same with NVIDIA Texture Tools' nvcompress (Debian's libnvtt-bin, if
# installed) on the 8-bit PNG of each map (its BC1 output differs from run
# to run: one run each, so its rows move in the last digits). Then the
# time block compression takes: a 1024 and a 2048 ssbump written as VTF DXT1
# and DDS BC1 with their mips (2 threads, and 1 for 1024) against writing
# them as PNG, and nvcompress's time for the same DDS BC1 with mips; and the
# write stage of a bake (PNG, float and half EXR, VTF, DDS) against its
# trace, from bake --json's stages.
set -eu

BIN=${1:-build/bumpbake}
TQ=$(dirname "$BIN")/tools/texture_quality
[ -x "$BIN" ] && [ -x "$TQ" ] || { echo "bench_blocks: build first (make all): $BIN, $TQ" >&2; exit 2; }
if [ $# -ge 2 ]; then OUT=$2; mkdir -p "$OUT"; KEEP=1; else OUT=$(mktemp -d); KEEP=0; fi
trap '[ "$KEEP" = 1 ] || rm -rf "$OUT"' EXIT
FIX=${BB_FIXTURES:-fixtures}

"$BIN" bake "$FIX/rock06_height.png" --scale 64 --normal "$OUT/normal.exr" \
  --ssbump "$OUT/ssbump.exr" --ao "$OUT/ao.exr" -q

row() { # CODEC MAP FORMAT FILE COMPARE-ARGS...
  codec=$1 map=$2 format=$3 file=$4
  shift 4
  printf '%-12s %-7s %-13s %s\n' "$codec" "$map" "$format" "$("$TQ" compare "$OUT/$map.exr" "$file" "$@")"
}

# write MAP FORMAT EXT [OPTIONS]: our file, and its row.
ours() {
  map=$1 format=$2 ext=$3
  shift 3
  kind=plain
  [ "$map" = normal ] && kind=normal
  [ "$map" = ssbump ] && kind=ssbump
  file=$OUT/${map}_$format$(printf '%s' "$*" | tr -d ' -').$ext
  seconds=$("$TQ" write "$OUT/$map.exr" "$file" --map "$kind" --format "$format" "$@")
  channels=
  [ "$format" = bc5 ] && channels="--channels 2"
  # shellcheck disable=SC2086
  row "bumpbake$(printf '%s' "$*" | sed 's/--fast/-fast/')" "$map" "$ext $format" "$file" --map "$kind" $channels
  echo "$seconds" >"$file.seconds"
}

echo "== quality: rock06 1024 x 1024, scale 64, every level written (level 0 compared)"
printf '%-12s %-7s %-13s %s\n' codec map file "result (codes of 255)"
ours normal bc1 dds
ours normal bc1 dds --fast
ours normal bc3 dds
ours normal bc5 dds
ours normal rgba8 dds
ours normal bc1 vtf
ours ssbump bc1 dds
ours ssbump bc1 dds --fast
ours ssbump bc3 dds
ours ssbump bc1 vtf
ours ssbump bgr888 vtf
ours ao bc4 dds
ours ao bc1 dds
ours ao bc1 vtf

if command -v nvcompress >/dev/null 2>&1; then
  echo "== the same through NVIDIA Texture Tools 2.0.8 (nvcompress -nomips, 8-bit PNG in)"
  "$TQ" write "$OUT/normal.exr" "$OUT/normal8.png" --map normal >/dev/null
  "$TQ" write "$OUT/ssbump.exr" "$OUT/ssbump8.png" >/dev/null
  "$TQ" write "$OUT/ao.exr" "$OUT/ao8.png" >/dev/null
  # nvtt 2.0.8's BC4 encodes the alpha channel (a grey PNG's is 255
  # everywhere): give it ao in every channel, alpha included.
  oiiotool "$OUT/ao8.png" --ch 0,0,0,0 --chnames R,G,B,A -o "$OUT/ao8rgba.png"
  for job in "normal bc1" "normal bc3" "normal bc5" "ssbump bc1" "ssbump bc3" "ao bc4" "ao bc1"; do
    set -- $job
    in=$OUT/${1}8.png
    [ "$2" = bc4 ] && in=$OUT/ao8rgba.png
    nvcompress -nomips -"$2" "$in" "$OUT/${1}_nvtt_$2.dds" >/dev/null 2>&1
    kind=plain
    [ "$1" = normal ] && kind=normal
    channels=
    [ "$2" = bc5 ] && channels="--channels 2"
    # shellcheck disable=SC2086
    row nvtt "$1" "dds $2" "$OUT/${1}_nvtt_$2.dds" --map "$kind" $channels
  done
else
  echo "== nvcompress not found (apt-get install libnvtt-bin for the NVIDIA Texture Tools rows)"
fi

echo "== time: block compression of a 1024 and a 2048 ssbump (rock06, resized for 2048; scale 128),"
echo "   written in-process by texture_quality write, median of 3"
median() { sort -n | sed -n 2p; }
"$BIN" bake "$FIX/rock06_height.png" --scale 128 --ssbump "$OUT/ss1024.exr" -q
oiiotool "$FIX/rock06_height.png" --resize 2048x2048 -d uint16 -o "$OUT/h2048.png"
"$BIN" bake "$OUT/h2048.png" --scale 128 --ssbump "$OUT/ss2048.exr" -q
printf '%-6s %-24s %9s %12s\n' size file seconds bytes
for size in 1024 2048; do
  for target in "png" "vtf --threads 2" "vtf --threads 1" "vtf --fast --threads 2" \
    "dds --threads 2" "dds --threads 1"; do
    set -- $target
    ext=$1
    shift
    # one thread at 2048 takes half a minute a run: 1024 shows the speed-up
    case "$size $*" in "2048 "*"--threads 1") continue ;; esac
    t=$(for i in 1 2 3; do
      "$TQ" write "$OUT/ss$size.exr" "$OUT/ss$size.$ext" --map ssbump "$@"
    done | median)
    printf '%-6s %-24s %9s %12s\n' "$size" "$ext ${*:-}" "$t" "$(wc -c <"$OUT/ss$size.$ext")"
  done
done
if command -v nvcompress >/dev/null 2>&1; then
  "$TQ" write "$OUT/ss2048.exr" "$OUT/ss2048_8.png" >/dev/null
  for target in "" "-fast"; do
    t=$(for i in 1 2 3; do
      s=$(date +%s.%N)
      nvcompress $target -bc1 "$OUT/ss2048_8.png" "$OUT/ss2048_nvtt.dds" >/dev/null 2>&1
      awk -v a="$(date +%s.%N)" -v b="$s" 'BEGIN { printf "%.3f\n", a - b }'
    done | median)
    printf '%-6s %-24s %9s %12s\n' 2048 "dds nvcompress ${target:-}" "$t" \
      "$(wc -c <"$OUT/ss2048_nvtt.dds")"
  done
fi
echo "(png: 8-bit through OpenImageIO; vtf: DXT1 + all mip levels + low-res; dds: BC1 + mips;"
echo " --fast: the quick fit; nvcompress: the whole process, from the 8-bit PNG, its own threads)"

echo "== the write stage of a bake against its trace: rock06 1024 x 1024, scale 128, 256 rays,"
echo "   2 threads (bake --json's stages), median of 3"
# json_num KEY FILE: a number of the bake's JSON line.
json_num() { sed -n "s/.*\"$1\":\([0-9][0-9.eE+-]*\).*/\1/p" "$2" | head -n1; }
printf '%-10s %8s %8s %8s %12s %12s  %s\n' outputs trace_s write_s stages_s write/trace write/stages \
  options
for job in "png -o:w" "exr-float --ao:a.exr --ssbump:s.exr" \
  "exr-half --ao:a.exr --ssbump:s.exr --depth half" "vtf --ssbump:s.vtf" "dds --ssbump:s.dds" \
  "vtf-fast --ssbump:s.vtf --fast-compression"; do
  set -- $job
  label=$1
  shift
  args=
  for a in "$@"; do
    case $a in
    *:*) args="$args ${a%%:*} $OUT/bake_${a#*:}" ;;
    *) args="$args $a" ;;
    esac
  done
  for i in 1 2 3; do
    # shellcheck disable=SC2086
    "$BIN" bake "$FIX/rock06_height.png" --scale 128 --rays 256 --threads 2 --json -q $args \
      >"$OUT/stage_$label.$i.json"
  done
  med() { for i in 1 2 3; do json_num "$1" "$OUT/stage_$label.$i.json"; done | median; }
  stages=$(for i in 1 2 3; do
    f=$OUT/stage_$label.$i.json
    awk -v a="$(json_num load "$f")" -v b="$(json_num smooth "$f")" -v c="$(json_num pyramid "$f")" \
      -v d="$(json_num trace "$f")" -v e="$(json_num derive "$f")" -v g="$(json_num write "$f")" \
      'BEGIN { printf "%.3f\n", a + b + c + d + e + g }'
  done | median)
  trace=$(med trace) write=$(med write)
  printf '%-10s %8.3f %8.3f %8.3f %12s %12s  %s\n' "$label:" "$trace" "$write" "$stages" \
    "$(awk -v a="$write" -v b="$trace" 'BEGIN { printf "%.3f", a / b }')" \
    "$(awk -v a="$write" -v b="$stages" 'BEGIN { printf "%.3f", a / b }')" "$(echo "$@" | tr ':' ' ')"
done
echo "(png -o: normal, ssbump and ao as 8-bit PNG; exr: float, or half with --depth half;"
echo " stages_s: the sum of the bake's stages, load to write; the goal is write/stages under 0.10)"
