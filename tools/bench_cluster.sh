#!/usr/bin/env bash
# bench_cluster.sh [-n FILES] [-r ROUNDS] [SECTION...] BIN: bumpbake on a Dask
# cluster of this machine (a LocalCluster of 2 worker processes of one
# thread each) against one process, for docs/cluster.md.
#
#   tools/bench_cluster.sh build/bumpbake                 every section
#   tools/bench_cluster.sh batch build/bumpbake           the batch alone
#
# Sections:
#   batch  FILES (default 200) maps of 512 x 512 (genheight noise, seeds
#          0..FILES-1), scale 64, bake's default maps, three ways in turn,
#          ROUNDS times (default 3: A B C A B C ...): the CLI batch (`bake
#          DIR --out-dir OUT --force`, one process, 2 threads a bake); two
#          CLI batches side by side, each half the files on one thread (the
#          cluster's split of the work, without the engine); and
#          bumpbake.dask.bake_files on the cluster. Maps per second of each
#          (medians) and the engine's overhead against both; the cluster's
#          start-up and a re-run (all up to date) apart.
#          The last round's files are compared (cmp) with the CLI batch's.
#   big    rock06 resized to 8192 x 8192 (oiiotool), ssbump and ao: one
#          process (2 threads) and bumpbake.dask.bake_big on the cluster;
#          seconds, peak memory of each process, bytes moved; the files of
#          both compared byte for byte.
#   huge   rock06 resized to 16384 x 16384, ssbump and ao, one process:
#          seconds and peak memory.
# Every figure is printed with the load average when it was taken (the
# machine is shared). Work files go to build/bench/cluster/ (about 3 GB).
# Needs python3-distributed, oiiotool (openimageio-tools), /usr/bin/time.
set -euo pipefail

files=200 rounds=3 sections=()
while [ $# -gt 1 ]; do
  case $1 in
  -n) files=$2; shift 2 ;;
  -r) rounds=$2; shift 2 ;;
  batch | big | huge) sections+=("$1"); shift ;;
  *) break ;;
  esac
