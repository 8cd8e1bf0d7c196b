#!/usr/bin/env bash
# check_install.sh: `make install` as a user runs it, checked. `make test`
# runs it (as `make check-install`) after building; it takes a few seconds.
#
#   1. installs into a temporary prefix and checks the files and symlinks;
#   2. builds tests/install_client.c with `pkg-config --cflags --libs
#      bumpbake` (shared; nothing else: the prefix's rpath must come from
#      bumpbake.pc, and --cflags must be the include directory alone) and
#      with `pkg-config --static --libs` against libbumpbake.a, runs both
#      and checks they print "ok";
#   3. checks libbumpbake.so exports exactly the functions of bumpbake.h and
#      bumpbake_cluster.h;
#   4. checks the man page renders without warnings and names every command
#      and option the installed bumpbake's --help lists;
#   5. a staged install (DESTDIR) lands under DESTDIR with PREFIX's paths;
#   6. the installed Python package imports and bakes with PYTHONPATH set to
#      its dist-packages and nothing else (no BUMPBAKE_LIBRARY, no
#      PKG_CONFIG_PATH): it loads the installed library by itself; the
#      installed program's `bake --scheduler` finds it with no PYTHONPATH,
#      and imports nothing from the working directory.
#
# Environment: MAKE (make), DEBUG (0), BUILD (build), CC (cc), PYTHON
# (/usr/bin/python3). A DEBUG=1 library is sanitized, so the clients are
# built with the sanitizers too, and Python runs with their runtimes
# preloaded.
set -euo pipefail

cd "$(dirname "$0")/.."
make=${MAKE:-make}
debug=${DEBUG:-0}
cc=${CC:-cc}
python=${PYTHON:-/usr/bin/python3}
client_flags=(-std=c11 -Wall -Wextra -Werror)
[ "$debug" = 1 ] && client_flags+=("-fsanitize=address,undefined")
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/bumpbake-install.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
failures=0
fail() { echo "check_install: FAILED: $*" >&2; failures=$((failures + 1)); }
pass() { echo "check_install: $*"; }

# ------------------------------------------------------------ 1. install
if ! "$make" --no-print-directory install DEBUG="$debug" PREFIX="$prefix" LDCONFIG=: \
  >"$tmp/install.log" 2>&1; then
  cat "$tmp/install.log" >&2
  echo "check_install: FAILED: make install PREFIX=$prefix" >&2
  exit 1
fi
for f in bin/bumpbake lib/libbumpbake.a lib/libbumpbake.so include/bumpbake.h include/bumpbake_cluster.h \
  lib/pkgconfig/bumpbake.pc share/man/man1/bumpbake.1; do
  [ -e "$prefix/$f" ] || fail "make install did not install $f"
