#!/usr/bin/env bash
# bench.sh BIN: times bumpbake's trace and whole bake against brute force and the Embree
# peer, measures accuracy against converged references, and large sizes.
#
#   tools/bench.sh build/bumpbake        (make bench runs it after make all)
#
# Sections: 1 trace benchmark (build/tools/bench_trace), 2 the peer
# (valve-embree, built into build/peer/ from ../shared/peers/valve-embree),
# 3 full bake (periodic and --clamp; ao and ssbump at the peer's accuracy, its
# slice count derived on rock06 as section 5 measures), 4 ratios against the targets, 5 accuracy
# against converged references (the peer at 16384 rays, and bumpbake's own
# dense-azimuth reference, build/tools/accuracy_ref) on 256 x 256 maps, at
# 64, 256 and 1024 rays and at 6, 10 and 12 slices,
# 6 large sizes (rock06 tiled 4 x 4 and 8 x 8), 7 start-up
# (tools/bench_startup.sh: the CLI as built and linked to libbumpbake.so), 8 batches (tools/bench_batch.sh: 20 bakes of 256 x 256 in
# one process against one process each), 9 engine textures (tools/bench_blocks.sh:
# block compression's PSNR and worst error per format and map, bumpbake's codec
# against nvcompress, and the time of a 2048 x 2048 VTF DXT1 with mips against
# PNG), 10 inter-reflection (tools/bench_bounce.sh: bake --bounce against a
# path tracer and exact radiosity, and its cost), 11 a Dask cluster of this
# machine (tools/bench_cluster.sh batch big: 200 maps of 512 x 512 as a CLI
# batch, two half batches and bumpbake.dask.bake_files; one 8192 x 8192 map
# in one process and split over 2 workers; `make bench-cluster` runs it
# alone, with 16384 x 16384 too), 12 `bumpbake serve`'s save-to-pixels
# latency in headless Chromium against the cold bake + render pair
# (tools/bench_serve.py; again with saves of a 32 x 32 edit), 13 the loop
# before and after: an older build
# (BENCH_BEFORE=DIR, its build directory) and this one in turns, the
# stages of a bake, the writes, the kernel, a bounce's cost and the whole
# bake (tools/bench_loop.py; skipped without BENCH_BEFORE), 14 edit-local
# bakes (build/tools/bench_rebake: a 32 x 32 brush at five places of rock,
# the CPU of a bake through a keeping context against a whole bake, the
# same bits checked), then a summary table.
# Everything it writes goes into build/bench/.
#
# Timing rule: a measurement whose first run takes under 10 s is run 3 times
# and the median is reported, otherwise it is run once; each figure says
# which. bench_trace applies the same rule inside, to each part it times.
# The peer's 16384-ray references take minutes; they are kept in
# build/bench/accuracy/ and reused while newer than the peer and the map.
#
# Environment, for quick runs on small maps (defaults are the real bench):
#   BENCH_ROCK=PATH        rock height map (fixtures/rock06_height.png)
#   BENCH_LAVA=PATH        lava height map (lava01_height.png beside rock06)
#   BENCH_NOISE_SIZE=N     side of the genheight noise map (1024)
#   BENCH_SUBSET=N         texels of the per-texel march / brute-force subset (2000)
#   BENCH_PEER_DIR=DIR     valve-embree sources (../shared/peers/valve-embree)
#   BENCH_LARGE=0          skip section 6 (4096 and 8192 texels square)
#   BENCH_ACCURACY=0       skip section 5
#   BENCH_BLOCKS=0         skip section 9
#   BENCH_BOUNCE=0         skip section 10 (its path-traced references take
#                          many minutes the first time; BOUNCE_* as in
#                          tools/bench_bounce.sh)
#   BENCH_CLUSTER=0        skip section 11 (about 15 minutes and 3 GB of
#                          files in build/bench/cluster)
#   BENCH_SERVE=0          skip section 12
#   BENCH_BEFORE=DIR       an older build directory (with bumpbake and tools/)
#                          for section 13; BENCH_PAIRS=N its pairs (3)
#   BENCH_SECTIONS="9 10"  run only the sections listed (default: every one);
#                          the summary then has only their figures
#
# Exits 0 whatever the ratios and whether or not the peer could be built;
# exits 1 when bumpbake itself fails or its paths disagree on a horizon.
set -euo pipefail

bin=${1:?usage: tools/bench.sh path/to/bumpbake}
bin=$(realpath "$bin")
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
tools=$(dirname "$bin")/tools
out=build/bench
mkdir -p "$out"

rays=256 bias=0.55 threads=2 repeat_under=10
acc_size=256 acc_rock_scale=32 acc_noise_scale=16 acc_ref_rays=16384
rock_scale=128 noise_scale=64
noise_size=${BENCH_NOISE_SIZE:-1024}
subset=${BENCH_SUBSET:-2000}
target_trace=3 target_whole=20 target_peer_acc=25 target_brute=20
failures=() # bumpbake-side failures: they make the bench exit 1
peer_ok=0 peer_reason="not tried"
bake_ok=0 clamp_ok=0 startup_ok=0 batch_ok=0 blocks_ok=0 bounce_ok=0
ratio_rows=() acc_rows=() large_rows=()
acc=$out/accuracy peer_slices="" peer_slices_ok=0
start_all=$(date +%s.%N)

# ------------------------------------------------------------------ helpers

section() { printf '\n== %s ==\n' "$*"; }
# want N: section N is to run (BENCH_SECTIONS lists it, or is unset).
want() { [ -z "${BENCH_SECTIONS:-}" ] || [[ " $BENCH_SECTIONS " == *" $1 "* ]]; }
now() { date +%s.%N; }
fail() { failures+=("$*"); echo "bench: FAILED: $*" >&2; }

# json_num KEY FILE: the number stored under "KEY" in a one-line JSON file.
json_num() {
  local v
  v=$(sed -n "s/.*\"$1\":\(-\{0,1\}[0-9][0-9.eE+-]*\).*/\1/p" "$2" 2>/dev/null | head -n1) || true
  printf '%s' "${v:-nan}"
}

