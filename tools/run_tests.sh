#!/usr/bin/env bash
# run_tests.sh TESTBIN: runs the Criterion suite family by family (the
# folders of tests/), so `make test` says what it is doing as it goes: a
# line as each suite of a family finishes (a long family, cli, runs for
# minutes), a line per family with its count and time, the failures in
# full, the total and the ten slowest tests at the end (where the suite's
# time goes). Exits 1 when any test failed.
#
# No test bounds the wall clock (a busy machine stretches it: CI shares its
# cores); tests bound CPU time, and the suites' timeouts are hang guards
# with room for a load of 10 and more. Time bounds belong in make hostile
# and make bench.
set -uo pipefail
bin=${1:?usage: tools/run_tests.sh path/to/bb_tests}
cd "$(dirname "$0")/.."
now() { date +%s.%N; }
start=$(now)
failed=0 total=0
log=$(mktemp "${TMPDIR:-/tmp}/bb_tests.XXXXXX")
times=$(mktemp "${TMPDIR:-/tmp}/bb_times.XXXXXX")
trap 'rm -f "$log" "$times"' EXIT
# Tests per suite ("suite: N tests" in --list), to tell when one is done.
declare -A in_suite
while read -r suite n; do in_suite[$suite]=$n; done < <("$bin" --list 2>&1 |
  sed -n 's/^\([a-z0-9_]*\): \([0-9]*\) tests\{0,1\}$/\1 \2/p')
for dir in tests/*/; do
  family=$(basename "$dir")
  # Folders without Criterion files (tests/tools: the checks' own tests) are not the suite's.
  compgen -G "${dir}test_*.c" >/dev/null || continue
  # The suites a family's files define: Test(SUITE, ...) and TestSuite(SUITE, ...).
  suites=$(sed -n 's/^Test\(Suite\)\{0,1\}(\([a-z0-9_]*\).*/\2/p' "$dir"test_*.c | sort -u | paste -sd'|')
  [ -n "$suites" ] || continue
  t0=$(now)
  # Each suite's line as its last test ends (tests of several suites run
  # side by side on 2 jobs); the whole output kept for the failures.
  { "$bin" --jobs 2 --verbose --filter "@($suites)/*" 2>&1; echo "run_tests: exit $?"; } |
    while IFS= read -r line; do
      printf '%s\n' "$line" >>"$log"
      case $line in
      "[PASS] "*::* | "[FAIL] "*::* | "[SKIP] "*::*) ;;
      *) continue ;;
      esac
      verdict=${line:1:4} name=${line:7} suite=${name%%::*}
      [[ "|$suites|" == *"|$suite|"* ]] || continue # another family's, filtered out
      # "[PASS] suite::test: (1.23s)": the test's own time, for the slowest list
      [[ $line =~ ^\[(PASS|FAIL)\]\ ([^:]+::[^:]+):\ \(([0-9.]+)s\) ]] &&
        printf '%s %s\n' "${BASH_REMATCH[3]}" "${BASH_REMATCH[2]}" >>"$times"
      [ "$verdict" = SKIP ] && [[ $line == *"Test is disabled"* ]] && continue
      done_var=done_$suite fail_var=fail_$suite
      printf -v "$done_var" '%d' $((${!done_var:-0} + 1))
      [ "$verdict" = FAIL ] && printf -v "$fail_var" '%d' $((${!fail_var:-0} + 1))
      if [ "${!done_var}" -eq "${in_suite[$suite]:-0}" ]; then
        printf 'test:   %-7s %-22s %4d tests%s  (%5.1f s)\n' "$family" "$suite" "${!done_var}" \
          "$([ "${!fail_var:-0}" -gt 0 ] && echo ", ${!fail_var} FAILED")" \
          "$(echo "$(now) - $t0" | bc)"
      fi
    done
  status=$(sed -n 's/^run_tests: exit \([0-9]*\)$/\1/p' "$log" | tail -n 1)
  line=$(sed -n 's/.*Synthesis: Tested: \([0-9]*\) | Passing: \([0-9]*\) | Failing: \([0-9]*\) | Crashing: \([0-9]*\).*/\1 \2 \3 \4/p' "$log")
  read -r tested passing failing crashing <<<"${line:-0 0 0 0}"
  total=$((total + tested))
  printf 'test: %-7s %4d tests, %4d passed in %5.1f s' "$family" "$tested" "$passing" \
    "$(echo "$(now) - $t0" | bc)"
  if [ "${status:-1}" -ne 0 ] || [ "${failing:-0}" != 0 ] || [ "${crashing:-0}" != 0 ]; then
    printf ': FAILED\n'
    grep -E '^\[(FAIL|----)\]' "$log" | grep -v '^\[----\] Criterion v' | sed 's/^/  /'
    failed=1
  else
    printf '\n'
  fi
  : >"$log"
done
echo "test: the ten slowest Criterion tests (seconds, each on one of 2 jobs):"
sort -rn "$times" | head -n 10 | awk '{ printf "test:   %6.1f  %s\n", $1, $2 }'
printf 'test: %d Criterion tests in %.0f s%s\n' "$total" "$(echo "$(now) - $start" | bc)" \
  "$([ $failed = 0 ] && echo ', all passed' || echo ', SOME FAILED')"
exit $failed