done
soname=$(readelf -d "$prefix/lib/libbumpbake.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
{ [ -L "$prefix/lib/$soname" ] && [ -f "$prefix/lib/$soname" ]; } ||
  fail "lib/$soname (the soname) is not a symlink to the library"
[ "$(readlink "$prefix/lib/libbumpbake.so")" = "$soname" ] ||
  fail "lib/libbumpbake.so does not point at $soname"
version=$("$prefix/bin/bumpbake" --version) || fail "installed bumpbake --version failed"
pass "installed $version, soname $soname, into a temporary prefix"

# ------------------------------------------------------ 2. pkg-config client
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
cflags=$(pkg-config --cflags bumpbake)
libs=$(pkg-config --libs bumpbake)
libdir=$(pkg-config --variable=libdir bumpbake)
[ "$(pkg-config --modversion bumpbake)" = "${version#bumpbake }" ] ||
  fail "bumpbake.pc's version $(pkg-config --modversion bumpbake) is not ${version#bumpbake }"
# bumpbake.h needs no other header: --cflags is the include directory alone
# (Requires.private once added Debian's libsquish.pc's stray -I/include).
[ "$(echo $cflags)" = "-I$prefix/include" ] || # (echo: pkg-config ends with a space)
  fail "pkg-config --cflags bumpbake is '$cflags', not -I$prefix/include"
# The client itself uses libm (exp, sqrt); pkg-config's output is split on
# purpose. Nothing but pkg-config's flags: the temporary prefix is not one
# the loader searches, so the client runs only if Libs carries its rpath.
# shellcheck disable=SC2086
"$cc" "${client_flags[@]}" $cflags tests/install_client.c -o "$tmp/client" $libs \
  -lm || fail "cc \$(pkg-config --cflags --libs bumpbake) failed"
if [ -x "$tmp/client" ]; then
  # (ldd's output is kept first: grep -q quitting early would fail the pipe)
  loaded=$(env -u LD_LIBRARY_PATH ldd "$tmp/client")
  grep -q "$soname => $libdir/" <<<"$loaded" || fail "the client does not load $libdir/$soname"
  env -u LD_LIBRARY_PATH "$tmp/client" >"$tmp/client.out" 2>&1 || true
  if [ "$(tail -n1 "$tmp/client.out")" = ok ]; then
    pass "client built with pkg-config --cflags --libs bumpbake: ok"
  else
    cat "$tmp/client.out" >&2
    fail "the shared client's checks"
  fi
fi
# A static link of libbumpbake.a with what Requires.private/Libs.private add.
static_libs=$(pkg-config --static --libs bumpbake | sed "s|-lbumpbake|$libdir/libbumpbake.a|")
# shellcheck disable=SC2086
"$cc" "${client_flags[@]}" $cflags tests/install_client.c -o "$tmp/client-static" \
  $static_libs -lm || fail "cc with pkg-config --static --libs bumpbake failed"
if [ -x "$tmp/client-static" ]; then
  loaded=$(ldd "$tmp/client-static")
  ! grep -q libbumpbake <<<"$loaded" || fail "the static client loads libbumpbake.so"
  "$tmp/client-static" >"$tmp/client-static.out" 2>&1 || true
  if [ "$(tail -n1 "$tmp/client-static.out")" = ok ]; then
    pass "client linked with libbumpbake.a and pkg-config --static: ok"
  else
    cat "$tmp/client-static.out" >&2
    fail "the static client's checks"
  fi
fi

# ------------------------------------------------------ 3. exported symbols
# (typedef lines left out: "typedef bb_status (*name)(...)" is no function.)
# Besides them, png_set_error_fn and png_create_write_struct (src/image/
# png_hooks.c: they set up the libpng structs OpenImageIO makes, so they
# must be found before libpng's).
{ cat "$prefix/include/bumpbake.h" "$prefix/include/bumpbake_cluster.h" | grep -v '^[[:space:]]*typedef' |
    grep -o '\bbb_[a-z0-9_]*[[:space:]]*(' | tr -d '( '
  echo png_set_error_fn; echo png_create_write_struct; } | sort -u >"$tmp/header.sym"
# Exports only: global and weak definitions (upper-case types, i and u).
# A local entry of the dynamic table (lower-case t: the linker leaves one
# for a template instance another library of the link defines too) binds
# nothing outside the library.
nm -D --defined-only "$prefix/lib/libbumpbake.so" | awk '$2 ~ /^[A-Ziu]$/ { print $3 }' |
  sort -u >"$tmp/so.sym"
if cmp -s "$tmp/header.sym" "$tmp/so.sym"; then
  pass "libbumpbake.so exports the functions of bumpbake.h, bumpbake_cluster.h and its two libpng hooks, nothing else ($(wc -l <"$tmp/so.sym"))"
else
  fail "exports differ from the functions of bumpbake.h and bumpbake_cluster.h (< headers only, > .so only):"
  diff "$tmp/header.sym" "$tmp/so.sym" | grep '^[<>]' >&2 || true
fi

# The installed headers name no internal (bb__): a reader of them cannot
# call one, so their comments say what it does or name the public call.
internal=$(grep -n '\bbb__[a-z0-9_]*' "$prefix/include/bumpbake.h" "$prefix/include/bumpbake_cluster.h" || true)
if [ -z "$internal" ]; then
  pass "bumpbake.h and bumpbake_cluster.h name no internal (bb__)"
else
  fail "the installed headers name internals (bb__), which their readers cannot call:"
  printf '%s\n' "$internal" >&2
fi

# The OpenImageIO module (src/image/oiio_module.h): beside the library,
# exporting its entry only; the installed program (libbumpbake.a with
# LIBDIR compiled in) loads it for its first image, and without it says so
# in one line naming it.
module=$prefix/lib/libbumpbake-oiio.so.${version#bumpbake }
if [ -f "$module" ]; then
  exports=$(nm -D --defined-only "$module" | awk '$2 ~ /^[A-Ziu]$/ { print $3 }' | sort -u)
  [ "$exports" = bb__oiio_module_entry ] &&
    pass "lib/$(basename "$module") exports its entry only" ||
    fail "lib/$(basename "$module") exports more than bb__oiio_module_entry: $exports"
  "$prefix/bin/bumpbake" info fixtures/bricks_128x64.png >"$tmp/info.out" 2>&1 &&
    pass "the installed bumpbake reads an image through lib/$(basename "$module")" ||
    { cat "$tmp/info.out" >&2; fail "the installed bumpbake info of a PNG"; }
  mv "$module" "$module.aside"
  code=0
  "$prefix/bin/bumpbake" info fixtures/bricks_128x64.png >/dev/null 2>"$tmp/info.err" || code=$?
  mv "$module.aside" "$module"
  if [ "$code" -ne 0 ] && [ "$(wc -l <"$tmp/info.err")" -eq 1 ] && grep -qF "$module" "$tmp/info.err"; then
    pass "without its module the installed bumpbake says so in one line: $(cat "$tmp/info.err")"
  else
    cat "$tmp/info.err" >&2
    fail "without its module the installed bumpbake did not fail in one line naming $module"
  fi
else
  fail "make install did not install lib/$(basename "$module") beside the library"
fi

# ----------------------------------------------------------- 4. man page
man_page=$prefix/share/man/man1/bumpbake.1
if command -v groff >/dev/null 2>&1; then
  warnings=$(groff -man -ww -z "$man_page" 2>&1)
  [ -z "$warnings" ] || fail "groff warns about the man page: $warnings"
  groff -man -Tascii -P-cbou "$man_page" 2>/dev/null >"$tmp/man.txt"
  bin=$prefix/bin/bumpbake
  missing=()
  commands=$("$bin" --help | awk '/^commands:/ { on = 1; next } on && NF == 0 { exit } on { print $1 }')
  for c in $commands; do
    grep -q "^ *bumpbake $c\b" "$tmp/man.txt" || missing+=("command $c")
    # Every option the command's --help names (long ones, and short-only ones).
    for o in $("$bin" "$c" --help | grep -oE '(^|[[ ])--?[A-Za-z][A-Za-z0-9-]*' | tr -d '[ ' | sort -u); do
      grep -qe "$o\b" "$tmp/man.txt" || missing+=("$c $o")
    done
  done
  if [ "${#missing[@]}" -eq 0 ]; then
    pass "man page: no groff warnings; names every command and option of --help"
  else
    fail "docs/bumpbake.1 does not describe: ${missing[*]}"
  fi
else
  echo "check_install: groff not found; man page not checked"
fi

# --------------------------------------------------------- 5. staged install
stage=$tmp/stage
"$make" --no-print-directory install DEBUG="$debug" DESTDIR="$stage" PREFIX=/usr \
  LDCONFIG=: >"$tmp/stage.log" 2>&1 || fail "make install DESTDIR=... PREFIX=/usr"
if [ -f "$stage/usr/lib/pkgconfig/bumpbake.pc" ] && [ -e "$stage/usr/bin/bumpbake" ] &&
  grep -qx 'prefix=/usr' "$stage/usr/lib/pkgconfig/bumpbake.pc"; then
  pass "staged install (DESTDIR, PREFIX=/usr) lands under DESTDIR with /usr paths"
  ! grep -q '^Libs:.*rpath' "$stage/usr/lib/pkgconfig/bumpbake.pc" ||
    fail "bumpbake.pc for PREFIX=/usr adds an rpath (the loader searches /usr/lib)"
else
  fail "staged install: files or bumpbake.pc's prefix not as expected"
fi
# The package's record names where the library will be, not the stage.
staged_record=$stage/usr/lib/python3/dist-packages/bumpbake/_install.py
if grep -qx "LIBRARY = \"/usr/lib/$soname\"" "$staged_record" 2>/dev/null; then
  pass "staged install: the Python package in /usr/lib/python3/dist-packages loads /usr/lib/$soname"
else
  fail "staged install: $staged_record does not name /usr/lib/$soname"
fi

# ------------------------------------------------------ 6. Python package
site=$prefix/lib/python3/dist-packages
if [ ! -f "$site/bumpbake/__init__.py" ]; then
  fail "make install did not install the Python package into $site"
elif ! "$python" -c 'import cffi, numpy' 2>/dev/null; then
  echo "check_install: $python lacks cffi or numpy; the Python package not checked"
else
  preload=()
  if [ "$debug" = 1 ]; then
    preload=("LD_PRELOAD=$("$cc" -print-file-name=libasan.so) $("$cc" -print-file-name=libubsan.so)"
      ASAN_OPTIONS=detect_leaks=0)
  fi
  # From /, with nothing set but PYTHONPATH (and PATH for the interpreter).
  if out=$(cd / && env -i PATH=/usr/bin:/bin PYTHONPATH="$site" "${preload[@]}" "$python" -c '
import os, sys
import numpy as np
import bumpbake
assert os.path.realpath(bumpbake.library_path) == os.path.realpath(sys.argv[1]), bumpbake.library_path
maps = bumpbake.bake(np.zeros((8, 8), np.float32), 4, outputs=("normal", "ao"), rays=16)
assert (maps["normal"][..., 2] == 1).all() and (maps["ao"] == 1).all()
print("ok", bumpbake.library_path)
' "$prefix/lib/$soname" 2>&1) && [ "${out%% *}" = ok ]; then
    pass "python3 -c 'import bumpbake' with PYTHONPATH=$site alone: bakes, loads ${out#ok }"
  else
    echo "$out" >&2
    fail "the installed Python package does not import or bake with PYTHONPATH alone"
  fi
  # bumpbake.dask, a subpackage, is installed too (it needs python3-distributed)
  if [ ! -f "$site/bumpbake/dask/__init__.py" ]; then
    fail "make install did not install bumpbake.dask into $site"
  elif "$python" -c 'import distributed' 2>/dev/null; then
    if out=$(cd / && env -i PATH=/usr/bin:/bin PYTHONPATH="$site" "${preload[@]}" "$python" \
        -c 'import bumpbake.dask._command; print("ok")' 2>&1) && [ "$out" = ok ]; then
      pass "python3 imports bumpbake.dask (what --scheduler runs) with PYTHONPATH=$site alone"
    else
      echo "$out" >&2
      fail "the installed bumpbake.dask does not run with PYTHONPATH alone"
    fi
    # `bumpbake bake --scheduler` from the installed program: its Python
    # finds the package where make install put it (recorded in the
    # program), with no PYTHONPATH, and imports nothing from the directory
    # it bakes in (a bumpbake/ there would run).
    hostile=$tmp/hostile
    mkdir -p "$hostile/bumpbake"
    cp fixtures/rock06_128.png "$hostile/h.png"
    printf 'open(%s, "w").write("ran")\n' "'$hostile/RAN'" >"$hostile/bumpbake/__init__.py"
    out=$(cd "$hostile" && env -i PATH=/usr/bin:/bin "${preload[@]}" "$prefix/bin/bumpbake" \
      bake h.png --scale 8 --normal n.png --scheduler not-an-address 2>&1) || true
    if [ -e "$hostile/RAN" ]; then
      fail "bumpbake bake --scheduler imported bumpbake/ from the working directory"
    elif grep -q "cannot import bumpbake.dask" <<<"$out"; then
      fail "the installed bumpbake bake --scheduler does not find its package: $out"
    else
      pass "installed bumpbake bake --scheduler: finds the package in $site, nothing from the working directory"
    fi
  fi
fi

if [ "$failures" -gt 0 ]; then
  echo "check_install: $failures check(s) failed" >&2
  exit 1
fi
