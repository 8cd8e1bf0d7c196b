#!/usr/bin/env python3
"""test_check_abi.py: tools/check_abi.sh, with this tree's public header and
abi/bumpbake.abignore, on a small library built against the header and
against copies of it with a public struct changed.

The library's functions take bb_image, bb_option_info and the opaque
bb_job, so their types are in its ABI as in libbumpbake's. Its ABI is
stored as a release's would be (check_abi.sh dump), then the check must:
pass it unchanged and with a function added; fail a field inserted in
bb_image and a function removed, naming them; pass that field with the
soname raised, and fail a soname raised for an addition alone; pass a
field appended to bb_option_info (the suppression) but fail one inserted
at its start and one appended to bb_image; pass a change to the private
definition of bb_job. `make check-abi` runs it after the check itself; it
prints one line, or what failed and exits 1."""
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CHECK = os.path.join(ROOT, "tools", "check_abi.sh")
SUPPRESSIONS = os.path.join(ROOT, "abi", "bumpbake.abignore")
CC = os.environ.get("CC", "cc")
failures = []

LIBRARY = r"""
#include "bumpbake.h"
/* bb_job is opaque in the header: this definition is the library's own. */
struct bb_job {
  int items;
#ifdef PRIVATE_FIELD
  int more;
#endif
};
int bb_demo_width(const bb_image *image) { return image->width; }
const char *bb_demo_help(const bb_option_info *option) { return option->help; }
int bb_demo_items(const bb_job *job) { return job->items; }
#ifndef REMOVE_ONE
int bb_demo_count(void) { return 1; }
#endif
#ifdef ADD_ONE
int bb_demo_added(void) { return 2; }
#endif
"""


def struct_edit(header, name, where, field):
    """The header with field inserted first in struct name, or last."""
    opening = f"typedef struct {name} {{\n"
    closing = f"\n}} {name};"
    assert opening in header and closing in header, f"include/bumpbake.h has no struct {name}"
    if where == "first":
        return header.replace(opening, opening + f"  {field}\n", 1)
    return header.replace(closing, f"\n  {field}" + closing, 1)


def main():
    with open(os.path.join(ROOT, "include", "bumpbake.h"), encoding="utf-8") as f:
        header = f.read()
    with tempfile.TemporaryDirectory(prefix="bb-abi-") as tmp:
        source = os.path.join(tmp, "demo.c")
        with open(source, "w", encoding="utf-8") as f:
            f.write(LIBRARY)

        def headers(name, text=header):
            folder = os.path.join(tmp, name)
            os.makedirs(folder, exist_ok=True)
            with open(os.path.join(folder, "bumpbake.h"), "w", encoding="utf-8") as f:
                f.write(text)
            return folder

        def build(name, include, soname="libdemo.so.0.4", *defines):
            out = os.path.join(tmp, name + ".so")
            subprocess.run([CC, "-g", "-shared", "-fPIC", f"-Wl,-soname,{soname}", f"-I{include}",
                            *[f"-D{d}" for d in defines], "-o", out, source], check=True)
            return out

        def expect(name, lib, include, status, words, suppressions=SUPPRESSIONS):
            r = subprocess.run([CHECK, "check", stored, lib, include, suppressions],
                               capture_output=True, text=True)
            out = r.stdout + r.stderr
            if r.returncode != status or any(not re.search(w, out) for w in words):
                failures.append(f"{name}: exit {r.returncode}, wanted {status} and {words}:\n{out}")

        real = headers("real")
        stored = os.path.join(tmp, "stored.abi")
        subprocess.run([CHECK, "dump", build("release", real), real, stored], check=True,
                       capture_output=True)

        expect("the release again", build("same", real), real, 0, ["keeps the ABI"])
        expect("a function added", build("added", real, "libdemo.so.0.4", "ADD_ONE"), real, 0,
               ["keeps the ABI", "functions added since: 1"])
        expect("a private struct changed", build("private", real, "libdemo.so.0.4", "PRIVATE_FIELD"),
               real, 0, ["keeps the ABI"])

        inserted = headers("inserted", struct_edit(header, "bb_image", "first", "int stride;"))
        expect("a field inserted in bb_image", build("inserted", inserted), inserted, 1,
               ["struct bb_image", "data member insertion", "breaks the ABI", "BB_ABI_VERSION"])
        expect("a function removed", build("removed", real, "libdemo.so.0.4", "REMOVE_ONE"), real, 1,
               ["bb_demo_count", "breaks the ABI"])
        expect("the field with the soname raised", build("raised", inserted, "libdemo.so.0.5"),
               inserted, 0, ["libdemo.so.0.4 -> libdemo.so.0.5", "make abi-dump"])
        expect("the soname raised for an addition", build("needless", real, "libdemo.so.0.5", "ADD_ONE"),
               real, 1, ["nothing breaks the ABI", "keep libdemo.so.0.4"])

        appended = headers("appended", struct_edit(header, "bb_option_info", "last", "int later;"))
        expect("a field appended to bb_option_info", build("appended", appended), appended, 0,
               ["keeps the ABI"])
        expect("the same without the suppressions", build("appended2", appended), appended, 1,
               ["struct bb_option_info", "breaks the ABI"], "")
        first = headers("first", struct_edit(header, "bb_option_info", "first", "int sooner;"))
        expect("a field inserted first in bb_option_info", build("first", first), first, 1,
               ["struct bb_option_info", "breaks the ABI"])
        image_end = headers("image_end", struct_edit(header, "bb_image", "last", "int later;"))
        expect("a field appended to bb_image", build("image_end", image_end), image_end, 1,
               ["struct bb_image", "breaks the ABI"])
    if failures:
        print("test_check_abi: FAILED\n" + "\n".join(failures))
        return 1
    print("test_check_abi: additions and private changes pass; a changed public struct, a removed "
          "function and a needless soname change fail; appending to the descriptions passes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
