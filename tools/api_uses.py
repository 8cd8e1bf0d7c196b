#!/usr/bin/env python3
"""api_uses.py: who uses each function libbumpbake.so exports.

    api_uses.py --shared LIB.so --header H.h... --library OBJ...
                [--client NAME OBJ...]... [--source NAME FILE...]...
                [--python DIR] [--tests NAME OBJ...]... [--table OUT.tsv]
                [--together NAME CLIENT...]... [--both CLIENT CLIENT]...

Reads the exports (nm -D of LIB.so), the public headers (lines, and where
each export is declared, comments left out), the objects of the library
(which file defines each export, which other library files call it), the
objects of each client (their undefined symbols), C sources of clients
built elsewhere (the names they call), the Python package (calls through
_lib.bb_NAME, and parser names handed over as "bb_NAME"; _cdef.py is read
apart, as the declarations cffi knows) and the objects of the tests, tools
and fuzz targets. Prints how many exports each client uses (each
--together group of clients, each --both pair) and how many no client
does; --table writes one row per export saying who uses it.
`make api-report` runs it over this tree's build.
"""
import argparse
import os
import re
import subprocess
import sys

from object_symbols import symbols

CALL = re.compile(r"\b(bb_[a-z0-9_]+)\s*\(")


def exports(shared):
    out = subprocess.run(["nm", "-D", "--defined-only", shared], capture_output=True, text=True,
                         check=True).stdout
    return sorted({f[2] for f in (line.split() for line in out.splitlines())
                   if len(f) == 3 and f[1] in "TW"})


def without_comments(text):
    """C text with its comments blanked, line numbers kept."""
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def declarations(headers):
    """{name: "header:line"} of the functions the headers declare (typedefs
    of function pointers left out), and each header's line count."""
    where, lines = {}, {}
    for path in headers:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        lines[path] = text.count("\n")
        # Preprocessor lines blanked too: a macro is no declaration, and
        # what follows one starts a statement of its own.
        code = re.sub(r"(?m)^[ \t]*#.*(?:\\\n.*)*$", lambda m: re.sub(r"[^\n]", " ", m.group(0)),
                      without_comments(text))
        for m in CALL.finditer(code):
            start = code.rfind("\n", 0, m.start()) + 1
            statement = code[code.rfind(";", 0, m.start()) + 1:m.start()]
            if re.search(r"\btypedef\b", statement) or m.group(1) in where:
                continue
            where[m.group(1)] = f"{os.path.basename(path)}:{code.count(chr(10), 0, start) + 1}"
    return where, lines


def python_calls(folder, names):
    """{name: files} of the package's calls, and the names _cdef.py declares."""
    calls, declared = {}, set()
    for dirpath, _, files in os.walk(folder):
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            path = os.path.join(dirpath, name)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            if name == "_cdef.py":
                declared |= set(CALL.findall(text)) & names
                continue
            rel = os.path.relpath(path, folder)
            for m in re.finditer(r"_lib\.(bb_[a-z0-9_]+)|\"(bb_[a-z0-9_]+)\"", text):
                n = m.group(1) or m.group(2)
                if n in names:
                    calls.setdefault(n, set()).add(rel)
    return calls, declared


def source_calls(paths, names):
    calls = {}
    for path in paths:
        with open(path, encoding="utf-8") as f:
            for n in set(CALL.findall(without_comments(f.read()))) & names:
                calls.setdefault(n, set()).add(os.path.basename(path))
    return calls