# median V...: the middle value (the lower middle for an even count).
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# calc EXPR [FORMAT]: awk arithmetic; "n/a" when a term is missing or a divisor is 0.
calc() {
  case $1 in *nan* | *n/a*) printf 'n/a'; return ;; esac
  # mawk prints nan and inf for 0/0 and 1/0 rather than failing
  awk -v f="${2:-%.3f}" "BEGIN { r = $1; if ((r \"\") ~ /nan|inf/) printf \"n/a\"; else printf f, r }" \
    2>/dev/null || printf 'n/a'
}

# ratio A B: A / B to 2 decimals, or n/a.
ratio() {
  awk -v a="$1" -v b="$2" 'BEGIN { if (a ~ /^[0-9.eE+-]+$/ && b ~ /^[0-9.eE+-]+$/ && b + 0 > 0)
    printf "%.2f", a / b; else printf "n/a" }'
}

# verdict VALUE TARGET: information only.
verdict() {
  awk -v v="$1" -v t="$2" 'BEGIN { if (v !~ /^[0-9.]+$/) print "-"; else if (v + 0 >= t + 0)
    print "meets"; else print "below" }'
}

# run_once NAME I CMD...: one run; stdout to NAME.I.out, stderr to NAME.I.err,
# wall seconds to NAME.I.wall, peak RSS (KiB) to NAME.I.rss.
run_once() {
  local name=$1 i=$2 t0 rc=0
  shift 2
  t0=$(now)
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f '%M' -o "$out/$name.$i.time" "$@" >"$out/$name.$i.out" \
      2>"$out/$name.$i.err" || rc=$?
    tail -n1 "$out/$name.$i.time" >"$out/$name.$i.rss"
  else
    "$@" >"$out/$name.$i.out" 2>"$out/$name.$i.err" || rc=$?
    echo nan >"$out/$name.$i.rss"
  fi
  calc "$(now) - $t0" '%.3f' >"$out/$name.$i.wall"
  return "$rc"
}

# measure NAME CMD...: runs CMD once, and twice more when that took under
# $repeat_under s; the number of runs goes to NAME.runs. Returns CMD's status.
measure() {
  local name=$1 rc=0
  shift
  rm -f "$out/$name".*
  run_once "$name" 1 "$@" || rc=$?
  local n=1
  if [ "$rc" = 0 ] && [ "$(calc "($(cat "$out/$name.1.wall") < $repeat_under)" %d)" = 1 ]; then
    run_once "$name" 2 "$@" || rc=$?
    [ "$rc" = 0 ] && { run_once "$name" 3 "$@" || rc=$?; }
    n=3
  fi
  echo "$n" >"$out/$name.runs"
  if [ "$rc" != 0 ]; then sed 's/^/  | /' "$out/$name".*.err | tail -n 5 >&2; fi
  return "$rc"
}

# med NAME KEY: median over NAME's runs of KEY in the JSON output, or of the
# wall / rss files when KEY is @wall / @rss.
med() {
  local name=$1 key=$2 n i vals=()
  n=$(cat "$out/$name.runs" 2>/dev/null || echo 0)
  [ "$n" -gt 0 ] || { printf 'n/a'; return; }
  for ((i = 1; i <= n; i++)); do
    case $key in
    @*) vals+=("$(cat "$out/$name.$i.${key#@}" 2>/dev/null || echo nan)") ;;
    *) vals+=("$(json_num "$key" "$out/$name.$i.out")") ;;
    esac
  done
  median "${vals[@]}"
}

# runs_text NAME: "median of 3" or "1 run".
runs_text() {
  local n
  n=$(cat "$out/$1.runs" 2>/dev/null || echo 0)
  if [ "$n" = 1 ]; then printf '1 run'; else printf 'median of %s' "$n"; fi
}

mib() { calc "$1 / 1024" '%.0f'; }

# ------------------------------------------------------------------- inputs

# acc_map NAME SRC: SRC downsampled to acc_size square as $acc/NAME.png (kept
# while newer than SRC), for the accuracy measurements.
acc_map() {
  mkdir -p "$acc"
  [ -f "$acc/$1.png" ] && [ "$acc/$1.png" -nt "$2" ] ||
    oiiotool "$2" --resize "${acc_size}x${acc_size}" -d uint16 -o "$acc/$1.png"
}

# find_fixture NAME [OVERRIDE]: fixtures/NAME, or the shared copy beside the
# checkout (or beside the worktrees), as demo.sh.
find_fixture() {
  local input=${2:-fixtures/$1} alt
  for alt in ../shared/fixtures ../../shared/fixtures; do
    [ -f "$input" ] || input=$alt/$1
  done
  [ -f "$input" ] || { echo "bench: $1 not found" >&2; return 1; }
  printf '%s' "$input"
}

rock=$(find_fixture rock06_height.png "${BENCH_ROCK:-}") || exit 1
lava=$(find_fixture lava01_height.png "${BENCH_LAVA:-}") || lava=""
noise=$out/noise${noise_size}.png
"$tools/genheight" noise "$noise_size" "$noise_size" "$noise"
maps=(rock noise)
declare -A map_path=([rock]=$rock [noise]=$noise)
declare -A map_scale=([rock]=$rock_scale [noise]=$noise_scale)

section "bumpbake bench"
echo "commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "machine: $(nproc) cores, $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1)," \
  "load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "maps: rock = $rock (scale $rock_scale), noise = $noise (genheight noise, scale $noise_scale)"
echo "rays $rays per texel ($(( $(printf '%.0f' "$(calc "sqrt($rays)" %.3f)") )) slices), bias $bias;" \
  "a figure is the median of 3 runs when a run takes under ${repeat_under} s, else 1 run"
[ -z "${BENCH_SECTIONS:-}" ] || echo "sections: $BENCH_SECTIONS (BENCH_SECTIONS)"

# ---------------------------------------------------------- 1. trace bench

# trace_bench MAP THREADS: runs bench_trace into trace_MAP_tTHREADS.json.
trace_bench() {
  local m=$1 t=$2 rc=0
  local json=$out/trace_${m}_t$t.json
  "$tools/bench_trace" "${map_path[$m]}" "${map_scale[$m]}" "$rays" "$t" --subset "$subset" \
    --bias "$bias" >"$json" || rc=$?
  [ "$rc" = 0 ] || fail "bench_trace ${map_path[$m]} with $t thread(s) exited $rc"
}