done
[ ${#sections[@]} -gt 0 ] || sections=(batch big huge)
bin=$(realpath "${1:?usage: tools/bench_cluster.sh [-n FILES] [-r ROUNDS] [batch|big|huge]... BIN}")
build=$(dirname "$bin")
root=$(cd "$(dirname "$0")/.." && pwd)
work=$root/build/bench/cluster
mkdir -p "$work"
python=${PYTHON:-/usr/bin/python3}
export PYTHONPATH=$root/python${PYTHONPATH:+:$PYTHONPATH}
export BUMPBAKE_LIBRARY=${BUMPBAKE_LIBRARY:-$build/libbumpbake.so.0.5}
helper=$root/tools/bench_cluster.py

load() { cut -d' ' -f1-3 /proc/loadavg; }
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
# peak resident KiB and seconds of a command: "KIB SECONDS"
timed() { /usr/bin/time -f '%M %e' -o "$work/time.txt" "$@" >/dev/null && cat "$work/time.txt"; }

echo "bench_cluster: $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $(grep MemTotal /proc/meminfo | awk '{printf "%.1f GiB", $2 / 1048576}'), commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"

for section in "${sections[@]}"; do
  case $section in
  batch)
    mkdir -p "$work/in512-$files"
    for ((i = 0; i < files; i++)); do
      f=$work/in512-$files/h$(printf %03d "$i").png
      [ -f "$f" ] || "$build/tools/genheight" noise 512 512 "$f" --seed "$i" >/dev/null
    done
    mapfile -t all < <(ls "$work/in512-$files"/*.png)
    even=() odd=()
    for ((i = 0; i < ${#all[@]}; i++)); do
      if ((i % 2)); then odd+=("${all[i]}"); else even+=("${all[i]}"); fi
    done
    cli=() halves=() dask=() starts=()
    for ((r = 0; r < rounds; r++)); do
      rm -rf "$work/out_cli" && mkdir -p "$work/out_cli"
      l=$(load)
      t=$(timed "$bin" bake "$work/in512-$files" --scale 64 --out-dir "$work/out_cli" --force -q | cut -d' ' -f2)
      cli+=("$t")
      echo "  round $((r + 1)): CLI batch $t s (load $l)"
      rm -rf "$work/out_cli" && mkdir -p "$work/out_cli"
      l=$(load)
      t0=$(date +%s.%N)
      "$bin" bake "${even[@]}" --scale 64 --threads 1 --out-dir "$work/out_cli" --force -q &
      "$bin" bake "${odd[@]}" --scale 64 --threads 1 --out-dir "$work/out_cli" --force -q
      wait
      t=$(echo "$(date +%s.%N) - $t0" | bc)
      halves+=("$t")
      echo "  round $((r + 1)): two CLI batches of half the files, one thread each, side by side: $t s (load $l)"
      rm -rf "$work/out_dask"
      l=$(load)
      line=$("$python" "$helper" batch "$work/in512-$files" "$work/out_dask" 1)
      t=$(echo "$line" | "$python" -c 'import json, sys; print(json.load(sys.stdin)["seconds"][0])')
      s=$(echo "$line" | "$python" -c 'import json, sys; d = json.load(sys.stdin); print(d["cluster_start_s"], d["rerun_s"])')
      dask+=("$t") starts+=("$s")
      printf '  round %d: bake_files %.2f s; cluster start %.2f s, re-run (up to date) %.2f s (load %s)\n' \
        $((r + 1)) "$t" ${s} "$l"
    done
    # the cluster's files against the CLI batch typed as the outputs record
    # it (command_text's options): every byte
    read -r -a options < <(echo "$line" | "$python" -c 'import json, sys; print(" ".join(json.load(sys.stdin)["options"]))')
    rm -rf "$work/out_dask_kept" && mv "$work/out_dask" "$work/out_dask_kept"
    "$bin" bake "$work/in512-$files" "${options[@]}" >/dev/null
    if diff -rq "$work/out_dask_kept" "$work/out_dask" >/dev/null; then
      echo "batch: bake_files's $(ls "$work/out_dask" | wc -l) files are byte-identical to the CLI batch's (bake DIR ${options[*]})"
    else
      echo "batch: bake_files's files DIFFER from the CLI batch's"
    fi
    mc=$(printf '%s\n' "${cli[@]}" | median) mh=$(printf '%s\n' "${halves[@]}" | median)
    md=$(printf '%s\n' "${dask[@]}" | median)
    awk -v n="$files" -v c="$mc" -v h="$mh" -v d="$md" -v l="$(load)" 'BEGIN {
      printf "batch: %d maps of 512 x 512 (medians of the rounds; load now %s):\n", n, l
      printf "batch:   CLI batch, 2 threads a bake      %7.2f s  %6.2f maps/s\n", c, n / c
      printf "batch:   2 CLI batches, 1 thread each     %7.2f s  %6.2f maps/s\n", h, n / h
      printf "batch:   bake_files, 2 workers x 1 thread %7.2f s  %6.2f maps/s: %+.1f%% of the time of the CLI batch, %+.1f%% of the two side by side\n",
             d, n / d, 100 * (d / c - 1), 100 * (d / h - 1) }'
    ;;
  big)
    [ -f "$work/rock8k.png" ] || oiiotool "$root/fixtures/rock06_height.png" --resize 8192x8192 -o "$work/rock8k.png"
    # the same command in two directories (the outputs record it), so the
    # files of both can be compared byte for byte
    rm -rf "$work/one" "$work/split" && mkdir -p "$work/one" "$work/split"
    l=$(load)
    r=$(cd "$work/one" && timed "$bin" bake ../rock8k.png --scale 64 --ssbump big_ssbump.png --ao big_ao.png)
    echo "big: 8192 x 8192, one process (2 threads): ${r#* } s, peak ${r%% *} KiB (load $l)"
    l=$(load)
    line=$(cd "$work/split" && "$python" "$helper" big ../rock8k.png big)
    echo "big: 8192 x 8192 split over 2 workers: $line (load $l)"
    for k in ssbump ao; do
      if cmp "$work/one/big_$k.png" "$work/split/big_$k.png"; then
        echo "big: $k: byte-identical to the single process's"
      else
        echo "big: $k: DIFFERENT from the single process's"
      fi
    done
    ;;
  huge)
    [ -f "$work/rock16k.png" ] || oiiotool "$root/fixtures/rock06_height.png" --resize 16384x16384 -o "$work/rock16k.png"
    l=$(load)
    r=$(timed "$bin" bake "$work/rock16k.png" --scale 64 --ssbump "$work/huge_ssbump.png" --ao "$work/huge_ao.png" -q)
    echo "huge: 16384 x 16384 ssbump and ao, one process (2 threads): ${r#* } s, peak ${r%% *} KiB (load $l, $(load) at the end)"
    ;;
  esac
done