def object_calls(objects, names, found):
    calls = {}
    for obj in objects:
        for n in found[obj][1] & names:
            calls.setdefault(n, set()).add(os.path.basename(obj)[:-2])
    return calls


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shared", required=True)
    parser.add_argument("--header", nargs="+", required=True)
    parser.add_argument("--library", nargs="+", required=True)
    parser.add_argument("--python")
    parser.add_argument("--table")
    parser.add_argument("--client", nargs="+", action="append", default=[])
    parser.add_argument("--source", nargs="+", action="append", default=[])
    parser.add_argument("--tests", nargs="+", action="append", default=[])
    parser.add_argument("--together", nargs="+", action="append", default=[])
    parser.add_argument("--both", nargs=2, action="append", default=[])
    args = parser.parse_args(argv)

    names = exports(args.shared)
    nameset = set(names)
    where, header_lines = declarations(args.header)
    objects = list(args.library)
    for group in args.client + args.tests:
        objects += group[1:]
    found = symbols(dict.fromkeys(objects))

    defined_in, library = {}, {}
    for obj in args.library:
        for n in found[obj][0] & nameset:
            defined_in[n] = obj
    for obj in args.library:
        for n in found[obj][1] & nameset:
            if defined_in.get(n) != obj:
                library.setdefault(n, set()).add(os.path.basename(obj)[:-2])

    clients = {}  # client name -> {export: files}, in the order given
    for group in args.client:
        clients[group[0]] = object_calls(group[1:], nameset, found)
    for group in args.source:
        clients[group[0]] = source_calls(group[1:], nameset)
    declared = set()
    if args.python:
        clients["python"], declared = python_calls(args.python, nameset)
    tests = {}
    for group in args.tests:
        for n, files in object_calls(group[1:], nameset, found).items():
            tests.setdefault(n, set()).update(f"{group[0]}/{f}" for f in files)

    by_client = {n for uses in clients.values() for n in uses}
    lone = {}
    for n in by_client:
        users = [c for c, uses in clients.items() if n in uses]
        if len(users) == 1:
            lone[users[0]] = lone.get(users[0], 0) + 1

    def row(label, count, note=""):
        print(f"  {label:<42}{count:>5}" + (f"  {note}" if note else ""))

    others = [n for n in names if not n.startswith("bb_")]
    print(f"api_uses: {args.shared} exports {len(names)} functions"
          + (f" ({len(names) - len(others)} bb_*, {len(others)} others: {' '.join(others)})"
             if others else ""))
    for path, count in header_lines.items():
        print(f"api_uses: {path}: {count} lines")
    undeclared = [n for n in names if n not in where and n.startswith("bb_")]
    if undeclared:
        print(f"api_uses: exports no header declares: {' '.join(undeclared)}")
    print("exports used, by client (alone: used by no other client)")
    for client, uses in clients.items():
        note = f"{lone.get(client, 0)} alone"
        if client == "python" and declared:
            never = len(declared - set(uses))
            note += f"; _cdef.py declares {len(declared)}, {never} never called"
        row(client, len(uses), note)
    joined = dict(clients)
    for group in args.together:
        joined[group[0]] = set().union(*(clients[c].keys() for c in group[1:]))
        row(f"{group[0]} ({' + '.join(group[1:])})", len(joined[group[0]]))
    for group in args.both:
        common = set.intersection(*(set(joined[c]) for c in group))
        row(f"both {' and '.join(group)}", len(common))
    row("any client", len(by_client))
    nobody = [n for n in names if n not in by_client]
    print(f"exports no client uses: {len(nobody)}")
    kinds = {}
    for n in nobody:
        key = " and ".join(([f"{'/'.join(g[0] for g in args.tests)}"] if n in tests else [])
                           + (["the library"] if n in library else []))
        kinds.setdefault(key, []).append(n)
    for key in sorted(kinds, key=lambda k: -len(kinds[k])):
        short = " ".join(kinds[key]) if len(kinds[key]) <= 6 else ""
        row(f"used by {key}" if key else "by nothing but its own file", len(kinds[key]), short)

    if args.table:
        cols = ["name", "declared", "defined_in"] + list(clients) + ["cdef", "tests", "library"]
        with open(args.table, "w", encoding="utf-8") as f:
            f.write("\t".join(cols) + "\n")
            for n in names:
                source = re.sub(r"^.*?(?=\bsrc/)", "", defined_in.get(n, ""))[:-2]
                cells = [n, where.get(n, ""), source]
                cells += [",".join(sorted(uses.get(n, ()))) for uses in clients.values()]
                cells += ["1" if n in declared else "", ",".join(sorted(tests.get(n, ()))),
                          ",".join(sorted(library.get(n, ())))]
                f.write("\t".join(cells) + "\n")
        print(f"api_uses: one row per export in {args.table}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
