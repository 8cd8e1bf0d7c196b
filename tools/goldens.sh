#!/usr/bin/env bash
# goldens.sh: regenerate or check the golden bakes listed in fixtures/goldens/cases.txt.
#
#   tools/goldens.sh BIN regenerate   bake every case into fixtures/goldens/
#   tools/goldens.sh BIN check        run the golden test (tests/job/test_goldens.c),
#                                     which re-bakes and compares with tolerances
#
# Regenerate only on purpose (`make goldens`): a changed golden is a changed
# promise to users, so commit it with a message saying why the pixels moved.
set -euo pipefail

bin=${1:?usage: tools/goldens.sh BIN regenerate|check}
mode=${2:?usage: tools/goldens.sh BIN regenerate|check}
# Paths relative to the repository root, so the command lines recorded in
# the goldens' provenance do not name the machine they were baked on.
[[ $bin == */* ]] && bin=$(realpath "$bin")
cd "$(dirname "$0")/.."
fixtures=${BB_FIXTURES:-fixtures}
cases=$fixtures/goldens/cases.txt
golden_limit=$((1024 * 1024)) # bytes; goldens live in git, keep them small

trim() { local s=$1; s=${s#"${s%%[![:space:]]*}"}; printf '%s' "${s%"${s##*[![:space:]]}"}"; }

# Reads cases.txt into the parallel arrays names, inputs, commands, args, outputs.
names=() inputs=() commands=() args=() outputs=()
load_cases() {
  local line name input command arguments outs
  while IFS= read -r line || [[ -n $line ]]; do
    [[ $line =~ ^[[:space:]]*(#|$) ]] && continue
    IFS='|' read -r name input command arguments outs <<<"$line"
    names+=("$(trim "$name")") inputs+=("$(trim "$input")")
    commands+=("$(trim "$command")") args+=("$(trim "$arguments")")
    outputs+=("$(trim "$outs")")
    case ${commands[-1]} in
    bake | height2ssbump) ;;
    *) echo "goldens.sh: $cases: unknown subcommand '${commands[-1]}'" >&2; exit 2 ;;
    esac
  done <"$cases"
}

# Argument words of case i with IN replaced by the input path $2.
case_words() {
  local word out=()
  for word in ${args[$1]}; do
    [[ $word == IN ]] && out+=("$2") || out+=("$word")
  done
  printf '%s\n' "${out[@]}"
}

regenerate_bake() {
  local i=$1 dest=$2 kind flags=()
  mapfile -t words < <(case_words "$i" "$fixtures/${inputs[$i]}")
  for kind in ${outputs[$i]}; do flags+=("--$kind" "$dest/${names[$i]}_$kind.exr"); done
  "$bin" bake "${words[@]}" "${flags[@]}" --quiet
}

# height2ssbump writes next to its input, so it runs on a copy in a scratch
# directory with a fixed name (it is recorded in the provenance).
regenerate_height2ssbump() {
  local i=$1 dest=$2 tmp=build/goldens-scratch input stem
  rm -rf "$tmp" && mkdir -p "$tmp"
  input=$tmp/${inputs[$i]}
  cp "$fixtures/${inputs[$i]}" "$input"
  mapfile -t words < <(case_words "$i" "$input")
  "$bin" height2ssbump "${words[@]}" >/dev/null
  stem=${input%.*}
  mv "$stem-ssbump.tga" "$dest/${names[$i]}_ssbump.tga"
  rm -rf "$tmp"
}

regenerate() {
  local i start file size status=0
  # Goldens of cases no longer listed must not linger and look current.
  rm -f "$fixtures"/goldens/*.exr "$fixtures"/goldens/*.tga
  for i in "${!names[@]}"; do
    start=$(date +%s%N)
    "regenerate_${commands[$i]}" "$i" "$fixtures/goldens"
    printf '%-14s %6d ms\n' "${names[$i]}" $((($(date +%s%N) - start) / 1000000))
  done
  for file in "$fixtures"/goldens/*.exr "$fixtures"/goldens/*.tga; do
    size=$(stat -c %s "$file")
    printf '  %-36s %8d bytes\n' "${file#"$fixtures"/}" "$size"
    if ((size >= golden_limit)); then
      echo "goldens.sh: $file: $size bytes, over the $golden_limit limit" >&2
      status=1
    fi
  done
  return $status
}

check() {
  local tests
  tests=$(dirname "$bin")/bb_tests
  BB_BIN=$bin BB_FIXTURES=$fixtures "$tests" --filter 'goldens/*'
}

load_cases
case $mode in
regenerate) regenerate ;;
check) check ;;
*) echo "goldens.sh: unknown mode '$mode' (regenerate or check)" >&2; exit 2 ;;
esac
