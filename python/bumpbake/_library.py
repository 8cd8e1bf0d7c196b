"""Finds and loads libbumpbake.so for the package (cffi, ABI mode).

Where the library is looked for, first found wins:

1. ``BUMPBAKE_LIBRARY``: the path of the library file (or of the directory
   holding it). When set, nothing else is tried.
2. An installed package (``make install`` put it in PREFIX's dist-packages
   and wrote ``bumpbake/_install.py`` beside it): the library file the
   install put in LIBDIR, by the path recorded then (as bumpbake.pc records
   it), then the dynamic loader's own search.
3. A package in its source tree (``PYTHONPATH=python`` after ``make``): the
   tree's ``build/`` directory, then the libdir pkg-config gives for
   ``bumpbake``, then the dynamic loader's search (LD_LIBRARY_PATH, the
   ldconfig cache).

The file loaded is always the soname below: the ABI the declarations in
_cdef.py describe. An ImportError lists what was tried and says what to do.
"""

import os
import shutil
import subprocess

import cffi

from . import _cdef

# libbumpbake's soname (the Makefile's SONAME); it changes with the ABI, and
# with it the declarations in _cdef.py. tests/test_cdef.py checks both.
SONAME = "libbumpbake.so.0.5"

_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_SOURCE_ROOT = os.path.dirname(os.path.dirname(_PACKAGE_DIR))
_SOURCE_BUILD_DIR = os.path.join(_SOURCE_ROOT, "build")


def installed_library():
    """The library path `make install` recorded for this package, or None
    for a package that was not installed (the source tree's)."""
    try:
        from . import _install
    except ImportError:
        return None
    return _install.LIBRARY


def _in_source_tree():
    return os.path.exists(os.path.join(_SOURCE_ROOT, "include", "bumpbake.h"))


def _pkg_config_libdir():
    """libdir of the installed bumpbake.pc, or None."""
    if not shutil.which("pkg-config"):
        return None
    try:
        out = subprocess.run(
            ["pkg-config", "--variable=libdir", "bumpbake"],
            capture_output=True, text=True, timeout=10, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    libdir = out.stdout.strip()
    return libdir if out.returncode == 0 and libdir else None


def candidates(environ=None):
    """The paths load() tries, in order (a bare soname means the dynamic
    loader's search)."""
    environ = os.environ if environ is None else environ
    explicit = environ.get("BUMPBAKE_LIBRARY")
    if explicit:
        return [os.path.join(explicit, SONAME) if os.path.isdir(explicit) else explicit]
    installed = installed_library()
    if installed:
        return [installed, SONAME]
    found = []
    if _in_source_tree():
        found.append(os.path.join(_SOURCE_BUILD_DIR, SONAME))
    libdir = _pkg_config_libdir()
    if libdir:
        found.append(os.path.join(libdir, SONAME))
    found.append(SONAME)
    return found


def _advice(environ):
    if environ.get("BUMPBAKE_LIBRARY"):
        return "BUMPBAKE_LIBRARY names no loadable library: correct it, or unset it"
    if installed_library():
        return ("the library this package was installed with is gone: run `make install` "
                "again with the same PREFIX, or set BUMPBAKE_LIBRARY to the library's path")
    if _in_source_tree():
        return (f"build it with `make` in {_SOURCE_ROOT}, or set BUMPBAKE_LIBRARY to the "
                "library's path")
    return ("install bumpbake (`make install`), or set BUMPBAKE_LIBRARY to the library's "
            "path")


def load():
    """(ffi, lib, path): the declarations and the loaded library.

    Raises ImportError saying where it looked and what to do when no
    library loads.
    """
    ffi = cffi.FFI()
    ffi.cdef(_cdef.CDEF)
    tried = []
    for path in candidates():
        if os.sep in path and not os.path.exists(path):
            tried.append(f"{path} (no such file)")
            continue
        try:
            return ffi, ffi.dlopen(path), path
        except OSError as e:
            where = path if os.sep in path else f"{path} by the dynamic loader's search"
            tried.append(f"{where} ({e})")
    raise ImportError(f"bumpbake: cannot load {SONAME}: {_advice(os.environ)}. Tried: "
                      + "; ".join(tried))
