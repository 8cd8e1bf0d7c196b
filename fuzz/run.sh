#!/usr/bin/env bash
# fuzz/run.sh: runs the libFuzzer targets `make fuzz` built.
#   fuzz/run.sh BUILD_DIR SECONDS "fuzz_NAME [libFuzzer options]" ...
# For each target: replays the saved crash inputs of fuzz/regressions/NAME,
# then fuzzes SECONDS seconds from build/fuzz/corpus/NAME (kept between runs)
# and the seeds make_seeds wrote from fixtures/, and prints executions and
# time per target. Exits 1 when a target crashed, leaked or hung; the input
# is saved in BUILD_DIR/crashes/.
set -uo pipefail
build=$1 seconds=$2
shift 2
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
    if ! "$build/$target" $options -close_fd_mask=3 "${regressions[@]}" >"$log" 2>&1; then
      echo "fuzz: $target: a saved regression input fails again (see $log)"
      failed=1
      continue
    fi
  fi
  start=$(date +%s.%N)
  # -rss_limit_mb: every read is bounded by 1 GiB of samples, plus the
  # sanitizers' own overhead; -timeout: no input may take this long.
  "$build/$target" $options -max_total_time="$seconds" -close_fd_mask=3 \
    -rss_limit_mb=3072 -timeout=30 -print_final_stats=1 \
    -artifact_prefix="$build/crashes/$name-" "$corpus" "$build/seeds/$name" >"$log" 2>&1
  status=$?
  elapsed=$(echo "$(date +%s.%N) - $start" | bc)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  units=$(find "$corpus" -type f | wc -l)
  line=$(printf '%-16s %10s executions in %6.1f s, corpus %5d inputs' "$name" "${execs:-?}" "$elapsed" "$units")
  if [ "$status" -ne 0 ]; then
    line="$line: FAILED (see $log)"
    failed=1
  fi
  echo "$line"
  summary="$summary$line"$'\n'
done
printf '%s' "$summary" >"$build/summary.txt"
exit "$failed"
