#!/usr/bin/env bash
# link_order.sh PROBE: prints the shared libraries PROBE loads, one path a
# line, the library the most symbol lookups end in first (ties by path).
#
# Why: OpenImageIO on Debian 12 loads about 260 libraries, and most of a
# bumpbake process's start-up (0.29 s of 0.35 s of CPU) is the dynamic
# linker looking up symbols: each lookup walks the libraries in load order
# until one defines the symbol, and 57,000 of the 158,000 end in OpenVDB,
# deep in that order. Named first on the link line, in this order, the
# walks are short: bumpbake --version's CPU halves. The libraries are those
# loaded anyway, so nothing more is loaded; every symbol of bumpbake's own
# code binds where it did, and a symbol several libraries define binds to
# one of its identical copies (C++ templates, libm's frexp in libc).
#
# Prints nothing (and exits 0) where LD_DEBUG is not honoured: the link is
# then the plain one.
set -uo pipefail
probe=${1:?usage: tools/link_order.sh PROBE}
dir=$(mktemp -d "${TMPDIR:-/tmp}/bb_link_order.XXXXXX") || exit 0
trap 'rm -rf "$dir"' EXIT
LD_DEBUG=bindings LD_DEBUG_OUTPUT="$dir/bind" "$probe" >/dev/null 2>&1 || exit 0
cat "$dir"/bind.* 2>/dev/null |
  sed -n 's/.* to \(\/[^ ]*\) \[[0-9]*\]: normal symbol.*/\1/p' |
  grep -v -e '/ld-linux' -e "^$(readlink -f "$probe")\$" |
  sort | uniq -c | sort -k1,1nr -k2,2 | awk '{print $2}'
