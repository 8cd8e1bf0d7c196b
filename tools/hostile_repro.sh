#!/usr/bin/env bash
# hostile_repro.sh BIN: reruns every reproduction of a hostile input (the hostile
# files: 15 numbered cases with their variants, and the compares of NaN and
# of a flat model), the security and memory cases (32.N: code from the
# working directory, outputs that are not regular files, a memory cgroup, a
# render's picture, the cluster path) and `bumpbake serve` probed as a
# server (39.N, tools/hostile_serve.py) against the binary
# BIN, one line per case: its id, what ran, and CLEAN or NOT CLEAN with the
# reasons.
#
# Clean means: a refusal exits non-zero with one line on
# stderr (a case that should work exits 0), nothing is killed by a signal,
# no control character is printed, the time and peak memory (GNU time's %M,
# children included) stay within the case's bound, and no file is changed,
# added, removed or left behind (.bb-tmp-*) that should not be: every case
# runs in a directory of its own, hashed before and after. Some cases check
# more (a depfile make can read, a signal's set all old or all new, a link
# target untouched); they say so below. The last line is "N cases tried,
# M clean"; the exit code is 0 when every case tried is clean.
#
# Self-contained: it makes its files in a temporary directory and removes
# it (HOSTILE_KEEP=1 keeps it, with each case's output in log/); about a
# minute and a half on 2 cores, and three more for the server (`make
# hostile`). Needs python3, /usr/bin/time and timeout; uses strace (case
# 9), unshare (case 10), setpriv (case 8, when run as root), make and
# ninja (case 11) where they are installed and says SKIPPED where they are
# not.
set -u

if [ $# -ne 1 ] || [ ! -x "$1" ]; then
  echo "usage: hostile_repro.sh BIN (a bumpbake executable)" >&2
  exit 2
fi
BIN=$(realpath "$1")
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
[ -x "$PY" ] || PY=$(command -v python3)
for tool in "$PY" /usr/bin/time timeout; do
  command -v "$tool" >/dev/null || { echo "hostile_repro.sh: $tool is missing" >&2; exit 2; }
done
W=$(mktemp -d "${TMPDIR:-/tmp}/bb-hostile.XXXXXX") || exit 2
chmod 755 "$W"
cleanup() { [ -n "${HOSTILE_KEEP:-}" ] && { echo "kept $W"; return; }; cd /; chmod -R u+rwx "$W" 2>/dev/null; rm -rf "$W"; }
trap cleanup EXIT
trap 'exit 130' INT TERM HUP
LOG=$W/log
mkdir "$LOG"
cp "$ROOT/tools/hostile_repro.py" "$W/hx.py"
chmod 644 "$W/hx.py"
hx() { "$PY" "$W/hx.py" "$@"; }
have() { command -v "$1" >/dev/null 2>&1; }
IS_ROOT=0
[ "$(id -u)" = 0 ] && IS_ROOT=1

tried=0 clean=0 skipped=0 not_clean_ids=()

# ------------------------------------------------------------ the harness

# begin ID DESC: a fresh directory holding h.png (rock06_128.png), and the
# default expectation: a refusal with exit 1, one line, 5 s, 600 MB.
begin() {
  ID=$1 DESC=$2
  reasons=() WANT=fail WANT_RC=1 FAIL_LINES=1 LINES=1 TMAX=5 MMAX=600 VLIM= TLIM=30 MSG= NOTMSG= ALLOW=
  SIGOK=0 rc= sig= secs=0 kib=0
  C=$W/c/$ID
  mkdir -p "$C" && cd "$C" || exit 2
  cp "$ROOT/fixtures/rock06_128.png" h.png
}

bad() { reasons+=("$*"); }

# run CMD...: snapshots the directory, then runs CMD under timeout and GNU
# time (and ulimit -v VLIM), stdout and stderr to the log.
run() {
  hx snap . "$LOG/$ID.snap"
  OUTF=$LOG/$ID.out ERRF=$LOG/$ID.err TF=$LOG/$ID.time
  (
    # A safety net (soft, so a child may raise it) against a binary that
    # takes all memory: HOSTILE_VLIM KiB, or unlimited (ASan builds).
    if [ -n "$VLIM" ]; then ulimit -v "$VLIM" || exit 125
    else ulimit -S -v "${HOSTILE_VLIM:-6000000}" || exit 125; fi
    exec /usr/bin/time -f '%e %M' -o "$TF" timeout -k 2 "$TLIM" "$@"
  ) >"$OUTF" 2>"$ERRF" </dev/null
  rc=$?
  sig=$(sed -n 's/^Command terminated by signal \([0-9]*\).*/\1/p' "$TF" 2>/dev/null)
  read -r secs kib < <(tail -n 1 "$TF" 2>/dev/null)
  secs=${secs:-0} kib=${kib:-0}
  case $kib in '' | *[!0-9]*) kib=0 ;; esac
}

in_list() { local x=$1; shift; for y in "$@"; do [ "$x" = "$y" ] && return 0; done; return 1; }

# outcome: the checks every case shares, into reasons.
outcome() {
  ERRLINES=$(awk 'END { print NR }' "$ERRF")
  if [ -n "$sig" ] && ! { [ "$sig" = 2 ] && [ "$SIGOK" = 1 ]; }; then
    bad "killed by signal $sig (SIG$(kill -l "$sig" 2>/dev/null))"
  elif [ "$rc" = 124 ]; then
    bad "no answer in $TLIM s"
  elif [ "$WANT" = ok ] && [ "$rc" != 0 ]; then
    bad "exit $rc: $(head -n 1 "$ERRF" | cut -c1-120)"
  elif [ "$WANT" = fail ] && ! in_list "$rc" $WANT_RC; then
    bad "exit $rc, not $WANT_RC$([ "$rc" = 0 ] && echo ' (accepted)')"
  fi
  if [ "$WANT" = fail ] && ! in_list "$ERRLINES" $FAIL_LINES; then bad "$ERRLINES lines on stderr"; fi
  if [ "$WANT" = ok ] && [ "$ERRLINES" -gt "$LINES" ]; then bad "$ERRLINES lines on stderr"; fi
  local ctl
  ctl=$(hx ctl "$OUTF" "$ERRF")
  [ -n "$ctl" ] && bad "$ctl"
  awk -v s="$secs" -v m="$TMAX" 'BEGIN { exit !(s > m) }' && bad "took $secs s (bound $TMAX s)"
  [ "$kib" -gt $((MMAX * 1024)) ] && bad "peak $((kib / 1024)) MB (bound $MMAX MB)"
  [ -n "$MSG" ] && ! grep -qF -- "$MSG" "$ERRF" && bad "stderr lacks '$MSG'"
  local said
  [ -n "$NOTMSG" ] && said=$(cat "$OUTF" "$ERRF" | grep -oaE -- "$NOTMSG" | head -n 1) &&
    [ -n "$said" ] && bad "prints '$said'"
  local d
  d=$(hx diff . "$LOG/$ID.snap" "$ALLOW")
  [ -n "$d" ] && bad "$d"
}

