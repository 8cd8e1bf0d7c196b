#!/usr/bin/env python3
"""check_layers.py [--root DIR] [--families "F1 F2 ..."] OBJECT...: fails when a
family of the library reaches up to a family above it.

The families are the folders of src/, in the order written once in
docs/how-it-works.md ("Layers": a line "core < files < ... < cli < serve"). A
family may use itself and the families before it, never one after it:
- includes: every #include "FAMILY/..." of a file in src/FAMILY2/, and every
  relative one ("../FAMILY/x.h", or "x.h" found beside the file), must name
  FAMILY2 or a family before it;
- calls: an object of src/FAMILY2/ may use a global symbol (nm) defined by
  an object of FAMILY2 or of a family before it, not one after it. The
  program's entry (main.o) is no family's: it links the clients (the CLI
  and serve, above it) into one program, and may call any of them.
The clients (cli, serve) close the order; the library is the rest.
It also fails when a folder of src/ holding sources is missing from the
order, when --families (the Makefile's FAMILIES) or the sections of
include/bumpbake.h are not the order without the clients, or when the README's
"Layout" table lists the folders in another order.
`make check-layers` runs it over the library's and the CLI's objects; it
prints every offence and exits 1, or prints one line and exits 0.
"""
import argparse
import os
import re
import sys

from object_symbols import links

ORDER_LINE = re.compile(r"^\s*(?:`|    )?([a-z]+(?:\s*<\s*[a-z]+)+)`?\s*$")
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)
SOURCE_EXT = (".c", ".cpp", ".h")
# The families that are clients of the library (on its public header): the
# last of the order, in neither the Makefile's FAMILIES nor the header.
CLIENTS = ("cli", "serve")
# The program's entry: it links the clients together, so it calls up.
PROGRAM_ENTRY = "main.o"


def family_order(root):
    """The families in order, from docs/how-it-works.md's "Layers" section."""
    path = os.path.join(root, "docs", "how-it-works.md")
    in_section = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("## "):
                in_section = line.strip() == "## Layers"
                continue
            m = ORDER_LINE.match(line.rstrip("\n")) if in_section else None
            if m:
                return [w.strip() for w in m.group(1).split("<")]
    raise SystemExit(f"check_layers: {path} has no line 'core < ... < cli < serve' under '## Layers'")


def readme_order(root):
    """The src/ folders of the README's "Layout" table, in its order."""
    folders, in_section = [], False
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("## "):
                in_section = line.strip() == "## Layout"
                continue
            m = re.match(r"^\| `src/([a-z]+)` \|", line) if in_section else None
            if m:
                folders.append(m.group(1))
    return folders


def header_order(root):
    """The families of the public header's sections, in its order: each
    section opens with a rule of '=' and a line " * FAMILY: what it holds"."""
    path = os.path.join(root, "include", "bumpbake.h")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"^/\* =+\n \* ([a-z]+):", text, re.M)


def family_of(path, src):
    """The family a path under src/ belongs to, or None."""
    rel = os.path.relpath(os.path.normpath(path), src)
    if rel.startswith("..") or os.sep not in rel:
        return None
    return rel.split(os.sep, 1)[0]


def include_offences(src, rank):
    offences, count = [], 0
    for family in rank:
        folder = os.path.join(src, family)
        if not os.path.isdir(folder):
            continue
        for dirpath, _, names in os.walk(folder):
            for name in sorted(names):
                if not name.endswith(SOURCE_EXT):
                    continue
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                for m in INCLUDE.finditer(text):
                    count += 1
                    target = m.group(1)
                    beside = os.path.join(dirpath, target)
                    if target.startswith(".") or os.path.exists(beside):
                        other = family_of(beside, src)  # relative to the file
                    else:
                        other = family_of(os.path.join(src, target), src)
                    if other in rank and rank[other] > rank[family]:
                        line = text.count("\n", 0, m.start()) + 1
                        offences.append(f"{os.path.relpath(path, os.path.dirname(src))}:{line}: includes \"{target}\""
                                        f" ({family} reaches up to {other})")
    return offences, count


def call_offences(objects, rank):
    """Objects are build/.../src/FAMILY/NAME.o: their family is the folder."""
    family = {o: os.path.basename(os.path.dirname(o)) for o in objects}
    defined_by, uses = links(objects)
    offences = []
    for obj in objects:
        if os.path.basename(obj) == PROGRAM_ENTRY:
            continue
        for sym in sorted(uses[obj]):
            other = defined_by.get(sym)
            if not other:
                continue
            a, b = family[obj], family[other]
            if a in rank and b in rank and rank[b] > rank[a]:
                offences.append(f"{os.path.relpath(obj)} calls {sym} of {os.path.relpath(other)}"
                                f" ({a} reaches up to {b})")
    return offences


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--families", help="the Makefile's FAMILIES, checked against the order")
    parser.add_argument("objects", nargs="*")
    args = parser.parse_args(argv)
    root = os.path.normpath(args.root)
    src = os.path.join(root, "src")
    order = family_order(root)
    rank = {f: i for i, f in enumerate(order)}
    offences = []
    for name in sorted(os.listdir(src)):
        folder = os.path.join(src, name)
        if os.path.isdir(folder) and name not in rank and \
                any(n.endswith(SOURCE_EXT) for n in os.listdir(folder)):
            offences.append(f"src/{name}/ is not in the order of docs/how-it-works.md")
    for name in order:
        if not os.path.isdir(os.path.join(src, name)):
            offences.append(f"docs/how-it-works.md names {name}, which is not a folder of src/")
    library = [f for f in order if f not in CLIENTS]
    if args.families is not None and args.families.split() != library:
        offences.append(f"the Makefile's FAMILIES ({args.families}) are not the order of "
                        f"docs/how-it-works.md without {' and '.join(CLIENTS)} ({' '.join(order)})")
    readme = readme_order(root)
    if readme and readme != order:
        offences.append(f"README.md's Layout lists {' '.join(readme)}, not {' '.join(order)}")
    header = header_order(root)
    if header != library:
        offences.append(f"include/bumpbake.h's sections are {' '.join(header)}, not the order "
                        f"without {' and '.join(CLIENTS)} ({' '.join(library)})")
    includes, count = include_offences(src, rank)
    offences += includes
    offences += call_offences(args.objects, rank)
    for line in offences:
        print("check_layers: " + line)
    if offences:
        print(f"check_layers: {len(offences)} offence(s) against the order {' < '.join(order)}")
        return 1
    print(f"check_layers: {' < '.join(order)}: {count} includes and the calls of "
          f"{len(args.objects)} objects point down")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
