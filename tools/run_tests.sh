#!/usr/bin/env bash
# run_tests.sh TESTBIN [CRITERION OPTIONS]: runs the Criterion suite and says what it is doing
# as it goes: a line as each suite finishes, then a line per family (the
# folders of tests/) with its count and the seconds its tests took, the
# failures, the total and the ten slowest tests at the end (where the
# suite's time goes). Exits 1 when any test failed. The whole output is
# kept beside TESTBIN (bb_tests.log).
#
# The suite runs as one Criterion run on 2 jobs, not family by family: a
# family ending in one long test left a core idle until it finished, and a
# run per family paid that tail once per family.
#
# No test bounds the wall clock (a busy machine stretches it: CI shares its
# cores); tests bound CPU time, and the suites' timeouts are hang guards
# with room for a load of 10 and more. Time bounds belong in make hostile
# and make bench.
set -uo pipefail
bin=${1:?usage: tools/run_tests.sh path/to/bb_tests}
log="$(cd "$(dirname "$bin")" && pwd)/bb_tests.log"
cd "$(dirname "$0")/.."
now() { date +%s.%N; }
start=$(now)
times=$(mktemp "${TMPDIR:-/tmp}/bb_times.XXXXXX")
trap 'rm -f "$times"' EXIT
: >"$log"
# Tests per suite ("suite: N tests" in --list), to tell when one is done.
declare -A in_suite family_of
while read -r suite n; do in_suite[$suite]=$n; done < <("$bin" --list 2>&1 |
  sed -n 's/^\([a-z0-9_]*\): \([0-9]*\) tests\{0,1\}$/\1 \2/p')
# The family of each suite: the folder whose files define it, with
# Test(SUITE, ...) or TestSuite(SUITE, ...). Folders without Criterion files
# (tests/tools: the checks' own tests) have none.
families=()
for dir in tests/*/; do
  compgen -G "${dir}test_*.c" >/dev/null || continue
  family=$(basename "$dir")
  families+=("$family")
  for suite in $(sed -n 's/^Test\(Suite\)\{0,1\}(\([a-z0-9_]*\).*/\2/p' "$dir"test_*.c | sort -u); do
    family_of[$suite]=$family
  done
done
# Each suite's line as its last test ends (tests of several suites run side
# by side on 2 jobs).
{ "$bin" --jobs 2 --verbose "${@:2}" 2>&1; echo "run_tests: exit $?"; } |
  while IFS= read -r line; do
    printf '%s\n' "$line" >>"$log"
    case $line in
    "[PASS] "*::* | "[FAIL] "*::* | "[SKIP] "*::*) ;;
    *) continue ;;
    esac
    verdict=${line:1:4} name=${line:7} suite=${name%%::*}
    # "[PASS] suite::test: (1.23s)": the test's own time, for the slowest list
    [[ $line =~ ^\[(PASS|FAIL)\]\ ([^:]+::[^:]+):\ \(([0-9.]+)s\) ]] &&
      printf '%s %s %s\n' "${BASH_REMATCH[3]}" "${BASH_REMATCH[2]}" \
        "${family_of[$suite]:-?}" >>"$times"
    [ "$verdict" = SKIP ] && [[ $line == *"Test is disabled"* ]] && continue
    done_var=done_$suite fail_var=fail_$suite
    printf -v "$done_var" '%d' $((${!done_var:-0} + 1))
    [ "$verdict" = FAIL ] && printf -v "$fail_var" '%d' $((${!fail_var:-0} + 1))
    if [ "${!done_var}" -eq "${in_suite[$suite]:-0}" ]; then
      printf 'test:   %-7s %-22s %4d tests%s  (%5.1f s)\n' "${family_of[$suite]:-?}" "$suite" \
        "${!done_var}" "$([ "${!fail_var:-0}" -gt 0 ] && echo ", ${!fail_var} FAILED")" \
        "$(echo "$(now) - $start" | bc)"
    fi
  done
status=$(sed -n 's/^run_tests: exit \([0-9]*\)$/\1/p' "$log" | tail -n 1)
line=$(sed -n 's/.*Synthesis: Tested: \([0-9]*\) | Passing: \([0-9]*\) | Failing: \([0-9]*\) | Crashing: \([0-9]*\).*/\1 \2 \3 \4/p' "$log")
read -r total passing failing crashing <<<"${line:-0 0 0 0}"
# A line per family: its tests, how many failed, and the seconds its tests
# took (each on one of the 2 jobs: their sum, not the wall clock).
for family in "${families[@]}"; do
  failures=$(grep -E '^\[FAIL\] ' "$log" | sed 's/^\[FAIL\] \([^:]*\)::.*/\1/' |
    while read -r s; do [ "${family_of[$s]:-}" = "$family" ] && echo; done | wc -l)
  awk -v f="$family" -v bad="$failures" '$3 == f { n++; s += $1 }
    END { if (n) printf "test: %-7s %4d tests%s, %6.1f s of tests\n", f, n,
          (bad > 0 ? ", " bad " FAILED" : ""), s }' "$times"
done
failed=0
if [ "${status:-1}" -ne 0 ] || [ "${failing:-0}" != 0 ] || [ "${crashing:-0}" != 0 ]; then
  failed=1
  # The failures: each [FAIL] line and the assertion (file:line: and its
  # indented message) or crash reported before it; everything is in $log.
  echo "test: FAILED (the whole output: $log):"
  awk '/^\[FAIL\] / { print "  " $0; more = 0; next }
       /^\[----\] [^ ]+:[0-9]+: / { print "  " $0; more = 1; next }
       more && /^\[----\]   / { print "  " $0; next }
       { more = 0 }' "$log"
fi
echo "test: the ten slowest Criterion tests (seconds, each on one of 2 jobs):"
sort -rn "$times" | head -n 10 | awk '{ printf "test:   %6.1f  %s\n", $1, $2 }'
printf 'test: %d Criterion tests in %.0f s%s\n' "$total" "$(echo "$(now) - $start" | bc)" \
  "$([ $failed = 0 ] && echo ', all passed' || echo ', SOME FAILED')"
exit $failed