# report [SUMMARY]: the case's line.
report() {
  local summary=${1:-"exit $rc${sig:+ (signal $sig)}, $ERRLINES line(s), $secs s, $((kib / 1024)) MB"}
  tried=$((tried + 1))
  if [ ${#reasons[@]} -eq 0 ]; then
    clean=$((clean + 1))
    line=$(printf '%-5s %-62s CLEAN      %s' "$ID" "$DESC" "$summary")
  else
    not_clean_ids+=("$ID")
    local joined
    joined=$(printf '%s; ' "${reasons[@]}")
    line=$(printf '%-5s %-62s NOT CLEAN  %s' "$ID" "$DESC" "${joined%; }")
  fi
  printf '%s\n' "$line" | LC_ALL=C tr '\000-\011\013-\037\177' '?'
}

finish() { outcome; report; }

skip() {
  skipped=$((skipped + 1))
  printf '%-5s %-62s SKIPPED    %s\n' "$1" "$2" "$3"
}

# opened PATTERN CMD...: runs CMD under strace; true when a file whose
# name matches PATTERN was opened.
opened() {
  local pattern=$1; shift
  have strace || return 1
  timeout 60 strace -f -qq -o "$LOG/$ID.strace" -e trace=open,openat,openat2 "$@" \
    >/dev/null 2>&1 </dev/null
  grep -E "open(at2?)?\(.*\"[^\"]*($pattern)[^\"]*\".*= [0-9]+" "$LOG/$ID.strace" >/dev/null
}

bake_fast=(--scale 8 --rays 16 --filter-radius 2)
echo "hostile_repro: $BIN ($("$BIN" --version 2>&1 | head -n 1)), in $W"

# ------------------------------------------------ 1. models read what they should not

begin 1a "renderbumpflat: glTF buffer uri /etc/passwd"
hx make gltf_uri passwd.gltf /etc/passwd
run "$BIN" renderbumpflat passwd.gltf
NOTMSG=root: outcome
opened /etc/passwd "$BIN" renderbumpflat passwd.gltf && bad "/etc/passwd was opened"
report

begin 1b "renderbumpflat: OBJ mtllib /etc/passwd"
hx make obj_mtllib m.obj /etc/passwd
run "$BIN" renderbumpflat m.obj
NOTMSG=root: outcome
opened /etc/passwd "$BIN" renderbumpflat m.obj && bad "/etc/passwd was opened"
report

begin 1c "renderbumpflat: OBJ mtllib ../../../../etc/shadow"
hx make obj_mtllib m.obj ../../../../etc/shadow
run "$BIN" renderbumpflat m.obj
outcome
opened shadow "$BIN" renderbumpflat m.obj && bad "the shadow file was opened"
report

begin 1d "renderbumpflat: OBJ mtllib a link out (-> /etc/passwd)"
ln -s /etc/passwd link.mtl
hx make obj_mtllib m.obj link.mtl
run "$BIN" renderbumpflat m.obj
NOTMSG=root: outcome
opened 'link\.mtl|/etc/passwd' "$BIN" renderbumpflat m.obj && bad "the link was opened"
report

begin 1e "renderbumpflat: glTF buffer a link out (-> /etc/passwd)"
ln -s /etc/passwd buf.bin
hx make gltf_uri l.gltf buf.bin
run "$BIN" renderbumpflat l.gltf
NOTMSG=root: outcome
opened 'buf\.bin|/etc/passwd' "$BIN" renderbumpflat l.gltf && bad "the link was opened"
report

begin 1f "renderbumpflat: OBJ mtllib naming a directory"
mkdir sub
hx make obj_mtllib m.obj sub
run "$BIN" renderbumpflat m.obj
finish

# --------------------------------------------------- 2. models that crashed

begin 2a "renderbumpflat: glTF of 20,000 nested nodes"
hx make deep_gltf d.gltf 20000
run "$BIN" renderbumpflat d.gltf
TMAX=20 finish

begin 2b "renderbumpflat: Collada of 20,000 nested nodes"
hx make deep_dae d.dae 20000
run "$BIN" renderbumpflat d.dae
TMAX=20 finish

begin 2c "renderbumpflat: glTF whose JSON nests 200,000 deep"
hx make deep_json j.gltf 200000
run "$BIN" renderbumpflat j.gltf
TMAX=20 finish

# Deeper still, these crash the importer itself (a child process).
begin 2d "renderbumpflat: glTF of 200,000 nested nodes"
hx make deep_gltf d.gltf 200000
run "$BIN" renderbumpflat d.gltf
TMAX=20 finish

begin 2e "renderbumpflat: Collada of 200,000 nested nodes"
hx make deep_dae d.dae 200000
run "$BIN" renderbumpflat d.dae
TMAX=20 finish

begin 2f "renderbumpflat: glTF whose JSON nests 5,000,000 deep"
hx make deep_json j.gltf 5000000
run "$BIN" renderbumpflat j.gltf
TMAX=20 finish

# ------------------------------------------------------- 3. unbounded work

begin 3a "renderbumpflat: 10^6 faces on one triangle, --size 64 64"
hx make faces_obj f.obj 1000000
run "$BIN" renderbumpflat f.obj --size 64 64
TMAX=10 finish

# The importer (a child) may take BB_MAX_IMPORT_MEMORY, 4 GiB (limits.md):
# the bound is that cap and bumpbake's own.
begin 3b "renderbumpflat: an 80 MB OBJ (10^7 faces): memory"
hx make faces_obj big.obj 10000000
run "$BIN" renderbumpflat big.obj --size 64 64
TMAX=60 MMAX=4608 finish
rm -f big.obj

# -------------------------------------------- 4. FIFOs and devices as inputs

fifo_case() { # ID-SUFFIX DESC ARGS... with @ for the FIFO or device file
  local base=$1 desc=$2 ext=$3; shift 3
  for kind in f z; do
    local what=FIFO
    [ $kind = z ] && what="link to /dev/zero"
    begin "4$base$kind" "$desc ($what)"
    mkfifo "f$ext" && ln -s /dev/zero "z$ext"
    local args=()
    for a in "$@"; do args+=("${a//@/$kind$ext}"); done
    TLIM=10
    run "$BIN" "${args[@]}"
    WANT_RC=${RC:-1} TMAX=2 finish
  done
}
fifo_case a "info F" .png info @
fifo_case b "bake F" .png bake @ "${bake_fast[@]}" --normal o.png
RC=4 fifo_case c "compare h.png F (idiff's exit 4)" .png compare h.png @
fifo_case d "program 'invertColor(F)'" .png program "invertColor(@)" -o o.png
fifo_case e "render F --scale 8" .png render @ --scale 8 -o o.png
fifo_case g "render --ssbump h.png --albedo F" .png render --ssbump h.png --albedo @ -o o.png
fifo_case h "bake h.png --basis F" .txt bake h.png "${bake_fast[@]}" --basis @ --ssbump o.png
fifo_case i "renderbumpflat F.obj" .obj renderbumpflat @
# The other commands that read an image, through the same checks.
fifo_case k "normal F --scale 8" .png normal @ --scale 8 -o o.png
fifo_case l "combine F h.png --mix 0.5" .png combine @ h.png --mix 0.5 -o o.png
fifo_case m "height2ssbump F 8" .png height2ssbump @ 8
fifo_case n "normal2ssbump F" .png normal2ssbump @ -o o.png
fifo_case o "ssbump2normal F" .png ssbump2normal @ -o o.png
fifo_case p "sheet F --scale 8" .png sheet @ --scale 8 --rays 16 -o o.png
for kind in f z; do
  begin "4j$kind" "renderbumpflat m.obj, mtllib $([ $kind = f ] && echo FIFO || echo 'link to /dev/zero')"
  mkfifo f.mtl && ln -s /dev/zero z.mtl
  hx make obj_mtllib m.obj "$kind.mtl"
  TLIM=10
  run "$BIN" renderbumpflat m.obj
  TMAX=2 finish
done

# ----------------------------------- 5. headers that declare huge allocations

# Each file is read by info and by bake twice: under `ulimit -v 2000000`,
# the bound a user's shell may set, and with no limit but the safety net, where what the
# header made the reader allocate shows in the peak memory. A refusal from
# the header says what is wrong: a reason that is an allocation failing
# (the reader allocated first) is not clean.
ALLOC_FAILED='_M_default_append|bad_alloc|Insufficient memory|out of memory|cannot allocate'

hdr_case() { # ID DESC FILE MAKER-ARGS...
  local id=$1 desc=$2 file=$3; shift 3
  local vlim limited
  for vlim in 2000000 ''; do
    limited=$([ -n "$vlim" ] && echo ", ulimit -v $vlim" || echo ", no ulimit")
    begin "$id$([ -n "$vlim" ] && echo i || echo I)" "info $desc$limited"
    hx make "$@"
    VLIM=$vlim run "$BIN" info "$file"
    [ "$id" = 5b ] && WANT=ok # the TIFF's header is a fine 1 x 1 image
    NOTMSG=$ALLOC_FAILED TMAX=1 MMAX=400 finish
    begin "$id$([ -n "$vlim" ] && echo b || echo B)" "bake $desc$limited"
    hx make "$@"
    VLIM=$vlim run "$BIN" bake "$file" --scale 8 --normal n.png
    NOTMSG=$ALLOC_FAILED TMAX=1 MMAX=400 finish
  done
}
hdr_case 5a "a 126-byte progressive JPEG of 65500x65500" p.jpg progressive_jpeg p.jpg 65500 65500
hdr_case 5b "a 1x1 TIFF of 16384x16384 tiles" t.tif tiled_tiff t.tif 1 1 16384 16384
hdr_case 5c "a 91-byte EXR with a 2 GB string attribute" a.exr exr_attribute a.exr 2147483632
hdr_case 5d "a 35-byte GIF of 65535x65535" g.gif gif_screen g.gif 65535 65535
hdr_case 5e "an 80-byte VTF of 65535x65535 RGBA32323232F" v.vtf vtf_header v.vtf 65535 65535 29 1
hdr_case 5f "a 16x16 DDS declaring 65029 mip levels" d.dds dds_mips d.dds 65029

# -------------------------------------------- 6. outputs over what is read

render_setup() {
  "$BIN" bake h.png "${bake_fast[@]}" --normal n.png --ssbump s.png --ao ao.png --bent b.png -q
  cp h.png a.png
}
over_case() { # ID DESC ARGS...
  local id=$1 desc=$2; shift 2
  begin "$id" "$desc"
  render_setup
  run "$BIN" "$@"
  WANT_RC=${RC:-"1 2"} finish
}
over_case 6a "render --ssbump s.png --albedo a.png -o a.png" render --ssbump s.png --albedo a.png -o a.png
over_case 6b "render --ssbump s.png -o s.png" render --ssbump s.png -o s.png
over_case 6c "render --normal n.png --ao ao.png --mode ao -o ao.png" render --normal n.png --ao ao.png --mode ao -o ao.png
over_case 6d "render --ssbump s.png --bent b.png -o b.png" render --ssbump s.png --bent b.png --specular 8 -o b.png
over_case 6e "render h.png --scale 8 --albedo a.png -o a.png" render h.png --scale 8 --rays 16 --albedo a.png -o a.png
over_case 6f "render h.png --scale 8 -o ./sub/../h.png" render h.png --scale 8 --rays 16 -o ./sub/../h.png
over_case 6g "render --normal n.png --mode normal -o \$PWD/n.png" render --normal n.png --mode normal -o "$W/c/6g/n.png"
begin 6h "render --ssbump r_000.png --orbit 2 -o r.png (frame 0 = input)"
render_setup
cp s.png r_000.png
run "$BIN" render --ssbump r_000.png --orbit 2 -o r.png
WANT_RC="1 2" finish
over_case 6i "program 'invertColor(a.png)' -o a.png" program "invertColor(a.png)" -o a.png
over_case 6j "combine a.png h.png --mix 0.5 -o h.png" combine a.png h.png --mix 0.5 -o h.png
RC=4 over_case 6k "compare a.png h.png --diff a.png" compare a.png h.png --diff a.png
over_case 6l "normal h.png --scale 8 -o h.png" normal h.png --scale 8 -o h.png
over_case 6m "ssbump2normal s.png -o s.png" ssbump2normal s.png -o s.png
over_case 6n "sheet h.png --scale 8 -o h.png" sheet h.png --scale 8 --rays 16 -o h.png
# (6k: compare's exit for a usage error or an unreadable file is 4, idiff's)

# --------------------------------------------- 7. names leaving --out-dir

begin 7a "bake in/...png --out-dir out --name '{stem}/{kind}.png'"
mkdir in out && cp h.png in/...png
run "$BIN" bake in/...png "${bake_fast[@]}" --out-dir out --name '{stem}/{kind}.png'
WANT_RC="1 2" finish

begin 7b "bake h.png --out-dir out --name '{stem}/../../{kind}.png'"
mkdir out
run "$BIN" bake h.png "${bake_fast[@]}" --out-dir out --name '{stem}/../../{kind}.png'
WANT_RC="1 2" finish

begin 7c "bake h.png --out-dir out --name '../{stem}_{kind}.png'"
mkdir out
run "$BIN" bake h.png "${bake_fast[@]}" --out-dir out --name '../{stem}_{kind}.png'
WANT_RC="1 2" finish

# --------------------------------- 8. a link planted at a TIFF's temporary

# A watcher in the shared output directory (another user, the threat of a
# shared directory, when this runs as root) swaps every temporary file of the
# writer for a link to precious.txt, and moves every private directory
# aside for one of its own full of such links, while a mip-mapped TIFF is
# written. Clean: precious.txt keeps its bytes in every trial, and each
# bake either writes a real TIFF or fails with one line.
begin 8 "bake --normal shared/n.tif --mips, links planted (9 trials)"
cp "$ROOT/fixtures/rock06_height.png" big.png
mkdir shared && chmod 777 shared
echo precious >precious.txt
chmod 666 precious.txt
cp precious.txt "$LOG/8.precious"
as_other=()
if [ $IS_ROOT = 1 ] && have setpriv; then
  as_other=(setpriv --reuid=65534 --regid=65534 --clear-groups)
fi
hx snap . "$LOG/8.snap0"
through=0 swaps="" max_secs=0 max_kib=0
for t in 1 2 3 4 5 6 7 8 9; do
  rm -f "$W/stop"
  : >"$LOG/8.attack$t" && chmod 666 "$LOG/8.attack$t"
  "${as_other[@]}" "$PY" "$W/hx.py" attack "$C/shared" "$C/precious.txt" 30 "$LOG/8.attack$t" "$W/stop" &
  attacker=$!
  sleep 0.3
  run "$BIN" bake big.png --scale 8 --filter-radius 0 --normal shared/n.tif --mips -q
  touch "$W/stop"
  wait "$attacker"
  swaps+=" $(cat "$LOG/8.attack$t" 2>/dev/null)"
  cmp -s precious.txt "$LOG/8.precious" || { through=$((through + 1)); cp "$LOG/8.precious" precious.txt; }
  if [ -n "$sig" ] || ! in_list "$rc" 0 1 || [ "$(awk 'END { print NR }' "$ERRF")" -gt 1 ]; then
    bad "trial $t: exit $rc${sig:+ signal $sig}: $(head -n 1 "$ERRF" | cut -c1-100)"
  elif [ "$rc" = 0 ] && { [ -L shared/n.tif ] || ! "$BIN" info shared/n.tif >/dev/null 2>&1; }; then
    bad "trial $t: shared/n.tif is not the TIFF written"
  fi
  [ -n "$(hx ctl "$OUTF" "$ERRF")" ] && bad "trial $t: control characters printed"
  awk -v s="$secs" -v m="$max_secs" 'BEGIN { exit !(s > m) }' && max_secs=$secs
  [ "$kib" -gt "$max_kib" ] && max_kib=$kib
  rm -rf shared/* shared/.bb-tmp* 2>/dev/null
done
[ $through -gt 0 ] && bad "precious.txt written through in $through of 9 trials"
ERRLINES=0 secs=$max_secs kib=$max_kib
d=$(hx diff . "$LOG/8.snap0" '^shared')
[ -n "$d" ] && bad "$d"
attacks=$(echo "$swaps" | tr ' ' '\n' | awk -F= 'NF == 2 { n[$1] += $2 } END { printf "%d temporaries swapped, %d private dirs swapped, %d links planted inside, %d refused", n["files_swapped"], n["dirs_swapped"], n["planted_inside"], n["inside_refused"] }')
[ "$(echo "$swaps" | tr ' ' '\n' | awk -F= 'NF == 2 && $1 ~ /swapped|planted/ { n += $2 } END { print n + 0 }')" = 0 ] &&
  bad "the watcher never reached a temporary (not exercised)"
report "target untouched in 9 trials: $attacks, ${as_other[*]:+as nobody}"

# ---------------------------------------- 9. a signal in the middle of a commit

# strace delivers SIGINT at the second rename of the set; the set must be
# all old or all new, and the exit 130.
if have strace && strace -f -o /dev/null -e trace=none true >/dev/null 2>&1; then
  begin 9a "bake -o o/r --bent o/r_bent.exr, SIGINT at the 2nd rename"
  mkdir o
  "$BIN" bake h.png --scale 4 --rays 16 -o o/r --bent o/r_bent.exr -q
  for f in o/r_normal.png o/r_ssbump.png o/r_ao.png o/r_bent.exr; do cp "$f" "$LOG/9a.$(basename "$f")"; done
  run strace -f -o /dev/null -e trace=rename -e inject=rename:signal=SIGINT:when=2 \
    "$BIN" bake h.png --scale 8 --rays 16 -o o/r --bent o/r_bent.exr -q
  new=0 old=0
  for f in o/r_normal.png o/r_ssbump.png o/r_ao.png o/r_bent.exr; do
    if cmp -s "$f" "$LOG/9a.$(basename "$f")"; then old=$((old + 1)); else new=$((new + 1)); fi
  done
  [ $new != 0 ] && [ $old != 0 ] && bad "$new maps new and $old old"
  [ "$rc" = 0 ] && bad "exit 0: no SIGINT arrived (the renames are not rename(2) calls?)"
  # A deferred signal ends the process silently: no line is owed.
  ALLOW='^o/r_' WANT_RC=130 SIGOK=1 FAIL_LINES="0 1" outcome
  report "exit $rc${sig:+ (signal $sig)}, set $([ $new = 4 ] && echo 'all new' || echo "all old") ($new new, $old old), $secs s"

  begin 9b "render --orbit 4 -o x.png, SIGINT at the 2nd rename"
  "$BIN" render h.png --scale 8 --rays 16 --orbit 4 --light 0,30 -o x.png -q
  for i in 0 1 2 3; do cp "x_00$i.png" "$LOG/9b.$i"; done
  run strace -f -o /dev/null -e trace=rename -e inject=rename:signal=SIGINT:when=2 \
    "$BIN" render h.png --scale 8 --rays 16 --orbit 4 --light 0,60 -o x.png -q
  new=0 old=0
  for i in 0 1 2 3; do
    if cmp -s "x_00$i.png" "$LOG/9b.$i"; then old=$((old + 1)); else new=$((new + 1)); fi
  done
  [ $new != 0 ] && [ $old != 0 ] && bad "$new frames new and $old old"
  [ "$rc" = 0 ] && bad "exit 0: no SIGINT arrived (the renames are not rename(2) calls?)"
  ALLOW='^x_00' WANT_RC=130 SIGOK=1 FAIL_LINES="0 1" outcome
  report "exit $rc${sig:+ (signal $sig)}, frames $([ $new = 4 ] && echo 'all new' || echo "all old") ($new new, $old old), $secs s"
else
  skip 9a "bake, SIGINT at the 2nd rename" "strace is missing or cannot trace here"
  skip 9b "render --orbit, SIGINT at the 2nd rename" "strace is missing or cannot trace here"
fi

# ------------------------------------------------- 10. depfiles that cannot be written

# The old maps are there first: they must stay as they were.
dep_setup() { "$BIN" bake h.png --scale 4 --rays 16 --ao ao.png --normal n.png -q; }
if [ $IS_ROOT = 1 ]; then NS=(unshare -m); else NS=(unshare -Urm); fi
begin 10a "bake --depfile ro/h.d (a read-only directory)"
dep_setup
mkdir ro
if [ $IS_ROOT = 1 ]; then
  if "${NS[@]}" true 2>/dev/null; then
    run "${NS[@]}" sh -c 'mount --bind ro ro && mount -o remount,bind,ro ro && exec "$@"' sh \
      "$BIN" bake h.png --scale 8 --rays 16 --ao ao.png --normal n.png --depfile ro/h.d
    MSG=ro/h.d finish
  else
    skip 10a "bake --depfile in a read-only directory" "root, and no mount namespace to make one"
  fi
else
  chmod 555 ro
  run "$BIN" bake h.png --scale 8 --rays 16 --ao ao.png --normal n.png --depfile ro/h.d
  MSG=ro/h.d finish
fi

begin 10b "bake --depfile full/h.d (a full file system)"
dep_setup
mkdir full
if "${NS[@]}" true 2>/dev/null; then
  run "${NS[@]}" sh -c 'mount -t tmpfs -o size=64k none full &&
    dd if=/dev/zero of=full/fill bs=4k >/dev/null 2>&1; exec "$@"' sh \
    "$BIN" bake h.png --scale 8 --rays 16 --ao ao.png --normal n.png --depfile full/h.d
  MSG=full/h.d finish
else
  skip 10b "bake --depfile on a full file system" "no mount namespace for a small tmpfs"
fi

# ----------------------------------------------------- 11. depfile names

# A name make and ninja cannot hold is refused before the bake; one they
# can is escaped so that both read the name back (make -q finds the output
# up to date; ninja -t deps lists the input as it is named).
dep_name_case() { # ID NAME SHOWN-AS ok|refuse
  local id=$1 name=$2 shown=$3 want=$4
  begin "$id" "bake $shown --normal o.png --depfile o.d"
  cp h.png "$name"
  run "$BIN" bake "$name" "${bake_fast[@]}" --normal o.png --depfile o.d
  if [ "$want" = refuse ]; then
    finish
    return
  fi
  WANT=ok ALLOW='^o\.(png|d)$' outcome
  if [ ! -f o.d ]; then
    bad "no depfile"
  else
    if have make; then
      printf 'include o.d\n' >"$LOG/$id.mk"
      make -q -f "$LOG/$id.mk" o.png >"$LOG/$id.make" 2>&1 || bad "make misreads the depfile: $(head -n 1 "$LOG/$id.make")"
    fi
    if have ninja; then
      local nd=$LOG/$id.ninja
      mkdir -p "$nd" && cp o.d "$nd/o.d.src" && cp -- "$name" "$nd/$name"
      printf 'rule r\n  command = cp o.d.src o.d && touch o.png\n  depfile = o.d\n  deps = gcc\nbuild o.png: r\n' >"$nd/build.ninja"
      if (cd "$nd" && ninja >/dev/null 2>&1 && ninja -t deps o.png >deps.txt 2>&1); then
        grep -qxF -- "    $name" "$nd/deps.txt" || bad "ninja reads the input as $(sed -n 2p "$nd/deps.txt" | sed 's/^ *//')"
      else
        bad "ninja fails on the depfile"
      fi
    fi
  fi
  report
}
dep_name_case 11a $'t\tx.png' "t<TAB>x.png" refuse
dep_name_case 11b 'a\ b.png' "'a\\ b.png' (backslash, space)" ok
dep_name_case 11c 'c:d.png' "c:d.png" refuse
dep_name_case 11d 'e=f.png' "e=f.png" refuse
dep_name_case 11e 'g;h.png' "g;h.png" refuse
dep_name_case 11f 'i%j.png' "i%j.png" refuse
dep_name_case 11g 'k*l.png' "k*l.png" refuse

# --------------------------------------------------- 12. program images and --base

prog_case() { # ID DESC EXPR
  begin "$1" "$2"
  mkdir base && cp h.png base/in.png && cp h.png x.png
  ln -s "$C/x.png" base/link.png
  run "$BIN" program "$3" --base base -o o.png
  finish
}
prog_case 12a "program 'invertColor(../x.png)' --base base" "invertColor(../x.png)"
prog_case 12b "program 'invertColor(/ABS/x.png)' --base base" "invertColor($W/c/12b/x.png)"
prog_case 12c "program 'invertColor(link.png)', link.png -> ../x.png" "invertColor(link.png)"
prog_case 12d "program 'addnormals(in.png, heightmap(../x.png, 4))'" "addnormals(in.png, heightmap(../x.png, 4))"

# -------------------------------------------------- 13. terminal escapes

# command is left out of compare's provenance diff; input is not.
ESC_DESC=$(printf 'bumpbake_version=x\ncommand=\033]0;pwned\007\033[31mred\ninput=\033]2;t\007.png\n' |
  od -v -An -tx1 | tr -d ' \n')
ESC_DESC2=$(printf 'bumpbake_version=y\ncommand=\033[2J\033[H\233\302\233 cleared\ninput=\033[2J\302\233.png\n' |
  od -v -An -tx1 | tr -d ' \n')
esc_name=$'bad\e[2J.png'
print_case() { # ID DESC ok|fail ARGS...
  local id=$1 desc=$2 want=$3; shift 3
  begin "$id" "$desc"
  hx make png_desc e.png "$ESC_DESC"
  hx make png_desc "$esc_name" "$ESC_DESC2"
  printf '0 0 1\n\033]0;pwned\007\033[31m 1 0\n' >b.txt
  printf 'x' >"bad"$'\e[31m'".png"
  run "$BIN" "$@"
  if [ "$want" = ok ]; then WANT=ok finish; else WANT_RC="1 2" finish; fi
}
print_case 13a "info FILE, provenance holding ESC ] 0;pwned BEL ESC [31m" ok info e.png
print_case 13b "info, a file name holding ESC [2J" ok info "$esc_name"
print_case 13c "compare: provenance and names with escapes" ok compare e.png "$esc_name"
print_case 13d "info of a missing file named with ESC [31m" fail info $'missing\e[31m.png'
print_case 13e "bake of a corrupt file named with ESC [31m" fail bake "bad"$'\e[31m'".png" --scale 8 --normal o.png
print_case 13f "bake --basis b.txt, a line holding escapes" fail bake h.png "${bake_fast[@]}" --basis b.txt --ssbump o.png
print_case 13g "program text holding escapes" fail program $'invertColor(\e]0;pwned\a\e[31m)' -o o.png
begin 13h "batch bake: 'wrote' lines of a name holding ESC [2J"
mkdir in out && cp h.png "in/$esc_name"
run "$BIN" bake in "${bake_fast[@]}" --out-dir out --maps normal
WANT=ok ALLOW='^out' finish
print_case 13i "program's error naming an image with escapes" fail program $'invertColor(bad\e[31m.png)' -o o.png
begin 13j "renderbumpflat: 'wrote' line of a model named with ESC [2J"
cp "$ROOT/fixtures/rivet_panel.obj" $'m\e[2J.obj'
run "$BIN" renderbumpflat $'m\e[2J.obj' --size 32 32
WANT=ok LINES=1 ALLOW='_local\.tga$' finish

# --------------------------------------------------------- 14. --json

FF_DESC=$(printf 'bumpbake_version=x\ncommand=caf\351 \377 end\n' | od -v -An -tx1 | tr -d ' \n')
LONG_KEY=$(printf 'k%.0s' $(seq 200))
LONG_VAL="$(printf 'v%.0s' $(seq 1022))é$(printf 'w%.0s' $(seq 2000))"
LONG_DESC=$(printf 'bumpbake_version=x\n%s=%s\n' "$LONG_KEY" "$LONG_VAL" | od -v -An -tx1 | tr -d ' \n')
ff_name=$'bad\xff.png'
json_case() { # ID DESC ALLOW ARGS...
  local id=$1 desc=$2 allow=$3; shift 3
  begin "$id" "$desc"
  hx make png_desc ff.png "$FF_DESC"
  hx make png_desc "$ff_name" "$FF_DESC"
  hx make png_desc long.png "$LONG_DESC"
  run "$BIN" "$@"
  WANT=ok ALLOW=$allow outcome
  local j
  if [ "$id" = 14c ]; then j=$(hx json "$OUTF" "$LONG_KEY" 3023); else j=$(hx json "$OUTF"); fi
  [ -n "$j" ] && bad "$j"
  report
}
json_case 14a "info --json, provenance holding \\xff and Latin-1" '' info --json ff.png
json_case 14b "info --json of a file named bad\\xff.png" '' info --json "$ff_name"
json_case 14c "info --json, a 200-byte key and a 3023-char value" '' info --json long.png
json_case 14d "bake --json of bad\\xff.png" '^o\.png$' bake "$ff_name" "${bake_fast[@]}" --normal o.png --json -q
json_case 14e "compare --json of ff.png and bad\\xff.png" '' compare --json ff.png "$ff_name"

# ------------------------------------------ 15. address space: before and after main()

start_min=$(grep -m1 '^| `bumpbake --version`' "$ROOT/docs/limits.md" | grep -o '[0-9][0-9,]*' | head -n 1 | tr -d ,)
begin 15a "ulimit -v 400000..460000 before main() (documented)"
if [ -z "$start_min" ]; then
  bad "docs/limits.md gives no start-up minimum"
  ERRLINES=0
  report "-"
else
  outcomes=""
  for lim in 400000 430000 460000 "$start_min"; do
    VLIM=$lim run "$BIN" --version
    if [ "$lim" = "$start_min" ]; then
      [ "$rc" = 0 ] || bad "the documented minimum $start_min KiB does not start (exit $rc)"
    elif ! in_list "$rc" 0 127 134 139 || [ -s "$OUTF" -a "$rc" != 0 ]; then
      bad "$lim KiB: exit $rc, not the documented 127/134/139"
    fi
    outcomes+=" $lim:$rc"
  done
  ERRLINES=0
  report "limits.md: starts from $start_min KiB; exits$outcomes"
fi

# Every run above the documented start-up minimum ends cleanly: exit 0,
# or exit 1 with one line saying it is out of memory, and nothing written.
sweep_case() { # ID DESC ARGS...
  local id=$1 desc=$2; shift 2
  begin "$id" "$desc, ulimit -v 460000..1600000"
  cp "$ROOT/fixtures/rivet_panel.obj" m.obj
  local ok=0 oom=0 early=0
  for lim in 460000 480000 500000 520000 540000 560000 600000 700000 1000000 1600000; do
    rm -rf out && mkdir out
    VLIM=$lim TLIM=60 run "$BIN" "$@"
    local n
    n=$(awk 'END { print NR }' "$ERRF")
    if [ "$lim" -lt "${start_min:-0}" ] && { in_list "$rc" 127 134 139 || [ -n "$sig" ]; }; then
      early=$((early + 1))
    elif [ -z "$sig" ] && [ "$rc" = 0 ]; then
      ok=$((ok + 1))
    # An allocation that failed, or the bake's memory estimate refused first.
    elif [ -z "$sig" ] && [ "$rc" = 1 ] && [ "$n" = 1 ] &&
      grep -q -e 'out of memory' -e ' of memory; .* is available' "$ERRF" &&
      [ -z "$(ls -A out)" ]; then
      oom=$((oom + 1))
    elif [ -z "$sig" ] && [ "$rc" = 1 ] && [ "$n" = 1 ] && [ -z "$(ls -A out)" ]; then
      bad "$lim KiB: not a message of memory: $(head -n 1 "$ERRF" | cut -c1-90)"
    else
      bad "$lim KiB: exit $rc${sig:+ signal $sig}, $n lines: $(head -n 1 "$ERRF" | cut -c1-90)"
    fi
    [ -n "$(find . -name '.bb-tmp*')" ] && bad "$lim KiB: a temporary was left"
    [ -n "$(hx ctl "$OUTF" "$ERRF")" ] && bad "$lim KiB: control characters printed"
  done
  ERRLINES=0
  report "$ok ok, $oom out of memory (one line, nothing written), $early before main"
}
sweep_case 15b "info h.png" info h.png
sweep_case 15c "normal h.png --scale 8" normal h.png --scale 8 -o out/n.png
sweep_case 15d "bake h.png --scale 8 -o out/r" bake h.png --scale 8 --rays 16 -o out/r
sweep_case 15e "renderbumpflat rivet_panel.obj" renderbumpflat m.obj --size 128 128 -o out/p.tga
sweep_case 15f "render h.png --scale 8" render h.png --scale 8 --rays 16 -o out/x.png

# ------------------------------------------------- 32: security, memory

# 32.1: `bake --scheduler` ran `python3 -m bumpbake.dask`, which put the
# working directory first on sys.path: a numpy.py, distributed/ or
# bumpbake/ there ran. Each stub here leaves RAN behind if it runs. The
# address is not one, so the run ends at once; what Python then says about
# it (a traceback: case 32.6) is not judged here, only what was imported.
scheduler_case() { # ID DESC ENV...
  local id=$1 desc=$2; shift 2
  begin "$id" "$desc"
  mkdir -p distributed bumpbake/dask
  for stub in numpy.py distributed/__init__.py bumpbake/__init__.py bumpbake/dask/__init__.py; do
    printf 'open("%s/RAN", "a").write(__name__ + "\\n")\nraise SystemExit(0)\n' "$C" >"$stub"
  done
  TMAX=15 TLIM=60
  run env "$@" "$BIN" bake h.png --scale 8 --normal n.png --scheduler not-an-address
  [ -e RAN ] && bad "ran $(tr '\n' ' ' <RAN)from the working directory"
  grep -q "cannot import bumpbake.dask" "$ERRF" && bad "$(head -n 1 "$ERRF" | cut -c1-100)"
  WANT_RC="1 2" FAIL_LINES=$(awk 'END { print NR }' "$ERRF") ALLOW='^RAN$' finish
}
if "$PY" -c 'import distributed' 2>/dev/null; then
  scheduler_case 32.1a "bake --scheduler in a directory holding numpy.py, bumpbake/" BB_=
  scheduler_case 32.1b "bake --scheduler, PYTHONPATH=: (an empty entry is the cwd)" PYTHONPATH=:
  scheduler_case 32.1c "bake --scheduler, BUMPBAKE_PYTHONPATH=::" BUMPBAKE_PYTHONPATH=::
else
  skip 32.1 "bake --scheduler imports nothing from the working directory" "no python3-distributed"
fi

# 32.2: outputs that exist and are not regular files were renamed over (as
# root /dev/full became a 13-byte file). Every one here lives in the case's
# directory (a FIFO, a link to /dev/null or /dev/full, as root a device
# node made here), so a binary that still renames over them harms nothing
# outside it; the snapshot sees one replaced.
begin 32.2a "bake --normal FIFO"
mkfifo f.png
run "$BIN" bake h.png "${bake_fast[@]}" --normal f.png
MSG="is a FIFO" finish
begin 32.2b "bake --ssbump LINK (-> /dev/null)"
ln -s /dev/null null.png
run "$BIN" bake h.png "${bake_fast[@]}" --ssbump null.png
MSG="symbolic link" finish
begin 32.2c "bake --ssbump materials/s.vtf --vmt FIFO.vmt"
mkdir materials && mkfifo materials/m.vmt
run "$BIN" bake h.png "${bake_fast[@]}" --ssbump materials/s.vtf --vmt materials/m.vmt
MSG="is a FIFO" finish
begin 32.2d "bake --out-dir out, where out/h_normal.png is a FIFO"
mkdir out && mkfifo out/h_normal.png
run "$BIN" bake h.png "${bake_fast[@]}" --out-dir out --maps normal,ao
MSG="is a FIFO" finish
begin 32.2e "render -o DEVICE (a node like /dev/null; a link to it unless root)"
if [ $IS_ROOT = 1 ]; then mknod dev.png c 1 3; else ln -s /dev/null dev.png; fi
run "$BIN" render h.png --scale 8 --rays 16 -o dev.png
MSG="dev.png: cannot write" finish
begin 32.2f "bake --depfile DEVICE (like /dev/full): written through, fails"
if [ $IS_ROOT = 1 ]; then mknod full.d c 1 7; else ln -s /dev/full full.d; fi
run "$BIN" bake h.png "${bake_fast[@]}" --normal n.png --depfile full.d
MSG="No space left on device; the maps were written" ALLOW='^n\.png$' finish
begin 32.2g "bake --depfile LINK (-> /proc/self/fd/1) on a pipe: written through"
ln -s /proc/self/fd/1 out.d
run sh -c '"$@" | cat' sh "$BIN" bake h.png "${bake_fast[@]}" --normal n.png --depfile out.d -q
grep -qx 'n.png: h.png' "$OUTF" || bad "the rule did not come through the pipe"
WANT=ok ALLOW='^n\.png$' finish
begin 32.2h "bake --depfile LINK (-> /proc/self/fd/1) on a file: refused"
ln -s /proc/self/fd/1 out.d
run "$BIN" bake h.png "${bake_fast[@]}" --normal n.png --depfile out.d
MSG="symbolic link (to a regular file)" finish

# 32.9: in a 450 MB memory cgroup a 4096 x 4096 bake was killed by the
# kernel with no message. Run in one for real where one can be made here:
# systemd-run's scope, else (as root) a group below this process's own, in
# cgroup v2 or v1's memory hierarchy, removed afterwards.
cgroup_dir=
# cgroup_mount TYPE [OPTION]: where a cgroup file system of TYPE (cgroup2, or
# cgroup with OPTION among its options) is mounted, from mountinfo.
cgroup_mount() {
  awk -v type="$1" -v option="${2:-}" '{
    for (i = 7; i <= NF && $i != "-"; i++) {}
    if ($(i + 1) == type && (option == "" || ("," $(i + 3) ",") ~ ("," option ","))) { print $5; exit }
  }' /proc/self/mountinfo
}
# Never at a hierarchy's root: only below the group this process is in.
make_memory_cgroup() { # LIMIT_BYTES: sets cgroup_dir, or returns 1
  local limit=$1 mount own
  # cgroup v2: a group below this process's own, if memory is delegated to it
  mount=$(cgroup_mount cgroup2)
  own=$(sed -n 's/^0:://p' /proc/self/cgroup)
  if [ -n "$mount" ] && [ "${own:-/}" != / ] && mkdir "$mount$own/bb-hostile-$$" 2>/dev/null; then
    cgroup_dir=$mount$own/bb-hostile-$$
    [ -f "$cgroup_dir/memory.max" ] && echo "$limit" >"$cgroup_dir/memory.max" 2>/dev/null &&
      return 0
    rmdir "$cgroup_dir"
    cgroup_dir=
  fi
  # cgroup v1's memory hierarchy
  mount=$(cgroup_mount cgroup memory)
  own=$(sed -n 's/^[0-9]*:\([^:]*,\)\{0,1\}memory\(,[^:]*\)\{0,1\}://p' /proc/self/cgroup)
  if [ -n "$mount" ] && [ "${own:-/}" != / ] && mkdir "$mount$own/bb-hostile-$$" 2>/dev/null; then
    cgroup_dir=$mount$own/bb-hostile-$$
    echo "$limit" >"$cgroup_dir/memory.limit_in_bytes" 2>/dev/null && return 0
    rmdir "$cgroup_dir"
    cgroup_dir=
  fi
  return 1
}
begin 32.9a "bake 4096 x 4096 in a 450 MB memory cgroup"
hx make flat_png h4096.png 4096 4096
if command -v systemd-run >/dev/null 2>&1 && systemd-run --scope -q -p MemoryMax=450M true 2>/dev/null; then
  run systemd-run --scope -q -p MemoryMax=450M "$BIN" bake h4096.png --scale 8 -o r
  MSG="is available (cgroup memory" finish
