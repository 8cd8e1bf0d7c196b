#!/bin/bash
# bench_blocks_vs.sh: two bumpbake binaries' block compression side by side,
# in one run: PSNR per map and format on real height maps, and the write
# stage against the whole bake.
#
#   tools/bench_blocks_vs.sh OLD NEW [OUTDIR]     (after `make all`)
#
# OLD and NEW are bumpbake binaries (say /work/baseline/bumpbake, whose
# blocks are libsquish's cluster fit, and build/bumpbake). Their direct maps
# are the same bits, so each bakes the same maps; only the blocks differ.
# Maps: rock06 and lava01 (fixtures/ or ../shared/fixtures) and a genheight
# noise map, 1024 x 1024 at scale 64. Per map: ssbump as VTF DXT1, normal as
# VTF DXT1, DDS BC3 and DDS BC5, ao as DDS BC4, each with its mips; level 0
# read back (DDS through OpenImageIO's reader, VTF through the tests' exact
# decoder: build/tools/texture_quality compare) against the float map.
# Then the time: bake --json's write and stage seconds for --ssbump s.png,
# s.vtf and s.dds (and NEW's s.vtf --fast-compression), median of 3, 2
# threads, the two binaries' runs alternated; TIME_ARGS (default
# "--scale 64") sets the bake, e.g. TIME_ARGS="--scale 128 --rays 256".
set -eu

OLD=${1:?usage: bench_blocks_vs.sh OLD NEW [OUTDIR]}
NEW=${2:?usage: bench_blocks_vs.sh OLD NEW [OUTDIR]}
TQ=$(dirname "$NEW")/tools/texture_quality
GEN=$(dirname "$NEW")/tools/genheight
[ -x "$TQ" ] && [ -x "$GEN" ] || { echo "bench_blocks_vs: build first (make all)" >&2; exit 2; }
if [ $# -ge 3 ]; then OUT=$3; mkdir -p "$OUT"; KEEP=1; else OUT=$(mktemp -d); KEEP=0; fi
trap '[ "$KEEP" = 1 ] || rm -rf "$OUT"' EXIT

find_fixture() {
  local input=fixtures/$1 alt
  for alt in ../shared/fixtures ../../shared/fixtures /work/shared/fixtures; do
    [ -f "$input" ] || input=$alt/$1
  done
  [ -f "$input" ] || return 1
  printf '%s' "$input"
}

declare -A height
height[rock06]=$(find_fixture rock06_height.png)
height[lava01]=$(find_fixture lava01_height.png) || unset 'height[lava01]'
"$GEN" noise 1024 1024 "$OUT/noise.png"
height[noise]=$OUT/noise.png

echo "== bench_blocks_vs: $(date -u '+%Y-%m-%d %H:%M UTC'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "   old: $OLD   new: $NEW"
echo "== PSNR (dB) of level 0 against the float map, 1024 x 1024, scale 64"
printf '%-7s %-7s %-9s %9s %9s %8s\n' map kind format old new new-old
for m in rock06 lava01 noise; do
  [ -n "${height[$m]:-}" ] || { echo "$m: not found, skipped"; continue; }
  h=${height[$m]}
  "$NEW" bake "$h" --scale 64 --normal "$OUT/$m.normal.exr" --ssbump "$OUT/$m.ssbump.exr" \
    --ao "$OUT/$m.ao.exr" -q
  for who in old new; do
    bin=$OLD
    [ $who = new ] && bin=$NEW
    "$bin" bake "$h" --scale 64 --ssbump "$OUT/$m.$who.ss.vtf" --normal "$OUT/$m.$who.n1.vtf" \
      --ao "$OUT/$m.$who.ao.dds" -q
    "$bin" bake "$h" --scale 64 --normal "$OUT/$m.$who.n5.dds" -q
    "$bin" bake "$h" --scale 64 --normal "$OUT/$m.$who.n3.dds" --texture-format bc3 -q
  done
  for row in "ssbump ss.vtf dxt1 ssbump" "normal n1.vtf dxt1 normal" "normal n3.dds bc3 normal" \
    "normal n5.dds bc5 normal 2" "ao ao.dds bc4 plain"; do
    set -- $row
    kind=$1 file=$2 fmt=$3 map=$4 ch=${5:-}
    args=(--map "$map")
    [ -n "$ch" ] && args+=(--channels "$ch")
    p_old=$("$TQ" compare "$OUT/$m.$kind.exr" "$OUT/$m.old.$file" "${args[@]}" | awk '{print $2}')
    p_new=$("$TQ" compare "$OUT/$m.$kind.exr" "$OUT/$m.new.$file" "${args[@]}" | awk '{print $2}')
    printf '%-7s %-7s %-9s %9.3f %9.3f %+8.3f\n' "$m" "$kind" "$fmt" "$p_old" "$p_new" \
      "$(awk -v a="$p_new" -v b="$p_old" 'BEGIN { print a - b }')"
  done
done

TIME_ARGS=${TIME_ARGS:---scale 64}
echo "== time: rock06 1024 x 1024, $TIME_ARGS, 2 threads, bake --json seconds, median of 3"
json_num() { sed -n "s/.*\"$1\":\([0-9][0-9.eE+-]*\).*/\1/p" "$2" | head -n1; }
median() { sort -n | sed -n 2p; }
printf '%-4s %-8s %8s %8s %8s %12s\n' bin output write compress stages write/stages
targets=("old png" "old vtf" "old dds" "new png" "new vtf" "new dds" "new vtf-fast")
for i in 1 2 3; do
  for t in "${targets[@]}"; do
    set -- $t
    bin=$OLD
    [ "$1" = new ] && bin=$NEW
    ext=${2%-fast} extra=()
    [ "$2" = vtf-fast ] && extra=(--fast-compression)
    # shellcheck disable=SC2086
    "$bin" bake "${height[rock06]}" $TIME_ARGS --threads 2 --json -q \
      --ssbump "$OUT/t.$1.s.$ext" "${extra[@]}" >"$OUT/t.$1.$2.$i.json"
  done
done
for t in "${targets[@]}"; do
  set -- $t
  write=$(for i in 1 2 3; do json_num write "$OUT/t.$1.$2.$i.json"; done | median)
  compress=$(for i in 1 2 3; do json_num compress "$OUT/t.$1.$2.$i.json"; done | median)
  stages=$(for i in 1 2 3; do
    f=$OUT/t.$1.$2.$i.json
    awk -v a="$(json_num load "$f")" -v b="$(json_num smooth "$f")" \
      -v c="$(json_num pyramid "$f")" -v d="$(json_num trace "$f")" \
      -v e="$(json_num derive "$f")" -v g="$(json_num write "$f")" \
      'BEGIN { printf "%.3f\n", a + b + c + d + e + g }'
  done | median)
  printf '%-4s %-8s %8.3f %8s %8.3f %12.3f\n' "$1" "$2" "$write" "${compress:--}" "$stages" \
    "$(awk -v a="$write" -v b="$stages" 'BEGIN { print a / b }')"
done
echo "(compress: the block compression inside write, where the binary reports it)"