# trace_row MAP THREADS: one line of the trace table.
trace_row() {
  local j=$out/trace_${1}_t$2.json
  printf '%-6s %5s %4s %7s %-5s %9s %10s %9s %9s %8s %7s %9s %6s\n' "$1" \
    "$(json_num width "$j")" "$2" "$(calc "$(json_num trace_s "$j")")" \
    "($(json_num trace_runs "$j"))" "$(calc "$(json_num horizons_per_s "$j") / 1e6" %.2f)" \
    "$(calc "$(json_num horizons_per_s "$j") / 1e6 / $2" %.2f)" \
    "$(calc "$(json_num march_horizons_per_s "$j") / 1e6" %.3f)" \
    "$(calc "$(json_num brute_horizons_per_s "$j") / 1e6" %.3f)" \
    "$(calc "$(json_num trace_over_brute "$j")" %.0f)" \
    "$(calc "$(json_num positive_fraction "$j") * 100" %.1f)%" \
    "$(json_num disagreements "$j")/$(json_num region_mismatches "$j")" \
    "$(mib "$(json_num maxrss_kib "$j")")"
}

if want 1; then
section "1. Trace benchmark (build/tools/bench_trace)"
echo "bb__trace_occlusion (line sweeps) over every texel; then every slice's horizon at $subset texels"
echo "one at a time on 1 thread, by the max-mip march and by brute force, and each of those texels"
echo "traced alone as a one-texel region (marches), compared bit for bit with the whole trace."
for m in "${maps[@]}"; do
  for t in 1 "$threads"; do trace_bench "$m" "$t"; done
done
echo
printf '%-6s %5s %4s %7s %-5s %9s %10s %9s %9s %8s %7s %9s %6s\n' map size thr trace_s runs \
  Mhor/s Mhor/s/thr march_M/s brute_M/s tr/brute horizon diff/reg MiB
for m in "${maps[@]}"; do
  for t in 1 "$threads"; do trace_row "$m" "$t"; done
done
echo "(trace_s: median over 'runs' runs; Mhor/s = texels x slices / trace_s, Mhor/s/thr the same"
echo "per thread; tr/brute = trace"
echo "horizons/s over brute-force horizons/s; horizon = share of positive horizons; diff/reg ="
echo "march vs brute-force disagreements / region texels differing from the whole trace, both 0"
echo "when the paths agree; MiB = peak RSS of the process)"
fi # section 1

# ----------------------------------------------------------------- 2. peer

# The peer's sources: $BENCH_PEER_DIR when set, else shared/ beside the
# checkout (or beside the directory of worktrees).
find_peer_dir() {
  local d candidates=(../shared/peers/valve-embree ../../shared/peers/valve-embree)
  [ -z "${BENCH_PEER_DIR:-}" ] || candidates=("$BENCH_PEER_DIR")
  for d in "${candidates[@]}"; do
    [ -f "$d/valve-embree.cpp" ] && { (cd "$d" && pwd); return 0; }
  done
  return 1
}

have_embree() { printf '#include <embree3/rtcore.h>\n' | "${CXX:-g++}" -E -x c++ - >/dev/null 2>&1; }

# One attempt at installing Embree; sudo when not root (never waits for a
# password unless a terminal can answer).
install_embree() {
  local sudo=()
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || return 1
    if [ -t 0 ]; then sudo=(sudo); else sudo=(sudo -n); fi
  fi
  echo "peer: libembree-dev missing; trying apt-get install -y libembree-dev"
  ${sudo[@]+"${sudo[@]}"} env DEBIAN_FRONTEND=noninteractive apt-get install -y libembree-dev \
    >"$out/peer_install.log" 2>&1
}

# Builds the peer into build/peer/; sets peer, peer_ok and peer_reason.
build_peer() {
  local dir
  if ! dir=$(find_peer_dir); then
    peer_reason="sources not found (${BENCH_PEER_DIR:-../shared/peers/valve-embree beside the repository})"
    return
  fi
  peer=$root/build/peer/valve-embree
  local make_peer=(make -C "$dir" BUILD="$root/build/peer" "$peer")
  if ! have_embree && ! install_embree; then
    peer_reason="libembree-dev missing and apt-get install failed (see $out/peer_install.log)"
    return
  fi
  if "${make_peer[@]}" >"$out/peer_build.log" 2>&1; then
    peer_ok=1 peer_reason=""
    echo "peer: $dir -> build/peer/valve-embree"
  else
    peer_reason="build failed: $(grep -m1 -i error "$out/peer_build.log" || tail -n1 "$out/peer_build.log")"
  fi
}

# peer_run MAP: the peer's whole run on bumpbake's filtered MAP, its own ray
# set (Fibonacci, uniform in solid angle) of the same count.
peer_run() {
  local m=$1
  measure "peer_$m" "$peer" "$out/${m}_filtered.exr" --scale "${map_scale[$m]}" --rays "$rays" \
    --bias "$bias" --threads "$threads" \
    --ao "$out/${m}_peer_ao.exr" --ssbump "$out/${m}_peer_ssbump.exr"
}

# Filtered heights for the peer, which does not smooth.
make_filtered() {
  local m
  for m in "${maps[@]}"; do
    "$bin" bake "${map_path[$m]}" --scale "${map_scale[$m]}" -q \
      --filtered "$out/${m}_filtered.exr" || return 1
  done
}

peer_row() {
  local n=peer_$1
  printf '%-6s %9s %9s %9s %9s %7s  %s\n' "$1" "$(calc "$(med "$n" build_s)")" \
    "$(calc "$(med "$n" trace_s)")" "$(calc "$(med "$n" total_s)")" "$(calc "$(med "$n" @wall)")" \
    "$(mib "$(med "$n" @rss)")" "$(runs_text "$n")"
}

if want 2; then
section "2. Peer: valve-embree (Valve's method on Intel Embree 3)"
build_peer
if [ "$peer_ok" = 1 ]; then
  if ! make_filtered; then
    fail "bumpbake could not write the filtered heights for the peer"
    peer_ok=0 peer_reason="no filtered heights to give it"
  fi
fi
if [ "$peer_ok" = 1 ]; then
  echo "input: bumpbake's filtered height (bake --filtered, radius 10), since the peer does not"
  echo "smooth; $rays rays of its own set (uniform in solid angle); $threads threads"
  for m in "${maps[@]}"; do
    if ! peer_run "$m"; then
      peer_ok=0 peer_reason="the peer failed on ${m}_filtered.exr (see $out/peer_$m.1.err)"
      break
    fi
  done