elif make_memory_cgroup 471859200; then
  run sh -c 'echo $$ >"$0/cgroup.procs" && exec "$@"' "$cgroup_dir" "$BIN" bake h4096.png --scale 8 -o r
  rmdir "$cgroup_dir" 2>/dev/null
  MSG="is available (cgroup memory" finish
else
  skip 32.9a "bake in a 450 MB memory cgroup" "no systemd, and no cgroup (v2 or v1) can be made here"
fi

# 32.10: render --normal n4096.png --tile 8 ran 62 s at 16 GB; an 8192 map
# tiled 8 times was refused only after 8 s and 1.7 GB. The picture is now
# worked out from the headers (under the harness's 6 GB address space the
# first cannot fit).
begin 32.10a "render --normal n4096.png --mode normal --tile 8 (6 GB address space)"
hx make flat_png n4096.png 4096 4096 3
run "$BIN" render --normal n4096.png --mode normal --tile 8 -o big.png
TMAX=3 MMAX=300 MSG="a 32768 x 32768 render needs about" finish
begin 32.10b "render --normal n8192.png --tile 8"
hx make flat_png n8192.png 8192 8192 3
run "$BIN" render --normal n8192.png --tile 8 --mode normal -o big.png
WANT_RC=2 TMAX=3 MMAX=300 MSG="over the maximum" finish

