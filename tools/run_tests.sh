#!/usr/bin/env bash
# run_tests.sh TESTBIN: runs the Criterion suite family by family (the
# folders of tests/), so `make test` says what it is doing as it goes: one
# line per family with its count and time, the failures in full, and the
# total at the end. Exits 1 when any test failed.
set -uo pipefail
bin=${1:?usage: tools/run_tests.sh path/to/bb_tests}
cd "$(dirname "$0")/.."
start=$(date +%s.%N)
failed=0 total=0
for dir in tests/*/; do
  family=$(basename "$dir")
  # Folders without Criterion files (tests/tools: the checks' own tests) are not the suite's.
  compgen -G "${dir}test_*.c" >/dev/null || continue
  # The suites a family's files define: Test(SUITE, ...) and TestSuite(SUITE, ...).
  suites=$(sed -n 's/^Test\(Suite\)\{0,1\}(\([a-z0-9_]*\).*/\2/p' "$dir"test_*.c | sort -u | paste -sd'|')
  [ -n "$suites" ] || continue
  t0=$(date +%s.%N)
  out=$("$bin" --jobs 2 --filter "@($suites)/*" 2>&1)
  status=$?
  line=$(printf '%s\n' "$out" | sed -n 's/.*Synthesis: Tested: \([0-9]*\) | Passing: \([0-9]*\) | Failing: \([0-9]*\) | Crashing: \([0-9]*\).*/\1 \2 \3 \4/p')
  read -r tested passing failing crashing <<<"${line:-0 0 0 0}"
  total=$((total + tested))
  printf 'test: %-7s %4d tests, %4d passed in %5.1f s' "$family" "$tested" "$passing" \
    "$(echo "$(date +%s.%N) - $t0" | bc)"
  if [ "$status" -ne 0 ] || [ "${failing:-0}" != 0 ] || [ "${crashing:-0}" != 0 ]; then
    printf ': FAILED\n'
    printf '%s\n' "$out" | grep -E '^\[(FAIL|----)\]' | sed 's/^/  /'
    failed=1
  else
    printf '\n'
  fi
done
printf 'test: %d Criterion tests in %.0f s%s\n' "$total" "$(echo "$(date +%s.%N) - $start" | bc)" \
  "$([ $failed = 0 ] && echo ', all passed' || echo ', SOME FAILED')"
exit $failed
