#!/usr/bin/env bash
# test_cpu.sh TESTBIN [FAMILY...]: the CPU seconds (user and system, the
# tests' own and the programs they run) of the Criterion suite's families
# (the folders of tests/), each run alone on 2 jobs, and the sum. CPU time,
# not the wall clock: it hardly moves with the machine's load, so a change
# to the tests can be weighed on a busy machine. BB_BIN (default
# build/bumpbake) is the binary the CLI tests run; each family's whole
# output is kept in $TMPDIR/bb_cpu.FAMILY.log.
#
# Each test is its own process (Criterion runs every test in a fresh copy of
# TESTBIN) and most CLI tests start bumpbake a few times: a family's CPU is
# mostly those starts when its tests are small.
set -uo pipefail
bin=${1:?usage: tools/test_cpu.sh path/to/bb_tests [FAMILY...]}
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
shift
cd "$(dirname "$0")/.."
export BB_BIN=${BB_BIN:-build/bumpbake} BB_FIXTURES=${BB_FIXTURES:-fixtures}
families=${*:-$(for d in tests/*/; do basename "$d"; done)}
total=0
for family in $families; do
  dir=tests/$family/
  compgen -G "${dir}test_*.c" >/dev/null || continue
  suites=$(sed -n 's/^Test\(Suite\)\{0,1\}(\([a-z0-9_]*\).*/\2/p' "$dir"test_*.c | sort -u | paste -sd'|')
  [ -n "$suites" ] || continue
  log=${TMPDIR:-/tmp}/bb_cpu.$family.log
  /usr/bin/time -o "$log.cpu" -f '%U %S' "$bin" --jobs 2 --verbose --filter "@($suites)/*" \
    >"$log" 2>&1
  cpu=$(awk 'END { printf "%.1f", $1 + $2 }' "$log.cpu")
  rm -f "$log.cpu"
  tests=$(grep -c '^\[\(PASS\|FAIL\)\] ' "$log")
  failed=$(grep -c '^\[FAIL\] ' "$log")
  printf 'cpu: %-7s %4d tests%s %7.1f s\n' "$family" "$tests" \
    "$([ "$failed" -gt 0 ] && echo ", $failed FAILED")" "$cpu"
  total=$(echo "$total + $cpu" | bc)
done
printf 'cpu: all     %7.1f s (user + system)\n' "$total"
