#!/usr/bin/env bash
# bench_batch.sh [-n FILES] [-r ROUNDS] [-s SIZE] BIN: the cost per file of
# baking many small height maps in one process (`bake DIR --out-dir`)
# against one process per file (`bake FILE -o PREFIX`, as a shell loop or a
# make rule runs it), and of a batch re-run whose outputs are all up to date.
#
#   tools/bench_batch.sh build/bumpbake          (make bench runs it)
#
# FILES (default 20) noise maps of SIZE x SIZE texels (default 256) made by
# build/tools/genheight, baked at scale 16 with bake's default maps (normal,
# ssbump, ao) and rays, 2 threads. The three ways run in turn, ROUNDS times
# (default 5: A B C A B C ...), so load on this shared machine falls on all
# alike; each line gives the median wall time of a round over FILES files,
# that per file, and the ratio to the per-process loop. Everything goes into
# build/bench/batch/. Exits 1 when a bake fails.
set -euo pipefail

files=20 rounds=5 size=256
while [ $# -gt 0 ]; do
  case $1 in
  -n) files=$2; shift 2 ;;
  -r) rounds=$2; shift 2 ;;
  -s) size=$2; shift 2 ;;
  *) break ;;
  esac
done
bin=$(realpath "${1:?usage: tools/bench_batch.sh [-n FILES] [-r ROUNDS] [-s SIZE] BIN}")
genheight=$(dirname "$bin")/tools/genheight
root=$(cd "$(dirname "$0")/.." && pwd)
work=$root/build/bench/batch
rm -rf "$work"
mkdir -p "$work/in" "$work/batch" "$work/loop"

for ((i = 0; i < files; i++)); do
  "$genheight" noise "$size" "$size" "$work/in/h$(printf %02d "$i").png" --seed "$i" >/dev/null
done
opts=(--scale 16 --threads 2 -q)

# The three ways; each prints nothing and fails loudly.
batch() { "$bin" bake "$work/in" "${opts[@]}" --out-dir "$work/batch" --force; }
loop() {
  local f
  for f in "$work"/in/*.png; do
    "$bin" bake "$f" "${opts[@]}" -o "$work/loop/$(basename "${f%.png}")"
  done
}
uptodate() { "$bin" bake "$work/in" "${opts[@]}" --out-dir "$work/batch"; }

batch # warm-up, and the outputs the up-to-date runs find
declare -A times
for ((r = 0; r < rounds; r++)); do
  for way in loop batch uptodate; do
    t0=$EPOCHREALTIME
    "$way"
    t1=$EPOCHREALTIME
    times[$way]+="$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f", b - a }') "
  done
done
# The batch and the loop bake the same pixels (their provenance differs:
# the command lines do).
for f in "$work"/batch/*.png; do
  "$bin" compare "$f" "$work/loop/$(basename "$f")" -fail 0 -warn 0 -q ||
    { echo "bench_batch: $f differs from the per-process bake" >&2; exit 1; }
done

median() { tr ' ' '\n' <<<"$1" | sed '/^$/d' | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
loop_s=$(median "${times[loop]}")
printf '%d files of %d x %d, scale 16, normal + ssbump + ao, median of %d rounds:\n' \
  "$files" "$size" "$size" "$rounds"
printf '%-34s %9s %11s %9s\n' way "round_s" "per_file_s" "x_loop"
for way in loop batch uptodate; do
  m=$(median "${times[$way]}")
  case $way in
  loop) label="one process per file" ;;
  batch) label="one batch process (--force)" ;;
  uptodate) label="batch, all up to date" ;;
  esac
  awk -v l="$label" -v m="$m" -v n="$files" -v base="$loop_s" \
    'BEGIN { printf "%-34s %9.3f %11.4f %9.3f\n", l, m, m / n, m / base }'
done
