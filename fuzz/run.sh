#!/usr/bin/env bash
# fuzz/run.sh: runs the libFuzzer targets `make fuzz` built.
#   fuzz/run.sh BUILD_DIR SECONDS "fuzz_NAME [libFuzzer options]" ...
# For each target: replays the saved crash inputs of fuzz/regressions/NAME,
# then fuzzes SECONDS seconds from build/fuzz/corpus/NAME (kept between runs)
# and the seeds make_seeds wrote, and prints executions and time per
# target. Exits 1 when a target crashed, leaked, failed a property, took
# longer than FUZZ_TIMEOUT seconds on one input, allocated more than
# FUZZ_MALLOC_MB at once or grew past FUZZ_RSS_MB; the input is saved in
# BUILD_DIR/crashes/ (crash-, leak-, timeout- or oom-HASH). Inputs libFuzzer
# saves there without the target failing (slow units; a child process's own
# report) are named on the target's line as saved without failing.
#
# The limits (environment, `make fuzz` passes them on):
#   FUZZ_TIMEOUT   (10)   seconds one input may take (ASan and UBSan on)
#   FUZZ_MALLOC_MB (1100) one allocation: a read's documented bound is
#                         BB_MAX_READ_BYTES (1024 MiB), so more is a bug
#   FUZZ_RSS_MB    (2560) the process: that bound touched, with the
#                         sanitizers' own overhead
set -uo pipefail
build=$1 seconds=$2
shift 2
limits=(-timeout="${FUZZ_TIMEOUT:-10}" -malloc_limit_mb="${FUZZ_MALLOC_MB:-1100}"
        -rss_limit_mb="${FUZZ_RSS_MB:-2560}")
cd "$(dirname "$0")/.."
# Absolute paths: a target may chdir (fuzz_cli works in a scratch directory).
build=$(realpath "$build")

"$build/make_seeds" fixtures "$build/seeds" >/dev/null || exit 1
mkdir -p "$build/crashes"
failed=0
summary=""
for spec in "$@"; do
  read -r target options <<<"$spec"
  name=${target#fuzz_}
  corpus="$build/corpus/$name"
  mkdir -p "$corpus"
  log="$build/$target.log"
  # Inputs that once crashed must stay fixed.
  regressions=("$PWD"/fuzz/regressions/"$name"/*)
  if [ -e "${regressions[0]}" ]; then
    if ! "$build/$target" $options "${limits[@]}" -close_fd_mask=3 "${regressions[@]}" \
      >"$log" 2>&1; then
      echo "fuzz: $target: a saved regression input fails again (see $log)"
      failed=1
      continue
    fi
  fi
  before=$(find "$build/crashes" -name "$name-*" | sort)
  start=$(date +%s.%N)
  "$build/$target" $options -max_total_time="$seconds" -close_fd_mask=3 \
    "${limits[@]}" -print_final_stats=1 \
    -artifact_prefix="$build/crashes/$name-" "$corpus" "$build/seeds/$name" >"$log" 2>&1
  status=$?
  elapsed=$(echo "$(date +%s.%N) - $start" | bc)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  units=$(find "$corpus" -type f | wc -l)
  line=$(printf '%-16s %10s executions in %6.1f s, corpus %5d inputs' "$name" "${execs:-?}" "$elapsed" "$units")
  # Inputs libFuzzer saved although the target passed: slow units (over
  # -report_slow_units), or the report of a child process the target waited
  # for (the model loader's, whose failure the target takes as a refused
  # model). Named, so that a passing run's crashes/ is not read as failures.
  saved=$(comm -13 <(printf '%s\n' "$before") <(find "$build/crashes" -name "$name-*" | sort) |
    sed '/^$/d')
  if [ "$status" -ne 0 ]; then
    line="$line: FAILED (see $log)"
    failed=1
  elif [ -n "$saved" ]; then
    line="$line; saved without failing: $(echo "$saved" | xargs -n1 basename | paste -sd' ')"
  fi
  echo "$line"
  summary="$summary$line"$'\n'
done
printf '%s' "$summary" >"$build/summary.txt"
exit "$failed"