# ------------------------------------------------------------- minor

begin m1 "compare of an image holding NaN with itself"
hx make nan_tiff nan.tif
run "$BIN" compare nan.tif nan.tif
WANT=ok finish

begin m2 "renderbumpflat --height of a flat model: no --scale 0"
hx make flat_obj flat.obj
run "$BIN" renderbumpflat flat.obj --size 32 32 --height fh.png -o fn.tga
NOTMSG="--scale 0" WANT=ok ALLOW='^f[hn]\.' outcome
if scale=$(grep -ao 'scale [0-9.e+-]*' "$OUTF" "$ERRF" | head -n 1 | awk '{ print $2 }') &&
  grep -qa -- '--scale' "$OUTF" "$ERRF"; then
  "$BIN" bake fh.png --scale "$scale" --normal "$LOG/m2.png" -q >/dev/null 2>&1 ||
    bad "the suggested --scale $scale is refused by bake"
fi
report

# ---------------------------------------------------- 32: the cluster path

# 32.6: a malformed --scheduler gave a 27-44-line traceback and exit 1; it is
# a usage error (one line, exit 2) found before connecting. A refused
# connection took Dask's 30 s; it is one line at once.
if "$PY" -c 'import distributed' 2>/dev/null; then
  ids=(a b c d e f)
  n=0
  for address in garbage "" "tcp://[::1" inproc://x tcp://127.0.0.1:8786/path tcp://127.0.0.1:99999; do
    begin "32.6${ids[n]}" "bake --scheduler '$address'"
    n=$((n + 1))
    TLIM=120 run "$BIN" bake h.png --scale 8 --normal n.png --scheduler "$address"
    WANT_RC=2 TMAX=15 MSG="--scheduler" finish
  done
  begin 32.6g "bake --scheduler ADDRESS where nothing listens"
  port=$("$PY" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  TLIM=120 run "$BIN" bake h.png --scale 8 --normal n.png --scheduler "tcp://127.0.0.1:$port"
  TMAX=15 MSG="connection refused" finish
  # A port that accepts and never speaks Dask: the connection's own bound
  # (10 s), not Dask's 30 s. (The test suite asserts which bound fired.)
  begin 32.6h "bake --scheduler ADDRESS that accepts and never answers"
  LISTENER=$( ("$PY" -c 'import socket, time
s = socket.socket(); s.bind(("127.0.0.1", 0)); s.listen(8)
print(s.getsockname()[1], flush=True); time.sleep(120)' >"$W/32.6h.port" 2>/dev/null & echo $!) )
  for _ in $(seq 100); do [ -s "$W/32.6h.port" ] && break; sleep 0.1; done
  TLIM=120 run "$BIN" bake h.png --scale 8 --normal n.png --scheduler "tcp://127.0.0.1:$(cat "$W/32.6h.port")"
  kill "$LISTENER" 2>/dev/null
  TMAX=25 MSG="no Dask scheduler answered within 10 s" finish
else
  skip 32.6 "bake --scheduler: malformed and refused addresses" "no python3-distributed"
fi

# 32.7, 32.8: a scheduler and one worker (no nanny) on 127.0.0.1, killed or
# left alone while a batch of 60 maps runs: the scheduler killed gave a
# 62-127-line traceback after 35 s, the only worker killed a hang, Ctrl-C
# exit 130 but the workers went on writing. Each is one line, files whole,
# no temporary, and after Ctrl-C nothing is written once the client is gone.
cluster_start() {
  port=$("$PY" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  ADDRESS=tcp://127.0.0.1:$port
  # started from a command substitution: not jobs of this shell, which
  # would print a line when one is killed
  SCHED=$( (cd "$C" && exec "$PY" -m distributed.cli.dask_scheduler --host 127.0.0.1 \
    --port "$port" --no-dashboard) >"$LOG/$ID.scheduler" 2>&1 & echo $!)
  WORKER=$( (cd "$C" && PYTHONPATH=$ROOT/python exec "$PY" -m distributed.cli.dask_worker \
    "$ADDRESS" --nthreads 1 --no-nanny --memory-limit 0 --no-dashboard \
    --local-directory "$W/dask-$ID") >"$LOG/$ID.worker" 2>&1 & echo $!)
  "$PY" -c 'import sys, distributed
with distributed.Client(sys.argv[1], timeout=120) as c: c.wait_for_workers(1, timeout=120)' \
    "$ADDRESS" >/dev/null 2>&1
}
cluster_stop() {
  kill "$SCHED" "$WORKER" 2>/dev/null
  for _ in $(seq 100); do kill -0 "$SCHED" "$WORKER" 2>/dev/null || break; sleep 0.1; done
  kill -9 "$SCHED" "$WORKER" 2>/dev/null
}
# after_files N SIGNAL PID: sends SIGNAL to PID once out/ holds N files.
after_files() {
  (for _ in $(seq 1200); do
    [ "$(ls out 2>/dev/null | wc -l)" -ge "$1" ] && { kill -s "$2" "$3"; exit; }
    sleep 0.1
  done) &
}
whole() { # every output read back, no temporary
  [ -n "$(find out -name '.bb-tmp*' 2>/dev/null)" ] && bad "a temporary was left"
  for f in out/*.png; do
    [ -e "$f" ] && ! "$BIN" info "$f" >/dev/null 2>&1 && bad "$f is not whole"
  done
}
if "$PY" -c 'import distributed' 2>/dev/null; then
  begin 32.7a "bake DIR --scheduler: the scheduler killed mid-batch"
  mkdir in && for i in $(seq -w 1 60); do cp h.png "in/h$i.png"; done
  cluster_start
  after_files 3 KILL "$SCHED"
  TLIM=120 run "$BIN" bake in --scale 8 --out-dir out -q --scheduler "$ADDRESS"
  cluster_stop
  whole
  TMAX=60 MSG="the Dask cluster was lost" ALLOW='^out(/|$)' finish

  begin 32.7b "bake DIR --scheduler: the only worker killed mid-batch"
  mkdir in && for i in $(seq -w 1 60); do cp h.png "in/h$i.png"; done
  cluster_start
  after_files 3 KILL "$WORKER"
  TLIM=120 run "$BIN" bake in --scale 8 --out-dir out -q --scheduler "$ADDRESS"
  cluster_stop
  whole
  TMAX=60 MSG="no worker left" ALLOW='^out(/|$)' finish

  begin 32.8a "bake DIR --scheduler: Ctrl-C, then nothing more is written"
  mkdir in && for i in $(seq -w 1 60); do cp h.png "in/h$i.png"; done
  cluster_start
  # SIGINT as a terminal sends it: a background job of a script ignores
  # SIGINT, so a small Python parent starts the bake with it restored.
  TLIM=120 run "$PY" -c 'import os, signal, subprocess, sys, time
bake = subprocess.Popen(sys.argv[1:], preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
while bake.poll() is None and len(os.listdir("out") if os.path.isdir("out") else ()) < 3:
    time.sleep(0.05)
bake.send_signal(signal.SIGINT)
rc = bake.wait()
sys.exit(128 - rc if rc < 0 else rc)' "$BIN" bake in --scale 8 --out-dir out -q --keep-going --scheduler "$ADDRESS"
  at_exit=$(ls out | wc -l)
  sleep 10
  [ "$(ls out | wc -l)" = "$at_exit" ] || bad "$at_exit files at exit, $(ls out | wc -l) 10 s later"
  cluster_stop
  whole
  SIGOK=1 WANT_RC=130 FAIL_LINES="0 1" TMAX=60 ALLOW='^out(/|$)' finish
else
  skip 32.7 "bake --scheduler: a cluster lost, Ctrl-C" "no python3-distributed"
fi

# ------------------------------------------------------------ 39: the server
#
# `bumpbake serve` probed as a server (tools/hostile_serve.py, which prints
# one line per case in this script's form): a port already taken, framing,
# slow clients, 1,000 connections, event streams dropped, one address's
# share, stalled downloads, concurrent writes, malformed HTTP, the
# controls, a folder moved under the watch, names a shell takes apart;
# serve alive, the page loading during each attack, its RSS under the
# documented bound. Traffic to 127.0.0.1 only.
serve_finished=0
while IFS= read -r line; do
  case $line in
    *" cases tried, "*) serve_finished=1 ;;
    *"NOT CLEAN"*) printf '%s\n' "$line"; tried=$((tried + 1)); not_clean_ids+=("${line%% *}") ;;
    *" CLEAN "*) printf '%s\n' "$line"; tried=$((tried + 1)); clean=$((clean + 1)) ;;
    *) printf '%s\n' "$line" ;;
  esac
done < <(cd "$W" && "$PY" "$ROOT/tools/hostile_serve.py" "$BIN" 2>&1)
if [ "$serve_finished" != 1 ]; then
  tried=$((tried + 1))
  not_clean_ids+=("39")
  echo "39    tools/hostile_serve.py did not finish                            NOT CLEAN"
fi

[ ${#not_clean_ids[@]} -gt 0 ] && echo "not clean: ${not_clean_ids[*]}"
echo "$tried cases tried, $clean clean$([ $skipped -gt 0 ] && echo ", $skipped skipped")"
[ $clean = $tried ] && [ $skipped = 0 ]
