"""bumpbake/_cdef.py against include/bumpbake.h (and bumpbake_cluster.h) and
the built library.

cffi's ABI mode trusts the declarations it is given: a struct that gained a
field in the header but not in _cdef.py would be allocated too small. These
tests compile a C program with the real header that prints the size and
field offsets of every struct and the value of every enum constant _cdef.py
declares, and that redeclares its functions (a C compiler rejects a
redeclaration that does not match), then compare. When one fails, copy the
changed declaration from the header into _cdef.py.
"""

import os
import re
import shutil
import subprocess

import cffi
import pytest

import bumpbake
from bumpbake import _cdef, _library

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HEADER_DIR = os.path.join(ROOT, "include")
CC = os.environ.get("BB_CC") or "cc"

pytestmark = pytest.mark.skipif(shutil.which(CC) is None, reason=f"no C compiler ({CC})")


def _ffi():
    ffi = cffi.FFI()
    ffi.cdef(_cdef.CDEF)
    return ffi


def _compile_and_run(tmp_path, source):
    c = tmp_path / "layout.c"
    c.write_text(source)
    exe = tmp_path / "layout"
    build = subprocess.run([CC, "-std=c11", "-Werror", "-I", HEADER_DIR, str(c), "-o", str(exe)],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    # The program only uses the header, so it needs no sanitizer preload.
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    return subprocess.run([str(exe)], capture_output=True, text=True, check=True, env=env).stdout


def test_structs_and_enums_match_the_header(tmp_path):
    ffi = _ffi()
    structs, enums = ffi.list_types()[0], []
    lines, expected = [], {}
    for name in structs:
        t = ffi.typeof(name)
        if t.kind == "struct" and t.fields is None:
            continue  # opaque: the next test checks the header keeps it so
        if t.kind == "struct":
            lines.append(f'printf("sizeof {name} %zu\\n", sizeof({name}));')
            expected[f"sizeof {name}"] = ffi.sizeof(name)
            for field, f in t.fields:
                lines.append(f'printf("offsetof {name}.{field} %zu\\n", offsetof({name}, {field}));')
                expected[f"offsetof {name}.{field}"] = f.offset
        elif t.kind == "enum":
            enums.append(name)
            for value, constant in t.elements.items():
                lines.append(f'printf("enum {constant} %d\\n", (int){constant});')
                expected[f"enum {constant}"] = value
    source = ("#include <stddef.h>\n#include <stdio.h>\n#include \"bumpbake.h\"\n"
              "int main(void) {\n" + "\n".join(lines) + "\nreturn 0;\n}\n")
    got = {}
    for line in _compile_and_run(tmp_path, source).splitlines():
        key, value = line.rsplit(" ", 1)
        got[key] = int(value)
    mismatched = {k: (v, got[k]) for k, v in expected.items() if got[k] != v}
    assert not mismatched, f"_cdef.py (cffi) vs bumpbake.h (C): {mismatched}"
    assert enums, "no enum was checked"


def test_constants_match_the_header(tmp_path):
    constants = re.findall(r"#define (\w+) (\d+)", _cdef.CONSTANTS)
    assert constants
    source = ("#include <stdio.h>\n#include \"bumpbake.h\"\nint main(void) {\n"
              + "".join(f'printf("{name} %lld\\n", (long long)({name}));\n'
                        for name, _ in constants)
              + "return 0;\n}\n")
    got = dict(line.split() for line in _compile_and_run(tmp_path, source).splitlines())
    assert {name: int(value) for name, value in constants} == \
        {name: int(got[name]) for name, _ in constants}
    for name, value in constants:  # and cffi reads them as written
        assert getattr(bumpbake._lib, name) == int(value)


def _header_text():
    """bumpbake.h without comments."""
    with open(os.path.join(HEADER_DIR, "bumpbake.h")) as f:
        return re.sub(r"/\*.*?\*/", "", f.read(), flags=re.S)


def _header_body(kind, name):
    """What is between the braces of `typedef KIND NAME { ... } NAME;` (or of
    `KIND NAME { ... };` after a `typedef KIND NAME NAME;` that a function
    type before it needs) in bumpbake.h, without comments."""
    text = _header_text()
    found = (re.search(r"typedef %s %s \{(.*?)\} %s;" % (kind, name, name), text, re.S)
             or re.search(r"\n%s %s \{(.*?)\};" % (kind, name), text, re.S))
    assert found, f"{kind} {name} is not in bumpbake.h"
    return found.group(1)


def _header_struct_fields(name):
    """Field names of `typedef struct NAME { ... } NAME;` in bumpbake.h, in order."""
    body = _header_body("struct", name)
    fields = []
    for declaration in body.split(";"):
        for part in re.sub(r"\[[^]]*\]", "", declaration).split(","):
            words = re.findall(r"\w+", part)
            if words:
                fields.append(words[-1])
    return fields


def _header_enum_constants(name):
    """Constant names of `typedef enum NAME { ... } NAME;` in bumpbake.h."""
    return re.findall(r"\b(BB_\w+)", _header_body("enum", name))


def test_struct_fields_and_enum_constants_are_the_headers():
    # Sizes and offsets cannot see a trailing field that fits in padding,
    # nor the C program a constant _cdef.py lacks.
    ffi = _ffi()
    for name in ffi.list_types()[0]:
        t = ffi.typeof(name)
        if t.kind == "struct" and t.fields is None:
            assert f"typedef struct {name} {name};" in _header_text(), f"{name} is not opaque"
        elif t.kind == "struct":
            assert [f for f, _ in t.fields] == _header_struct_fields(name), name
        elif t.kind == "enum":
            ours = [t.elements[v] for v in sorted(t.elements)]
            assert ours == _header_enum_constants(name), name


def test_functions_match_the_header(tmp_path):
    # Redeclaring a function with another signature is a compile error in C.
    # (bumpbake_cluster.h includes bumpbake.h: the split trace and the
    # hand-over the package's dask module calls are declared there.)
    source = ('#include "bumpbake_cluster.h"\n' + _cdef.FUNCTIONS + "\nint main(void) { return 0; }\n")
    _compile_and_run(tmp_path, source)
    declared = set(re.findall(r"\b(bb_\w+)\s*\(", _cdef.FUNCTIONS))
    for name in declared:  # and each is there in the loaded library
        assert getattr(bumpbake._lib, name) is not None


def test_the_soname_is_the_built_one():
    if shutil.which("readelf") is None:
        pytest.skip("no readelf")
    out = subprocess.run(["readelf", "-d", os.path.realpath(bumpbake.library_path)],
                         capture_output=True, text=True, check=True).stdout
    soname = re.search(r"\(SONAME\).*\[(.*)\]", out).group(1)
    assert soname == _library.SONAME, "update SONAME in python/bumpbake/_library.py"
