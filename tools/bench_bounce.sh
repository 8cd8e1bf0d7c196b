#!/usr/bin/env bash
# bench_bounce.sh BIN: the bake's inter-reflection (bake --bounce) against
# the path tracer tools/bounce_ref, the trench's exact radiosity, and what
# the bounce costs in time.
#
#   tools/bench_bounce.sh build/bumpbake     (after make all build/bb_tests)
#
# Sections:
# 1. Accuracy (docs/accuracy.md "Inter-reflection"): rock06 and lava01 downsampled to 256 x 256
#    (oiiotool --resize, as tools/bench.sh section 5) at scale 32 and
#    genheight noise at scale 16, no smoothing, Valve's normal, bias 0.55,
#    256 rays; rho 0.3 and 0.6, bounces to convergence (the default). The
#    reference: build/tools/bounce_ref with 65536 paths at every 8th texel
#    of every 8th row (1024 texels), kept in build/bench/bounce/ and reused
#    while newer than the map and tools/bounce_ref.c. Rows: "bumpbake", the bake at
#    its defaults (build/tools/bounce_bake, which calls bb__bake_checked as `bake
#    --bounce RHO` does); "horizon-pt", the same bake with the whole blocked
#    band of each slice seeing the horizon's own point (the approximation the
#    sweeps give for free); "no-bounce", the bake without it; "coarse-2",
#    the bounce on the coarse level of every other vertex (--level 2, what
#    a map of 512 to 2048 texels gets) on these 256 maps. Each pair of
#    columns is mean |error| and bias (signed mean of bake - reference) of
#    ao and each ssbump channel; the reference's own standard error per
#    texel is printed above each map's rows (it adds to mean |error|).
# 2. The trench (tests/bake/test_bounce.c): the light the bounce adds to ao
#    on a trench's floor, against the exact 2D radiosity of its walls and
#    floor (Hottel's crossed strings), rho 0.5, 1024 rays, one bounce and to
#    convergence; then the wall case, walls 8, 32 and 64 high. Read from the
#    tests' own logs (build/bb_tests).
# 3. Time: the whole bake with and without --bounce 0.5, and the ratio of
#    the two (a bounce's cost over a bake's), 2 threads: the 256 x 256 maps
#    (medians of 3); rock06 at 512 x 512 (scale 64) and the rivet panel's
#    height (renderbumpflat of fixtures/rivet_panel.obj, tiled, at its own
#    scale) at 256 and 512 (medians of 3); rock06 1024 x 1024 at scale 128
#    (1 run; BOUNCE_LARGE=0 skips it).
# 4. CPU by size: `bumpbake bake --ao --ssbump` on rock06 resized to 256,
#    512, 1024 and 2048 (BOUNCE_SIZES) at scale size/16, with and without
#    --bounce 0.5, 2 threads, CPU seconds (user + system), medians of 3; the
#    ratio (goal: at most 3, not growing with size) and the bounce's CPU
#    per texel and slice.
#
# Environment: BOUNCE_PATHS (65536), BOUNCE_STRIDE (8), BOUNCE_LARGE (1),
# BOUNCE_SIZES ("256 512 1024 2048").
# Everything it writes goes into build/bench/bounce/. Exits 1 when a step
# fails, 0 otherwise (whatever the figures).
set -euo pipefail

bin=${1:?usage: tools/bench_bounce.sh path/to/bumpbake}
bin=$(realpath "$bin")
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
tools=$(dirname "$bin")/tools
tests=$(dirname "$bin")/bb_tests
out=build/bench/bounce
mkdir -p "$out"
paths=${BOUNCE_PATHS:-65536}
stride=${BOUNCE_STRIDE:-8}
bias=0.55 threads=2 size=256
status=0

fail() { echo "bench_bounce: FAILED: $*" >&2; status=1; }
section() { printf '\n== %s ==\n' "$*"; }

