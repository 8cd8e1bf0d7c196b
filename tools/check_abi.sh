#!/usr/bin/env bash
# check_abi.sh: the shared library's ABI against the one stored at the last
# release, judged as Debian judges a library (libabigail's abidw and
# abidiff, Debian's abigail-tools).
#
#   check_abi.sh check STORED.abi LIB.so HEADERS_DIR [SUPPRESSIONS]
#   check_abi.sh dump LIB.so HEADERS_DIR OUT.abi
#
# Only the types of the public headers in HEADERS_DIR count, so the
# library's private structs may change freely. `check`:
#   - the same soname as the stored one: only additions are allowed
#     (abidiff --no-added-syms finds nothing); a function removed or
#     changed, or a public struct changed, fails, naming it;
#   - a new soname: allowed only when the old one had to go (that abidiff
#     finds a change); a soname raised for nothing fails too, so the soname
#     changes exactly when programs built against the last release break.
# SUPPRESSIONS is abidiff's file of changes declared harmless. `dump`
# writes what `check` compares with, with the same abidw flags (`make
# abi-dump` at a release). Exits 0, 1 (the ABI check failed) or 2.
set -uo pipefail

# One set of flags for the stored dump and the current one: two dumps made
# otherwise differ in ways abidiff reports.
abidw_flags=(--drop-private-types --exported-interfaces-only --no-corpus-path --no-show-locs
             --no-comp-dir-path --type-id-style hash)

usage() {
  echo "usage: check_abi.sh check STORED.abi LIB.so HEADERS_DIR [SUPPRESSIONS]" >&2
  echo "       check_abi.sh dump LIB.so HEADERS_DIR OUT.abi" >&2
  exit 2
}
dump() { # LIB HEADERS OUT
  abidw "${abidw_flags[@]}" --headers-dir "$2" --out-file "$3" "$1" ||
    { echo "check_abi: abidw failed on $1" >&2; exit 2; }
}
soname_of() { grep -o -m1 "soname='[^']*'" "$1" | cut -d"'" -f2; }

mode=${1:-}
case $mode in
dump)
  [ $# -eq 4 ] || usage
  dump "$2" "$3" "$4"
  echo "check_abi: stored the ABI of $(soname_of "$4") in $4"
  exit 0 ;;
check) [ $# -eq 4 ] || [ $# -eq 5 ] || usage ;;
*) usage ;;
esac
stored=$2 lib=$3 headers=$4 suppressions=${5:-}
[ -f "$stored" ] || { echo "check_abi: no stored ABI $stored (make abi-dump writes it)" >&2; exit 2; }
tmp=$(mktemp -d) && trap 'rm -rf "$tmp"' EXIT
dump "$lib" "$headers" "$tmp/current.abi"
old=$(soname_of "$stored") new=$(soname_of "$tmp/current.abi")
diff_flags=(--no-added-syms --no-show-locs)
[ -n "$suppressions" ] && diff_flags+=(--suppressions "$suppressions")
# The soname is judged below, on its own: the types and functions are
# compared as if the stored dump had the new one (abidiff alone calls any
# soname change incompatible).
sed "s/soname='$old'/soname='$new'/" "$stored" >"$tmp/stored.abi"
abidiff "${diff_flags[@]}" "$tmp/stored.abi" "$tmp/current.abi" >"$tmp/report" 2>&1
rc=$?
[ $((rc & 3)) -eq 0 ] || { cat "$tmp/report" >&2; echo "check_abi: abidiff failed (exit $rc)" >&2; exit 2; }
# What was added since, for the record (additions never fail).
added=$(abidiff --no-show-locs ${suppressions:+--suppressions "$suppressions"} \
  "$tmp/stored.abi" "$tmp/current.abi" 2>/dev/null | grep -o -m1 '[0-9]* Added function' | cut -d' ' -f1)
if [ "$old" = "$new" ]; then
  if [ "$rc" -eq 0 ]; then
    echo "check_abi: $new keeps the ABI stored in $stored (functions added since: ${added:-0})"
    exit 0
  fi
  cat "$tmp/report"
  echo "check_abi: $new breaks the ABI stored in $stored (the last release's): abidiff above."
  echo "check_abi: undo the change, or make it a new ABI: raise BB_ABI_VERSION in"
  echo "check_abi: include/bumpbake.h (the soname follows; SONAME in python/bumpbake/_library.py too)."
  echo "check_abi: One raise covers every break until the next release, which stores its ABI (make abi-dump)."
  exit 1
fi
if [ "$rc" -eq 0 ]; then
  echo "check_abi: soname $old -> $new, but nothing breaks the ABI stored in $stored:"
  echo "check_abi: keep $old (BB_ABI_VERSION back as it was; additions keep the soname)"
  exit 1
fi
echo "check_abi: soname $old -> $new for a change that breaks the ABI stored in $stored;"
echo "check_abi: the release stores the new ABI (make abi-dump)"
exit 0
