"""object_symbols.py: the global symbols object files define and use, read
with one nm over all of them, for the checks and reports that follow calls
between files (check_circles.py, check_layers.py, api_uses.py).

symbols(objects) -> {object: (defined, used)}: sets of names; defined are
the symbols an object gives others (code, data, weak and unique ones), used
the undefined ones it needs.
links(objects) -> (defined_by, uses): the object defining each symbol (the
first, in the order given) and each object's used symbols.
"""
import subprocess

# nm's letters for a global symbol defined in the object: text, data, bss,
# read-only data, weak (V/W), indirect function (i), unique global (u).
DEFINED = set("TDBRVWiu")


def symbols(objects):
    objects = list(objects)
    found = {obj: (set(), set()) for obj in objects}
    if not objects:
        return found
    # -A starts every line with "OBJECT:", so one run reads them all; the
    # objects come out in the order given.
    out = subprocess.run(["nm", "-g", "-A", *objects], capture_output=True, text=True,
                         check=True).stdout
    at = 0
    for line in out.splitlines():
        while at < len(objects) and not line.startswith(objects[at] + ":"):
            at += 1
        if at == len(objects):
            raise RuntimeError(f"object_symbols: nm printed a line of no object given: {line}")
        parts = line[len(objects[at]) + 1:].split()
        if len(parts) == 3 and parts[1] in DEFINED:
            found[objects[at]][0].add(parts[2])
        elif len(parts) == 2 and parts[0] == "U":
            found[objects[at]][1].add(parts[1])
    return found


def links(objects):
    objects = list(objects)
    found = symbols(objects)
    defined_by, uses = {}, {}
    for obj in objects:
        defined, used = found[obj]
        uses[obj] = used
        for sym in defined:
            defined_by.setdefault(sym, obj)
    return defined_by, uses