find_fixture() {
  local input=fixtures/$1 alt
  for alt in ../shared/fixtures ../../shared/fixtures; do
    [ -f "$input" ] || input=$alt/$1
  done
  [ -f "$input" ] || return 1
  printf '%s' "$input"
}

# maps: NAME:PATH:SCALE words, the 256 x 256 maps of tools/bench.sh section 5.
maps() {
  local m src
  for m in rock lava; do
    src=$(find_fixture "$([ $m = rock ] && echo rock06_height.png || echo lava01_height.png)") ||
      continue
    [ -f "$out/$m.png" ] && [ "$out/$m.png" -nt "$src" ] ||
      oiiotool "$src" --resize "${size}x${size}" -d uint16 -o "$out/$m.png" || continue
    echo "$m:$out/$m.png:32"
  done
  [ -f "$out/noise.png" ] || "$tools/genheight" noise "$size" "$size" "$out/noise.png"
  echo "noise:$out/noise.png:16"
}

# numbers JSON NAME: "mean_abs mean" of each channel of one result of compare.
numbers() {
  grep -o "\"name\":\"$2\",\"channels\":\[[^]]*\]" "$1" | grep -o '"mean":[^,]*,"mean_abs":[^}]*' |
    sed 's/"mean":\([^,]*\),"mean_abs":\(.*\)/\2 \1/' | tr '\n' ' '
}