fi
if [ "$peer_ok" = 1 ]; then
  printf '%-6s %9s %9s %9s %9s %7s  %s\n' map build_s trace_s total_s wall_s MiB runs
  for m in "${maps[@]}"; do peer_row "$m"; done
  echo "(build_s, trace_s, total_s from the peer's JSON; wall_s = the whole process)"
else
  echo "peer: not available ($peer_reason)"
fi
else
  peer_reason="section 2 not run (BENCH_SECTIONS)"
fi # section 2

# ------------------------------------------------------------ 3. full bake

if want 3; then
section "3. Full bake: bumpbake bake rock, every output, $threads threads"
# full_cmd ARRAY PREFIX [options]: sets ARRAY to the whole bake of rock, every
# output under PREFIX
full_cmd() {
  local -n cmd=$1
  local prefix=$2
  shift 2
  cmd=("$bin" bake "$rock" --scale "$rock_scale" --rays "$rays" --threads "$threads" --json -q
    --normal "${prefix}_normal.png" --weights "${prefix}_weights.png"
    --ssbump "${prefix}_ssbump.png" --ao "${prefix}_ao.png" --bent "${prefix}_bent.png" "$@")
}
# stage_row NAME LABEL: the medians of a measured bake, one row
stage_row() {
  local name=$1 k v stage_sum=0
  printf '%-10s' "$2"
  for k in load smooth pyramid trace derive write; do
    v=$(med "$name" "$k")
    stage_sum=$(calc "$stage_sum + $v" %.6f)
    printf '%-8s' "$(calc "$v")"
  done
  printf '%-8s%-8s%-8s\n' "$(calc "$stage_sum")" "$(calc "$(med "$name" @wall)")" \
    "$(mib "$(med "$name" @rss)")"
}
# acc_errors JSON: accuracy_ref's results as "NAME AO SS" lines: mean |error|
# of ao and the largest of the ssbump channels'.
acc_errors() {
  sed 's/.*"results":\[//; s/\]}$//; s/}\]},{/}]}\n{/g' "$1" | while IFS= read -r res; do
    printf '%s ' "$(printf '%s' "$res" | sed 's/.*"name":"\([^"]*\)".*/\1/')"
    printf '%s' "$res" | grep -o '"mean_abs":[^}]*' | sed 's/"mean_abs"://' |
      awk 'NR == 1 { ao = $1 } NR > 1 && (NR == 2 || $1 > ss) { ss = $1 } END { print ao, ss }'
  done
}
# derive_peer_slices: the peer's accuracy as a slice count, found as
# docs/accuracy.md "Error by slice count" finds it: rock06 at 256 x 256
# (section 5's map and settings), the peer at $rays rays and bumpbake at
# every count from 6 to 16 slices against the dense reference (accuracy_ref); the
# fewest slices whose mean |error| is at most the peer's for ao and for
# ssbump (each its largest channel's). Sets peer_slices and peer_slices_ok;
# kept in $acc/peer_slices.txt while newer than bumpbake, the peer, the map
# and this script (whose counts it holds).
derive_peer_slices() {
  local d=$acc/peer_slices m=rock compare=() n name ao ss pao pss
  command -v oiiotool >/dev/null && acc_map "$m" "$rock" || return 1
  local path=$acc/$m.png
  if ! { [ -f "$d.txt" ] && [ "$d.txt" -nt "$bin" ] && [ "$d.txt" -nt "$peer" ] &&
    [ "$d.txt" -nt "$path" ] && [ "$d.txt" -nt "$root/tools/bench.sh" ]; }; then
    mkdir -p "$d"
    "$peer" "$path" --scale "$acc_rock_scale" --rays "$rays" --bias "$bias" --threads "$threads" \
      --ao "$d/peer.ao.exr" --ssbump "$d/peer.ss.exr" >/dev/null 2>&1 || return 1
    compare=("peer=$d/peer.ao.exr,$d/peer.ss.exr")
    for n in $(seq 6 16); do
      "$bin" bake "$path" --scale "$acc_rock_scale" --slices "$n" --filter-radius 0 \
        --normal-filter valve --bias "$bias" --threads "$threads" -q --ao "$d/s$n.ao.exr" \
        --ssbump "$d/s$n.ss.exr" || return 1
      compare+=("$n=$d/s$n.ao.exr,$d/s$n.ss.exr")
    done
    "$tools/accuracy_ref" "$path" "$acc_rock_scale" --bias "$bias" "${compare[@]}" \
      >"$d.json" 2>/dev/null || return 1
    acc_errors "$d.json" >"$d.txt"
  fi
  read -r name pao pss < <(grep '^peer ' "$d.txt") || return 1
  echo "the peer's accuracy: rock06 at ${acc_size} x ${acc_size}, scale $acc_rock_scale, mean |error|" \
    "against the dense reference (ao, ssbump's largest channel; section 5's settings):"
  printf '  peer %s rays: %s %s\n' "$rays" "$(calc "$pao" %.5f)" "$(calc "$pss" %.5f)"
  while read -r name ao ss; do
    [ "$name" != peer ] || continue
    printf '  %2s slices:    %s %s\n' "$name" "$(calc "$ao" %.5f)" "$(calc "$ss" %.5f)"
    if [ -z "$peer_slices" ] && [ "$(calc "($ao <= $pao && $ss <= $pss)" %d)" = 1 ]; then
      peer_slices=$name
    fi
  done <"$d.txt"
  [ -n "$peer_slices" ] || { echo "  no slice count up to 16 reaches it"; return 1; }
  echo "  -> $peer_slices slices, the fewest at or below the peer on both"
  peer_slices_ok=1
}
full_cmd periodic_cmd "$out/rock"
full_cmd clamp_cmd "$out/rock_clamp" --clamp
echo "${periodic_cmd[*]#"$root/"}"
echo "(and the same with --clamp, outputs rock_clamp_*.png)"
bake_ok=1 clamp_ok=1
measure bake_rock "${periodic_cmd[@]}" || { fail "bumpbake bake exited non-zero"; bake_ok=0; }
measure bake_rock_clamp "${clamp_cmd[@]}" || { fail "bumpbake bake --clamp exited non-zero"; clamp_ok=0; }
printf '%-10s' ""
printf '%-8s' load smooth pyramid trace derive write stages wall MiB
echo
[ "$bake_ok" = 1 ] && stage_row bake_rock periodic
[ "$clamp_ok" = 1 ] && stage_row bake_rock_clamp --clamp
echo "($(runs_text bake_rock); seconds; stages = their sum, wall = the whole process)"
echo
if [ "$peer_ok" != 1 ]; then
  echo "the whole bake at the peer's accuracy: not measured, the peer is not available ($peer_reason)"
elif ! derive_peer_slices; then
  fail "the peer's accuracy in slices could not be derived (see $acc/peer_slices*)"
else
  # what the peer writes (ao and ssbump), at the slice count of its accuracy
  peer_acc_cmd=("$bin" bake "$rock" --scale "$rock_scale" --slices "$peer_slices" --threads "$threads"
    --json -q --ao "$out/rock_s${peer_slices}_ao.png" --ssbump "$out/rock_s${peer_slices}_ssbump.png")
  echo "${peer_acc_cmd[*]#"$root/"}"
  if measure bake_rock_peer_acc "${peer_acc_cmd[@]}"; then
    printf '%-10s' ""
    printf '%-8s' load smooth pyramid trace derive write stages wall MiB
    echo
    stage_row bake_rock_peer_acc "${peer_slices} slices"
    echo "($(runs_text bake_rock_peer_acc); ao and ssbump, the peer's outputs, at the peer's accuracy)"
  else
    fail "bumpbake bake --slices $peer_slices exited non-zero"
    peer_slices_ok=0
  fi
fi
if [ "$bake_ok" = 1 ]; then
  if [ "$peer_ok" = 1 ]; then
    echo "peer, whole run on the same map (filtered, so it does no smoothing):" \
      "wall $(calc "$(med peer_rock @wall)") s (build $(calc "$(med peer_rock build_s)")," \
      "trace $(calc "$(med peer_rock trace_s)"), total $(calc "$(med peer_rock total_s)");" \
      "$(runs_text peer_rock))"
  else
    echo "peer: not available ($peer_reason)"
  fi
fi
fi # section 3

# --------------------------------------------------------------- 4. ratios

if want 4; then
section "4. Ratios (information only; the bench passes whatever they are)"
# add_ratio NAME VALUE TARGET
add_ratio() { ratio_rows+=("$(printf '%-50s %8s   >= %-4s %s' "$1" "$2" "$3" "$(verdict "$2" "$3")")"); }
for m in "${maps[@]}"; do
  j=$out/trace_${m}_t$threads.json
  if [ "$peer_ok" = 1 ]; then
    add_ratio "peer trace_s / bumpbake trace_s, $m ($threads thr)" \
      "$(ratio "$(med "peer_$m" trace_s)" "$(json_num trace_s "$j")")" "$target_trace"
  fi
done
if [ "$peer_ok" = 1 ] && [ "$bake_ok" = 1 ]; then
  add_ratio "peer whole run / bumpbake whole bake, rock" \
    "$(ratio "$(med peer_rock @wall)" "$(med bake_rock @wall)")" "$target_whole"
fi
if [ "$peer_ok" = 1 ] && [ "$peer_slices_ok" = 1 ]; then
  add_ratio "peer whole run / bumpbake at its accuracy ($peer_slices sl)" \
    "$(ratio "$(med peer_rock @wall)" "$(med bake_rock_peer_acc @wall)")" "$target_peer_acc"
fi
for m in "${maps[@]}"; do
  for t in 1 "$threads"; do
    j=$out/trace_${m}_t$t.json
    add_ratio "trace horizons/s / brute-force horizons/s, $m ($t thr)" \
      "$(calc "$(json_num trace_over_brute "$j")" %.0f)" "$target_brute"
  done
done
printf '%-50s %8s   %-7s %s\n' ratio value target ""
printf '%s\n' "${ratio_rows[@]}"
[ "$peer_ok" = 1 ] || echo "peer: not available ($peer_reason); its ratios are left out"
echo "(brute force runs on 1 thread; the $threads-thread ratio includes the parallel speed-up)"
fi # section 4

# ------------------------------------------------------------- 5. accuracy

acc_ok=0

# acc_maps: the 256 x 256 maps, as NAME:PATH:SCALE words.
acc_maps() {
  local words=() m src
  for m in rock lava; do
    src=$rock
    [ "$m" = lava ] && src=$lava
    [ -n "$src" ] || continue
    acc_map "$m" "$src" || continue
    words+=("$m:$acc/$m.png:$acc_rock_scale")
  done
  "$tools/genheight" noise "$acc_size" "$acc_size" "$acc/noise.png" &&
    words+=("noise:$acc/noise.png:$acc_noise_scale")
  printf '%s\n' "${words[@]}"
}

# acc_stats RUN REFNAME AO SS REFAO REFSS: "|e| bias" of ao and each ssbump
# channel, from imgstats, as 8 numbers.
acc_stats() {
  local a s
  a=$("$tools/imgstats" "$1" "$3" 2>/dev/null) || return 1
  s=$("$tools/imgstats" "$2" "$4" 2>/dev/null) || return 1
  printf '%s\n%s\n' "$a" "$s" | sed 's/.*"channels":\[//; s/\]}$//; s/},{/}\n{/g' |
    sed 's/.*"mean":\([^,]*\),"mean_abs":\([^,]*\),.*/\2 \1/' | tr '\n' ' '
}

# acc_row MAP RUN REF NUMBERS...: one line of the accuracy table
acc_row() {
  local m=$1 r=$2 ref=$3
  shift 3
  local line
  line=$(printf '%-6s %-11s %-9s' "$m" "$r" "$ref")
  while [ $# -ge 2 ]; do
    line+=$(printf ' %8s %9s' "$(calc "$1" %.5f)" "$(calc "$2" %+.5f)")
    shift 2
  done
  acc_rows+=("$line")
  printf '%s\n' "$line"
}

want 5 && section "5. Accuracy against converged references (256 x 256 maps)"
if ! want 5; then
  :
elif [ "${BENCH_ACCURACY:-1}" = 0 ]; then
  echo "skipped (BENCH_ACCURACY=0)"
elif ! command -v oiiotool >/dev/null; then
  echo "skipped: oiiotool (openimageio-tools) is needed to downsample the maps"
else
  echo "rock06 and lava01 downsampled to ${acc_size} x ${acc_size} (oiiotool --resize) at scale" \
    "$acc_rock_scale, genheight noise at scale $acc_noise_scale; no smoothing (--filter-radius 0)," \
    "bias $bias, Valve's normal (--normal-filter valve) on both sides. References:"
  echo "  peer16k = the peer (Valve's method on Embree) with $acc_ref_rays uniform rays per texel;"
  echo "  dense   = build/tools/accuracy_ref: bb__ray_horizon in 2048 azimuths at every 4th texel"
  echo "            of every 4th row, integrated in elevation in closed form."
  echo "Each pair of columns is mean |error| and bias (signed mean of run - reference)."
  echo "bbN = bumpbake at N rays (64, 256, 1024: 8, 16, 32 slices), bb_sA = bumpbake at A slices."
  printf '%-6s %-11s %-9s' map run reference
  for c in ao ss0 ss1 ss2; do printf ' %8s %9s' "$c|e|" "bias"; done
  echo
  while IFS=: read -r m path scale; do
    [ -n "$m" ] || continue
    runs=()
    # rays 64, 256, 1024 (8, 16, 32 slices) and the slice counts between
    for setting in rays:64 rays:256 rays:1024 slices:6 slices:10 slices:12; do
      option=${setting%%:*} n=${setting#*:}
      r=bb$n
      [ "$option" = slices ] && r=bb_s$n
      "$bin" bake "$path" --scale "$scale" "--$option" "$n" --filter-radius 0 --normal-filter valve \
        --bias "$bias" --threads "$threads" -q --ao "$acc/${m}_$r.ao.exr" \
        --ssbump "$acc/${m}_$r.ss.exr" || { fail "bumpbake bake $path --$option $n"; continue; }
      runs+=("$r")
    done
    if [ "$peer_ok" = 1 ]; then
      "$peer" "$path" --scale "$scale" --rays 256 --bias "$bias" --threads "$threads" \
        --ao "$acc/${m}_peer256.ao.exr" --ssbump "$acc/${m}_peer256.ss.exr" >/dev/null 2>&1 &&
        runs+=(peer256)
      ref="$acc/${m}_peer16k"
      if ! { [ -f "$ref.ss.exr" ] && [ "$ref.ss.exr" -nt "$peer" ] && [ "$ref.ss.exr" -nt "$path" ]; }; then
        "$peer" "$path" --scale "$scale" --rays "$acc_ref_rays" --bias "$bias" --threads "$threads" \
          --ao "$ref.ao.exr" --ssbump "$ref.ss.exr" >"$acc/${m}_peer16k.json" 2>&1 ||
          rm -f "$ref.ao.exr" "$ref.ss.exr"
      fi
      if [ -f "$ref.ss.exr" ]; then
        for r in "${runs[@]}"; do
          nums=$(acc_stats "$acc/${m}_$r.ao.exr" "$acc/${m}_$r.ss.exr" "$ref.ao.exr" "$ref.ss.exr") &&
            acc_row "$m" "$r" peer16k $nums
        done
      fi
    fi
    compare=()
    for r in "${runs[@]}"; do compare+=("$r=$acc/${m}_$r.ao.exr,$acc/${m}_$r.ss.exr"); done
    [ -f "$acc/${m}_peer16k.ss.exr" ] && compare+=("peer16k=$acc/${m}_peer16k.ao.exr,$acc/${m}_peer16k.ss.exr")
    if "$tools/accuracy_ref" "$path" "$scale" --bias "$bias" "${compare[@]}" \
      >"$acc/${m}_dense.json" 2>/dev/null; then
      acc_ok=1
      while IFS= read -r res; do
        name=$(printf '%s' "$res" | sed 's/.*"name":"\([^"]*\)".*/\1/')
        nums=$(printf '%s' "$res" | grep -o '"mean":[^,]*,"mean_abs":[^}]*' |
          sed 's/"mean":\([^,]*\),"mean_abs":\(.*\)/\2 \1/' | tr '\n' ' ')
        acc_row "$m" "$name" dense $nums
      done < <(sed 's/.*"results":\[//; s/\]}$//; s/}\]},{/}]}\n{/g' "$acc/${m}_dense.json")
    else
      fail "accuracy_ref on $path"
    fi
  done < <(acc_maps)
fi

# ---------------------------------------------------------- 6. large sizes

# large_run NAME INPUT: a whole bake (ssbump and ao as PNG) of INPUT, once
large_run() {
  measure "large_$1" "$bin" bake "$2" --scale "$rock_scale" --rays "$rays" --threads "$threads" \
    --json -q --ssbump "$out/large_$1_ssbump.png" --ao "$out/large_$1_ao.png"
}

want 6 && section "6. Large sizes: rock06 tiled, ssbump and ao, $threads threads"
if ! want 6; then
  :
elif [ "${BENCH_LARGE:-1}" = 0 ]; then
  echo "skipped (BENCH_LARGE=0)"
elif ! command -v oiiotool >/dev/null; then
  echo "skipped: oiiotool (openimageio-tools) is needed to tile the map"
else
  echo "inputs: rock06 tiled n x n with oiiotool --mosaic into build/bench/ (kept, not committed)"
  printf '%-6s %7s %9s %11s %9s %11s %8s\n' size texels trace_s "trace_ns/tx" wall_s "wall_ns/tx" MiB
  for n in 1 4 8; do
    size=$((1024 * n)) input=$rock
    if [ "$n" != 1 ]; then
      input=$out/rock_${n}x$n.png
      if [ ! -f "$input" ] || [ "$input" -ot "$rock" ]; then
        dups=()
        for ((k = 1; k < n * n; k++)); do dups+=(--dup); done
        oiiotool "$rock" "${dups[@]}" --mosaic "${n}x$n" -o "$input" || { echo "tiling failed"; continue; }
      fi
    fi
    large_run "$size" "$input" || { fail "bumpbake bake of the ${size}^2 map"; continue; }
    texels=$((size * size))
    tr=$(med "large_$size" trace) wall=$(med "large_$size" @wall)
    line=$(printf '%-6s %7s %9s %11s %9s %11s %8s' "$size" "$((texels / 1048576))M" "$(calc "$tr")" \
      "$(calc "$tr * 1e9 / $texels" %.1f)" "$(calc "$wall")" "$(calc "$wall * 1e9 / $texels" %.1f)" \
      "$(mib "$(med "large_$size" @rss)")")
    large_rows+=("$line")
    printf '%s\n' "$line"
  done
  echo "(ns/tx = nanoseconds per texel; MiB = peak RSS; each size $(runs_text large_1024) or 1 run)"
fi

# ------------------------------------------------------------- 7. start-up

if want 7; then
section "7. Start-up: bumpbake --version, the CLI linked two ways"
echo "static: build/bumpbake as built (libbumpbake.a); shared: linked to libbumpbake.so. Neither"
echo "loads OpenImageIO for --version: the library loads it with its image module on the first"
echo "image read or write (the module names OpenImageIO's libraries first, tools/link_order.sh)."
startup_ok=0
startup_bins=(static="$bin")
for variant in shared; do
  b=$(dirname "$bin")/bench/bumpbake-$variant
  [ -x "$b" ] && startup_bins+=("$variant=$b")
done
if tools/bench_startup.sh -n 41 -i "${startup_bins[@]}" | tee "$out/startup.txt"; then
  startup_ok=1
else
  fail "tools/bench_startup.sh failed"
fi
# startup_field NAME COLUMN: a column of bench_startup's row for NAME.
startup_field() { awk -v n="$1" -v c="$2" '$1 == n { print $c }' "$out/startup.txt"; }
fi # section 7

# ------------------------------------------------------------- 8. batches

if want 8; then
section "8. Batches: 20 bakes of 256 x 256 in one process against one process each"
if tools/bench_batch.sh -n 20 -r 3 "$bin" | tee "$out/batch.txt"; then
  batch_ok=1
else
  fail "tools/bench_batch.sh failed"
fi
# batch_field LABEL_START COLUMN: a column (counted from the end) of bench_batch's row.
batch_field() { awk -v l="$1" -v c="$2" 'index($0, l) == 1 { print $(NF - c) }' "$out/batch.txt"; }
fi # section 8

# ------------------------------------------------------ 9. engine textures

# NVIDIA Texture Tools' nvcompress, the peer of section 9: one attempt at
# installing it, as install_embree.
install_nvtt() {
  local sudo=()
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || return 1
    if [ -t 0 ]; then sudo=(sudo); else sudo=(sudo -n); fi
  fi
  echo "blocks: nvcompress missing; trying apt-get install -y libnvtt-bin"
  ${sudo[@]+"${sudo[@]}"} env DEBIAN_FRONTEND=noninteractive apt-get install -y libnvtt-bin \
    >"$out/nvtt_install.log" 2>&1
}

if want 9; then
  section "9. Engine textures: block compression's quality and time (tools/bench_blocks.sh)"
  if [ "${BENCH_BLOCKS:-1}" != 0 ] && ! command -v nvcompress >/dev/null; then
    install_nvtt || echo "blocks: apt-get install libnvtt-bin failed (see $out/nvtt_install.log)"
  fi
  if [ "${BENCH_BLOCKS:-1}" = 0 ]; then
    echo "skipped (BENCH_BLOCKS=0)"
  elif tools/bench_blocks.sh "$bin" "$out/blocks" | tee "$out/blocks.txt"; then
    blocks_ok=1
  else
    fail "tools/bench_blocks.sh failed"
  fi
fi
# blocks_field PATTERN COLUMN: a column of the first line of bench_blocks' output matching PATTERN.
blocks_field() { awk -v p="$1" -v c="$2" '$0 ~ p { print $c; exit }' "$out/blocks.txt"; }

# ------------------------------------------------------ 10. inter-reflection

if want 10; then
  section "10. Inter-reflection: bake --bounce against a path tracer (tools/bench_bounce.sh)"
  if [ "${BENCH_BOUNCE:-1}" = 0 ]; then
    echo "skipped (BENCH_BOUNCE=0)"
  elif tools/bench_bounce.sh "$bin" | tee "$out/bounce.txt"; then
    bounce_ok=1
  else
    fail "tools/bench_bounce.sh failed"
  fi
fi

if want 11; then
  section "11. A Dask cluster of this machine (tools/bench_cluster.sh batch big)"
  if [ "${BENCH_CLUSTER:-1}" = 0 ]; then
    echo "skipped (BENCH_CLUSTER=0)"
  elif ! tools/bench_cluster.sh batch big "$bin" | tee "$out/cluster.txt"; then
    fail "tools/bench_cluster.sh failed"
  fi
fi

if want 12; then
  section "12. bumpbake serve: save-to-pixels in headless Chromium (tools/bench_serve.py)"
  if [ "${BENCH_SERVE:-1}" = 0 ]; then
    echo "skipped (BENCH_SERVE=0)"
  elif ! /usr/bin/python3 tools/bench_serve.py "$bin" | tee "$out/serve.txt"; then
    fail "tools/bench_serve.py failed"
  elif ! /usr/bin/python3 tools/bench_serve.py "$bin" --edit 32 | tee "$out/serve_edit.txt"; then
    fail "tools/bench_serve.py --edit 32 failed"
  fi
fi

if want 14; then
  section "14. Edit-local bakes: a 32 x 32 brush on rock, against whole bakes (build/tools/bench_rebake)"
  for at in 496,496 300,700 800,200 100,100 600,900; do
    if ! "$(dirname "$bin")/tools/bench_rebake" "$rock" 64 --runs 5 --threads "$threads" --at "$at" \
      >> "$out/rebake.json"; then
      fail "bench_rebake differs from the whole bake (or failed) at $at"
    fi
  done
fi

if want 13; then
  section "13. The loop, before and after (tools/bench_loop.py, BENCH_BEFORE)"
  if [ -z "${BENCH_BEFORE:-}" ]; then
    echo "skipped: BENCH_BEFORE names no older build to compare with"
  elif ! /usr/bin/python3 tools/bench_loop.py "$BENCH_BEFORE" "$(dirname "$bin")" \
    --pairs "${BENCH_PAIRS:-3}" --rock "$rock" | tee "$out/loop.txt"; then
    fail "tools/bench_loop.py failed"
  fi
fi

# -------------------------------------------------------------- summary

summary_row() { printf '%-46s %14s  %s\n' "$1" "$2" "${3:-}"; }

section "Summary"
summary_row figure value note
for m in "${maps[@]}"; do
  want 1 || continue
  for t in 1 "$threads"; do
    j=$out/trace_${m}_t$t.json
    summary_row "bumpbake trace, $m, $t thr (s)" "$(calc "$(json_num trace_s "$j")")" \
      "$(calc "$(json_num horizons_per_s "$j") / 1e6" %.1f) M horizons/s ($(calc "$(json_num horizons_per_s "$j") / 1e6 / $t" %.1f) a thread), runs $(json_num trace_runs "$j")"
  done
  j=$out/trace_${m}_t1.json
  summary_row "brute force, $m, 1 thr (M horizons/s)" \
    "$(calc "$(json_num brute_horizons_per_s "$j") / 1e6" %.3f)" \
    "march $(calc "$(json_num march_horizons_per_s "$j") / 1e6" %.3f) M/s, $(json_num disagreements "$j") disagreements"
  if [ "$peer_ok" = 1 ]; then
    summary_row "peer trace, $m, $threads thr (s)" "$(calc "$(med "peer_$m" trace_s)")" \
      "build $(calc "$(med "peer_$m" build_s)") s, $(runs_text "peer_$m")"
  fi
done
if [ "$bake_ok" = 1 ]; then
  summary_row "bumpbake whole bake, rock (s)" "$(calc "$(med bake_rock @wall)")" \
    "$(runs_text bake_rock), peak $(mib "$(med bake_rock @rss)") MiB"
fi
if [ "$clamp_ok" = 1 ]; then
  summary_row "bumpbake whole bake, rock, --clamp (s)" "$(calc "$(med bake_rock_clamp @wall)")" \
    "$(runs_text bake_rock_clamp), trace $(calc "$(med bake_rock_clamp trace)") s"
fi
if [ "$peer_slices_ok" = 1 ]; then
  summary_row "bumpbake at the peer's accuracy, rock (s)" "$(calc "$(med bake_rock_peer_acc @wall)")" \
    "$peer_slices slices, ao + ssbump, $(runs_text bake_rock_peer_acc)"
fi
if [ "$peer_ok" = 1 ]; then
  summary_row "peer whole run, rock (s)" "$(calc "$(med peer_rock @wall)")" \
    "$(runs_text peer_rock), peak $(mib "$(med peer_rock @rss)") MiB"
elif want 2; then
  summary_row "peer" "not available" "$peer_reason"
fi
if [ "$startup_ok" = 1 ]; then
  for variant in static shared; do
    [ -n "$(startup_field "$variant" 2)" ] || continue
    summary_row "start-up, $variant (s)" "$(startup_field "$variant" 2)" \
      "x$(startup_field "$variant" 5) of static; $(startup_field "$variant" 6) M instructions"
  done
fi
if [ "$batch_ok" = 1 ]; then
  summary_row "bake per 256^2 file, one process each (s)" "$(batch_field "one process per file" 1)"
  summary_row "bake per 256^2 file, in one batch (s)" "$(batch_field "one batch process" 1)" \
    "x$(batch_field "one batch process" 0) of one process each"
  summary_row "batch per file, all up to date (s)" "$(batch_field "batch, all up to date" 1)" \
    "x$(batch_field "batch, all up to date" 0)"
fi
if [ "$blocks_ok" = 1 ]; then
  summary_row "ssbump VTF DXT1, rock06 1024 (PSNR dB)" \
    "$(blocks_field '^bumpbake +ssbump +vtf bc1' 6)" \
    "worst $(blocks_field '^bumpbake +ssbump +vtf bc1' 8) codes of 255"
  summary_row "normal DDS BC5, rock06 1024 (PSNR dB)" \
    "$(blocks_field '^bumpbake +normal +dds bc5' 6)" \
    "mean angle $(blocks_field '^bumpbake +normal +dds bc5' 12) deg"
  for size in 1024 2048; do
    summary_row "${size}^2 ssbump: VTF DXT1 + mips, $threads thr (s)" \
      "$(blocks_field "^$size +vtf --threads 2 " 5)" \
      "DDS BC1 $(blocks_field "^$size +dds --threads 2 " 5) s; PNG $(blocks_field "^$size +png " 3) s; quick fit $(blocks_field "^$size +vtf --fast" 6) s"
  done
  for f in png exr-float exr-half vtf dds; do
    summary_row "bake's write stage, $f (x the stages)" "$(blocks_field "^$f: " 6)" \
      "write $(blocks_field "^$f: " 3) s, trace $(blocks_field "^$f: " 2) s"
  done
fi
if [ "$bounce_ok" = 1 ]; then
  # "  trench, converged: added A, exact E (+D)"
  summary_row "bounce: light added on the trench floor" \
    "$(awk '/trench, converged:/ { sub(",", "", $4); print $4; exit }' "$out/bounce.txt")" \
    "exact $(awk '/trench, converged:/ { print $6; exit }' "$out/bounce.txt"); accuracy in section 10"
  # "rock06 512 (scale 64)   1.00s   2.00s   2.0x   2"
  summary_row "bounce: --bounce 0.5 over a bake, rock06 512" \
    "$(awk '/^rock06 512 / { print $7; exit }' "$out/bounce.txt")" \
    "rivet panel 512: $(awk '/^rivet panel 512 / { print $8; exit }' "$out/bounce.txt"); goal under 3x"
fi
if [ "${#acc_rows[@]}" -gt 0 ]; then
  echo
  printf '%-6s %-11s %-9s' map run reference
  for c in ao ss0 ss1 ss2; do printf ' %8s %9s' "$c|e|" "bias"; done
  echo
  printf '%s\n' "${acc_rows[@]}"
fi
if [ "${#large_rows[@]}" -gt 0 ]; then
  echo
  printf '%-6s %7s %9s %11s %9s %11s %8s\n' size texels trace_s "trace_ns/tx" wall_s "wall_ns/tx" MiB
  printf '%s\n' "${large_rows[@]}"
fi
if [ "${#ratio_rows[@]}" -gt 0 ]; then
  echo
  printf '%-50s %8s   %-7s %s\n' ratio value target ""
  printf '%s\n' "${ratio_rows[@]}"
fi
echo "bench took $(calc "$(now) - $start_all" %.0f) s; outputs in $out/"

if [ "${#failures[@]}" -gt 0 ]; then
  printf 'bench: FAILED: %s\n' "${failures[@]}" >&2
  exit 1
fi
exit 0
