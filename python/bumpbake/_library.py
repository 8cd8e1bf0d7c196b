"""Finds and loads libbumpbake.so for the package (cffi, ABI mode).

Where the library is looked for, first found wins:

1. ``BUMPBAKE_LIBRARY``: the path of the library file (or of the directory
   holding it). When set, nothing else is tried.
2. The build directory of the source tree this package sits in:
   ``python/bumpbake`` -> ``build/libbumpbake.so.X``, after ``make``.
3. The libdir pkg-config gives for ``bumpbake`` (after ``make install``;
   PKG_CONFIG_PATH when the prefix is not a standard one).
4. The dynamic loader's own search (LD_LIBRARY_PATH, the ldconfig cache, for
   example /usr/local/lib after ``make install`` as root).

The file loaded is always the soname below: the ABI the declarations in
_cdef.py describe.
"""

import os
import shutil
import subprocess

import cffi

from . import _cdef

# libbumpbake's soname (the Makefile's SONAME); it changes with the ABI, and
# with it the declarations in _cdef.py. tests/test_cdef.py checks both.
SONAME = "libbumpbake.so.0.2"

_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_SOURCE_BUILD_DIR = os.path.join(os.path.dirname(os.path.dirname(_PACKAGE_DIR)), "build")


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
    """The paths load() tries, in order (a bare soname means the loader's search)."""
    environ = os.environ if environ is None else environ
    explicit = environ.get("BUMPBAKE_LIBRARY")
    if explicit:
        return [os.path.join(explicit, SONAME) if os.path.isdir(explicit) else explicit]
    found = [os.path.join(_SOURCE_BUILD_DIR, SONAME)]
    libdir = _pkg_config_libdir()
    if libdir:
        found.append(os.path.join(libdir, SONAME))
    found.append(SONAME)
    return found


def load():
    """(ffi, lib, path): the declarations and the loaded library.

    Raises ImportError saying where it looked when no library loads.
    """
    ffi = cffi.FFI()
    ffi.cdef(_cdef.CDEF)
    tried = []
    for path in candidates():
        if os.sep in path and not os.path.exists(path):
            tried.append(f"{path} (missing)")
            continue
        try:
            return ffi, ffi.dlopen(path), path
        except OSError as e:
            tried.append(f"{path} ({e})")
    raise ImportError(
        f"bumpbake: cannot load {SONAME}; build it with `make`, install it with "
        f"`make install`, or set BUMPBAKE_LIBRARY to its path. Tried: " + "; ".join(tried))
