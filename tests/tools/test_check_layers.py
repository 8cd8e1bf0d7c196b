#!/usr/bin/env python3
"""test_check_layers.py: tools/check_layers.py passes this tree's sources and
refuses, in a copy of them, an upward include (by folder and by relative
path), an upward call between two objects (but not from the program's
entry, main.o, which links the clients), a folder missing from the order,
a Makefile order that differs and the public header's sections in another
order. `make check-layers` runs it after the check itself; it prints one
line, or what failed and exits 1."""
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CHECK = os.path.join(ROOT, "tools", "check_layers.py")
failures = []


def run(root, *args):
    r = subprocess.run([sys.executable, CHECK, "--root", root, *args],
                       capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def expect(name, root, status, words, *args):
    code, out = run(root, *args)
    if code != status or any(w not in out for w in words):
        failures.append(f"{name}: exit {code}, wanted {status} and {words}:\n{out}")


def copy_tree(dst):
    """docs/how-it-works.md, README.md, include/bumpbake.h and the sources of src/."""
    os.makedirs(os.path.join(dst, "docs"))
    shutil.copy(os.path.join(ROOT, "docs", "how-it-works.md"), os.path.join(dst, "docs"))
    os.makedirs(os.path.join(dst, "include"))
    shutil.copy(os.path.join(ROOT, "include", "bumpbake.h"), os.path.join(dst, "include"))
    shutil.copy(os.path.join(ROOT, "README.md"), dst)
    shutil.copytree(os.path.join(ROOT, "src"), os.path.join(dst, "src"),
                    ignore=lambda d, names: [n for n in names if n.endswith((".o", ".d"))])


def append(path, text):
    with open(path, "a", encoding="utf-8") as f:
        f.write(text)


def main():
    with tempfile.TemporaryDirectory(prefix="bb-layers-") as tmp:
        tree = os.path.join(tmp, "tree")
        copy_tree(tree)
        expect("the tree as it is", tree, 0, ["point down"])

        image_c = os.path.join(tree, "src", "core", "image.c")
        saved = open(image_c, encoding="utf-8").read()
        append(image_c, '#include "job/job_internal.h"\n')
        expect("an include of a later family", tree, 1,
               ["src/core/image.c", '"job/job_internal.h"', "core reaches up to job"])
        with open(image_c, "w", encoding="utf-8") as f:
            f.write(saved)

        rayset_c = os.path.join(tree, "src", "trace", "rayset.c")
        append(rayset_c, '#include "../bake/bake_internal.h"\n')
        expect("a relative include of a later family", tree, 1,
               ["src/trace/rayset.c", "trace reaches up to bake"])
        os.remove(rayset_c)
        expect("the tree again", tree, 0, ["point down"])

        # An object of core using a symbol an object of job defines.
        objs = []
        for family, code in (("core", "int bb__later(void);\nint bb__early(void) { return bb__later(); }\n"),
                             ("job", "int bb__later(void) { return 1; }\n")):
            folder = os.path.join(tmp, "build", "src", family)
            os.makedirs(folder)
            source = os.path.join(folder, "x.c")
            with open(source, "w", encoding="utf-8") as f:
                f.write(code)
            obj = os.path.join(folder, "x.o")
            subprocess.run([os.environ.get("CC", "cc"), "-c", source, "-o", obj], check=True)
            objs.append(obj)
        expect("a call of a later family", tree, 1,
               ["calls bb__later", "core reaches up to job"], *objs)
        expect("the same objects the other way", tree, 0, ["point down"], objs[1])
        # the program's entry links the families together: it may call up
        main_o = os.path.join(os.path.dirname(objs[0]), "main.o")
        shutil.copy(objs[0], main_o)
        expect("the program's entry calling up", tree, 0, ["point down"], main_o, objs[1])

        os.makedirs(os.path.join(tree, "src", "extra"))
        append(os.path.join(tree, "src", "extra", "e.c"), "int e;\n")
        expect("a folder outside the order", tree, 1, ["src/extra/ is not in the order"])
        shutil.rmtree(os.path.join(tree, "src", "extra"))

        expect("a Makefile order that differs", tree, 1, ["FAMILIES"],
               "--families", "core image files")

        # The header's sections: two swapped, then one named otherwise.
        header = os.path.join(tree, "include", "bumpbake.h")
        saved = open(header, encoding="utf-8").read()
        for name, text in (("swapped", saved.replace("\n * trace:", "\n * TRACE:")
                            .replace("\n * image:", "\n * trace:").replace("\n * TRACE:", "\n * image:")),
                           ("renamed", saved.replace("\n * cmd:", "\n * commands:"))):
            with open(header, "w", encoding="utf-8") as f:
                f.write(text)
            expect(f"the header's sections {name}", tree, 1, ["include/bumpbake.h's sections"])
        with open(header, "w", encoding="utf-8") as f:
            f.write(saved)
        expect("the header restored", tree, 0, ["point down"])
    if failures:
        print("test_check_layers: FAILED\n" + "\n".join(failures))
        return 1
    print("test_check_layers: upward includes (by folder, relative), an upward call (the "
          "program's entry's passes), a folder "
          "outside the order, another Makefile order and header sections out of order are refused")
    return 0


if __name__ == "__main__":
    sys.exit(main())
