#!/usr/bin/env bash
# bench_check.sh [-r ROUNDS] BIN: a golden suite of 200 maps checked three
# ways, for docs/performance.md ("Golden checks").
#
# The suite, built from the fixtures in build/bench/check/: 25 heights (the
# four small fixtures, and rock06_height cut to 21 squares of 64 to 320
# texels at scattered places), baked twice, so 2 x 25 x 4 = 200 maps:
#   png  --scale 16 --rays 64 --maps normal,ssbump,ao,bent   (8-bit PNG)
#   exr  --scale 32 --maps normal,ao,bent,filtered --name {stem}_{kind}.exr
# The goldens are baked, then 3 heights are perturbed (a bump added), so
# their maps fail and the rest pass. Timed ROUNDS times (default 3) in
# turn, every figure the median, with the load:
#   bake     bumpbake bake heights --out-dir OUT --force (writing 200 maps)
#   check    bumpbake check goldens heights --bake (writing nothing)
#   compare  the bake above, then bumpbake compare once per map (the loop a
#            script writes without check)
# each whole under GNU time: wall, CPU of every process, the largest
# process's peak memory. Needs oiiotool (openimageio-tools), /usr/bin/time
# and Debian's python3 with numpy (the perturbation, through the package).
set -euo pipefail

rounds=3
if [ "${1:-}" = -r ]; then
  rounds=$2
  shift 2
fi
bin=$(realpath "${1:?usage: bench_check.sh [-r ROUNDS] BIN}")
root=$(cd "$(dirname "$0")/.." && pwd)
work=$root/build/bench/check
rm -rf "$work" && mkdir -p "$work/heights"
cd "$work"

# ------------------------------------------------------------ the suite
cp "$root"/fixtures/{rock06_128,noise_96x80,pit_65x65,bricks_128x64}.png heights/
n=0
for size in 64 96 128 160 192 256 320; do
  for at in 0 1 2; do
    x=$(((n * 389 + at * 211) % (1024 - size))) y=$(((n * 577 + at * 97) % (1024 - size)))
    oiiotool "$root/fixtures/rock06_height.png" --cut "${size}x${size}+${x}+${y}" \
      --origin +0+0 --fullpixels -d uint16 -o "heights/rock_${size}_${at}.png"
    n=$((n + 1))
  done
done
count=$(ls heights | wc -l)
[ "$count" = 25 ] || { echo "bench_check: $count heights, not 25" >&2; exit 1; }

png=(--scale 16 --rays 64 --maps normal,ssbump,ao,bent)
exr=(--scale 32 --maps normal,ao,bent,filtered --name '{stem}_{kind}.exr')
"$bin" bake heights --out-dir goldens "${png[@]}" -q
"$bin" bake heights --out-dir goldens "${exr[@]}" -q

# Three heights perturbed: a bump of 8% of the range, 6 texels wide.
lib=${BUMPBAKE_LIBRARY:-$(dirname "$bin")}
PYTHONPATH=$root/python BUMPBAKE_LIBRARY=$lib /usr/bin/python3 -c '
import numpy as np
import bumpbake
for name in ("noise_96x80", "rock_128_1", "rock_256_2"):
    path = "heights/%s.png" % name
    h = bumpbake.read(path)
    y, x = np.mgrid[0:h.shape[0], 0:h.shape[1]]
    h = h + 0.08 * np.exp(-((x - 30.0) ** 2 + (y - 30.0) ** 2) / 36.0)
    bumpbake.write(path, np.clip(h, 0, 1).astype(np.float32), kind="height", depth=16)
'

maps=$(ls goldens | wc -l)
echo "bench_check: $count heights, $maps goldens ($(uptime | sed 's/.*load/load/'))"

# ----------------------------------------------------------- the timings
# Each way as a script of its commands, timed whole.
q() { printf '%q ' "$@"; }
{
  echo "rm -rf out"
  echo "$(q "$bin" bake heights --out-dir out --force "${png[@]}" -q)"
  echo "$(q "$bin" bake heights --out-dir out --force "${exr[@]}" -q)"
} >bake.sh
{
  echo "$(q "$bin" check goldens heights --bake "${png[@]}" -q) || true"
  echo "$(q "$bin" check goldens heights --bake "${exr[@]}" -q) || true"
} >check.sh
{
  cat bake.sh
  echo "for f in goldens/*; do $(q "$bin")compare \"\$f\" \"out/\${f#goldens/}\" -q || true; done"
} >compare.sh

rm -f times.*
for r in $(seq "$rounds"); do
  for mode in bake check compare; do
    /usr/bin/time -f "%e %U %S %M" -o "time.$mode" bash "$mode.sh" >/dev/null 2>&1
    awk '{printf "%s %.2f %s\n", $1, $2 + $3, $4}' "time.$mode" >>"times.$mode"
  done
done

median() { sort -n -k"$2" "$1" | awk -v k="$2" '{v[NR] = $k} END {print v[int((NR + 1) / 2)]}'; }
printf '%-8s %10s %10s %12s\n' way "wall s" "cpu s" "peak KiB"
for mode in bake check compare; do
  printf '%-8s %10s %10s %12s\n' "$mode" "$(median "times.$mode" 1)" \
    "$(median "times.$mode" 2)" "$(median "times.$mode" 3)"
done
awk -v b="$(median times.bake 1)" -v c="$(median times.check 1)" \
  -v p="$(median times.compare 1)" -v bc="$(median times.bake 2)" \
  -v cc="$(median times.check 2)" -v pc="$(median times.compare 2)" 'BEGIN {
  printf "check / bake: %.2f wall, %.2f cpu; check / bake-then-compare: %.2f wall, %.2f cpu\n",
    c / b, cc / bc, c / p, cc / pc }'
"$bin" check goldens heights --bake "${png[@]}" | tail -1
"$bin" check goldens heights --bake "${exr[@]}" | tail -1
echo "bench_check: done ($(uptime | sed 's/.*load/load/'))"
