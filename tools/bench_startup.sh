#!/usr/bin/env bash
# bench_startup.sh [-n RUNS] [-i] NAME=BIN...: start-up time of bumpbake
# builds, as the median wall time of `BIN --version` over RUNS runs (default
# 41); with -i also the instructions one run executes (valgrind's callgrind,
# dynamic loader included), which machine load does not move.
#
#   tools/bench_startup.sh static=build/bumpbake shared=build/bench/bumpbake-shared
#
# The builds are run in turn (A B C A B C ...), so load on this shared
# machine falls on all of them alike; each line gives the median, the
# quartiles and the ratio to the first build. `make bench` runs it on the
# default CLI (static library) and the CLI linked to libbumpbake.so.
set -euo pipefail

runs=41 instructions=0
while [ $# -gt 0 ]; do
  case $1 in
  -n) runs=$2; shift 2 ;;
  -i) instructions=1; shift ;;
  *) break ;;
  esac
done
[ $# -ge 1 ] || { echo "usage: tools/bench_startup.sh [-n RUNS] [-i] NAME=BIN..." >&2; exit 2; }
if [ "$instructions" = 1 ] && ! command -v valgrind >/dev/null 2>&1; then
  echo "bench_startup: valgrind not found; no instruction counts"
  instructions=0
fi

names=() bins=()
for arg in "$@"; do
  names+=("${arg%%=*}") bins+=("${arg#*=}")
  [ -x "${arg#*=}" ] || { echo "bench_startup: ${arg#*=}: not an executable" >&2; exit 1; }
done

# One warm-up run each, so the first timed run does not pay for cold caches.
for b in "${bins[@]}"; do "$b" --version >/dev/null; done

declare -A times
for ((r = 0; r < runs; r++)); do
  for i in "${!bins[@]}"; do
    t0=$EPOCHREALTIME
    "${bins[$i]}" --version >/dev/null
    t1=$EPOCHREALTIME
    times[$i]+="$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }') "
  done
done

# quantiles "T T T ...": median, lower and upper quartile (nearest rank).
quantiles() {
  tr ' ' '\n' <<<"$1" | sed '/^$/d' | sort -g | awk '{ v[NR] = $1 }
    END { printf "%.4f %.4f %.4f", v[int((NR + 1) / 2)], v[int((NR + 3) / 4)], v[int((3 * NR + 3) / 4)] }'
}

# instructions BIN: instructions of one `BIN --version`, in millions.
instructions_of() {
  local log
  log=$(mktemp)
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$1" --version >/dev/null 2>"$log" || true
  sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$log" | awk '{ printf "%.0f", $1 / 1e6 }'
  rm -f "$log"
}

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2f", a / b; else printf "n/a" }'; }

printf '%-8s %9s %9s %9s %7s %9s %7s  %s\n' build median_s q1_s q3_s ratio Minstr ratio binary
base="" base_instr=""
for i in "${!bins[@]}"; do
  read -r med q1 q3 <<<"$(quantiles "${times[$i]}")"
  [ -n "$base" ] || base=$med
  instr=- instr_ratio=-
  if [ "$instructions" = 1 ]; then
    instr=$(instructions_of "${bins[$i]}")
    [ -n "$base_instr" ] || base_instr=$instr
    instr_ratio=$(ratio "$instr" "$base_instr")
  fi
  printf '%-8s %9s %9s %9s %7s %9s %7s  %s\n' "${names[$i]}" "$med" "$q1" "$q3" \
    "$(ratio "$med" "$base")" "$instr" "$instr_ratio" "${bins[$i]}"
done
echo "(bumpbake --version, $runs runs each, alternated; ratio = median / the first build's median;"
echo " Minstr = millions of instructions of one run under callgrind, loader included)"