row() {
  local line
  line=$(printf '%-6s %-4s %-11s' "$1" "$2" "$3")
  shift 3
  while [ $# -ge 2 ]; do
    line+=$(awk -v a="$1" -v b="$2" 'BEGIN { printf " %8.5f %+9.5f", a, b }')
    shift 2
  done
  printf '%s\n' "$line"
}

section "bumpbake bounce bench"
echo "commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u '+%Y-%m-%d %H:%M UTC')," \
  "$(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"

section "1. Inter-reflection against the path tracer (256 x 256 maps, default settings)"
command -v oiiotool >/dev/null || echo "note: oiiotool (openimageio-tools) is needed for rock and lava"
echo "reference: build/tools/bounce_ref, $paths paths per texel at every ${stride}th texel of every ${stride}th row;"
echo "bakes: 256 rays, bias $bias, no smoothing, Valve's normal; each pair of columns mean |error| and bias"
printf '%-6s %-4s %-11s' map rho run
for c in ao ss0 ss1 ss2; do printf ' %8s %9s' "$c|e|" bias; done
echo
while IFS=: read -r m path scale; do
  [ -n "$m" ] || continue
  for rho in 0.3 0.6; do
    ref=$out/ref_${m}_$rho.exr
    if ! { [ -f "$ref" ] && [ "$ref" -nt "$path" ] && [ "$ref" -nt tools/bounce_ref.c ]; }; then
      "$tools/bounce_ref" trace "$path" "$scale" -o "$ref" --rho "$rho" --paths "$paths" \
        --stride "$stride" --bias "$bias" --threads "$threads" >"$out/ref_${m}_$rho.json" \
        2>"$out/ref_${m}_$rho.log" || { fail "bounce_ref on $path"; continue; }
    fi
    common=(--rays 256 --bias "$bias" --threads "$threads")
    "$tools/bounce_bake" "$path" "$scale" "$out/${m}_${rho}_bb" --rho "$rho" "${common[@]}" \
      >"$out/${m}_${rho}_bb.json" || { fail "bounce_bake $path"; continue; }
    "$tools/bounce_bake" "$path" "$scale" "$out/${m}_${rho}_hp" --rho "$rho" "${common[@]}" \
      --small-band 1e6 --steep 0 >"$out/${m}_${rho}_hp.json" || { fail "bounce_bake $path"; continue; }
    "$tools/bounce_bake" "$path" "$scale" "$out/${m}_${rho}_none" --rho 0 "${common[@]}" \
      >/dev/null || { fail "bounce_bake $path"; continue; }
    "$tools/bounce_bake" "$path" "$scale" "$out/${m}_${rho}_c2" --rho "$rho" "${common[@]}" \
      --level 2 >/dev/null || { fail "bounce_bake $path"; continue; }
    if "$tools/bounce_ref" compare "$ref" "$path" "$scale" \
      "bb=$out/${m}_${rho}_bb.ao.exr,$out/${m}_${rho}_bb.ss.exr" \
      "hp=$out/${m}_${rho}_hp.ao.exr,$out/${m}_${rho}_hp.ss.exr" \
      "none=$out/${m}_${rho}_none.ao.exr,$out/${m}_${rho}_none.ss.exr" \
      "c2=$out/${m}_${rho}_c2.ao.exr,$out/${m}_${rho}_c2.ss.exr" \
      >"$out/cmp_${m}_$rho.json" 2>/dev/null; then
      se=$(grep -o '"reference_se":\[[^]]*\]' "$out/cmp_${m}_$rho.json" | grep -o '"texel":[^,]*' |
        sed 's/"texel"://' | tr '\n' ' ')
      echo "  ($m, rho $rho: reference standard error per texel, ao ss0 ss1 ss2: $se)"
      row "$m" "$rho" bumpbake $(numbers "$out/cmp_${m}_$rho.json" bb)
      row "$m" "$rho" horizon-pt $(numbers "$out/cmp_${m}_$rho.json" hp)
      row "$m" "$rho" no-bounce $(numbers "$out/cmp_${m}_$rho.json" none)
      row "$m" "$rho" coarse-2 $(numbers "$out/cmp_${m}_$rho.json" c2)
    else
      fail "bounce_ref compare on $path"
    fi
  done
done < <(maps)

section "2. The trench: the light added to ao against its exact 2D radiosity (rho 0.5, 1024 rays)"
if [ -x "$tests" ]; then
  if BB_BIN="$bin" BB_FIXTURES=fixtures "$tests" --filter 'bounce/trench*' --verbose \
    >"$out/trench.log" 2>&1; then
    grep -o 'trench, [^:]*: added [0-9.]*, exact [0-9.]* ([+-][0-9.]*)' "$out/trench.log" |
      sed 's/^/  /'
    echo "  (floor 19 texels wide between walls 8 high, clamp mode, bias $bias; the test holds 0.002)"
    BB_BIN="$bin" BB_FIXTURES=fixtures "$tests" --filter 'bounce/deep*' --verbose \
      >"$out/wall.log" 2>&1 || fail "the wall case's test"
    grep -o 'wall [0-9.]* high, x [0-9]*: added [^)]*)' "$out/wall.log" | sed 's/^/  /'
    echo "  (the wall case: the same trench with walls 8, 32 and 64 high rising within one texel," \
      "converged; x 10 the floor's centre, x 2 one texel from a wall's foot)"
  else
    sed 's/^/  | /' "$out/trench.log" | tail -n 5
    fail "the trench test"
  fi
else
  echo "skipped: $tests not built (make build/bb_tests)"
fi

section "3. Time: the whole bake with and without --bounce 0.5 (2 threads)"
printf '%-24s %10s %10s %10s %8s\n' map without with ratio passes
time_row() { # NAME PATH SCALE RUNS
  local name=$1 path=$2 scale=$3 runs=$4 i w=() b=() t0 n=0
  for ((i = 0; i < runs; i++)); do
    t0=$(date +%s.%N)
    "$tools/bounce_bake" "$path" "$scale" "$out/time" --rho 0 --filter-radius 10 \
      --normal-filter vertex --threads "$threads" >/dev/null || return 1
    w+=("$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')")
    t0=$(date +%s.%N)
    "$tools/bounce_bake" "$path" "$scale" "$out/time" --rho 0.5 --filter-radius 10 \
      --normal-filter vertex --threads "$threads" >"$out/time.json" || return 1
    b+=("$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')")
    n=$(sed 's/.*"bounces":\([0-9]*\).*/\1/' "$out/time.json")
  done
  local mw mb
  mw=$(printf '%s\n' "${w[@]}" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
  mb=$(printf '%s\n' "${b[@]}" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
  awk -v n="$name" -v a="$mw" -v b="$mb" -v k="$n" \
    'BEGIN { printf "%-24s %9.2fs %9.2fs %9.1fx %8d\n", n, a, b, b / a, k }'
}
while IFS=: read -r m path scale; do
  [ -n "$m" ] || continue
  time_row "$m 256 (scale $scale)" "$path" "$scale" 3 || fail "timing $m"
done < <(maps)
if rock=$(find_fixture rock06_height.png); then
  [ -f "$out/rock512.png" ] && [ "$out/rock512.png" -nt "$rock" ] ||
    oiiotool "$rock" --resize 512x512 -d uint16 -o "$out/rock512.png" || true
  [ -f "$out/rock512.png" ] && { time_row "rock06 512 (scale 64)" "$out/rock512.png" 64 3 ||
    fail "timing rock06 512"; }
fi
for n in 256 512; do
  report=$("$bin" renderbumpflat -size "$n" "$n" fixtures/rivet_panel.obj --rect 0 0 1 1 --tile \
    -o "$out/rivet$n.tga" --height "$out/rivet$n.png" 2>&1) || { fail "renderbumpflat $n"; continue; }
  scale=$(printf '%s\n' "$report" | sed -n 's/^height scale \([^ ]*\) .*/\1/p')
  time_row "rivet panel $n (scale $scale)" "$out/rivet$n.png" "$scale" 3 || fail "timing rivet $n"
done
if [ "${BOUNCE_LARGE:-1}" != 0 ]; then
  rock=$(find_fixture rock06_height.png) &&
    { time_row "rock06 1024 (scale 128)" "$rock" 128 1 || fail "timing rock06"; }
fi
echo "(ratio: with over without, a bounce's cost over a bake's; passes: of the bounce, 2 when" \
  "converged; the bake's defaults otherwise: smoothing radius 10, the vertex normal, 256 rays;" \
  "medians of 3 runs, 1 run on 1024 x 1024)"

section "4. CPU by size: bake --ao --ssbump with and without --bounce 0.5 (rock06, scale size/16)"
# The issue's measure: CPU seconds (user + system) of the whole command,
# medians of 3 runs taken in turns; the bounce's CPU per texel and slice
# (16 slices) is (with - without) / (size^2 16).
printf '%-6s %10s %10s %8s %16s
' size without with ratio "bounce ns/texel/slice"
cpu_of() { # prints the CPU seconds of one run of "$@"
  /usr/bin/time -o "$out/cpu.txt" -f '%U %S' "$@" >/dev/null 2>&1 || return 1
  awk '{ print $1 + $2 }' "$out/cpu.txt"
}
if rock=$(find_fixture rock06_height.png); then
  for n in ${BOUNCE_SIZES:-256 512 1024 2048}; do
    map=$out/rock_size$n.png
    [ -f "$map" ] && [ "$map" -nt "$rock" ] ||
      oiiotool "$rock" --resize "${n}x$n" -d uint16 -o "$map" || { fail "resize $n"; continue; }
    w=() b=()
    for i in 1 2 3; do
      cmd=("$bin" bake "$map" --scale $((n / 16)) --ao "$out/size_ao.png" --ssbump "$out/size_ss.png"
        --threads "$threads" -q)
      w+=("$(cpu_of "${cmd[@]}")") || { fail "bake $n"; continue 2; }
      b+=("$(cpu_of "${cmd[@]}" --bounce 0.5)") || { fail "bake --bounce $n"; continue 2; }
    done
    mw=$(printf '%s\n' "${w[@]}" | sort -g | sed -n 2p)
    mb=$(printf '%s\n' "${b[@]}" | sort -g | sed -n 2p)
    awk -v n="$n" -v a="$mw" -v b="$mb" 'BEGIN {
      printf "%-6s %9.2fs %9.2fs %7.2fx %16.0f\n", n, a, b, b / a, (b - a) / (n * n * 16) * 1e9 }'
  done
fi
exit "$status"
