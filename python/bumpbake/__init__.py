"""bumpbake for Python: normal maps, Valve ssbump maps and ambient occlusion
from height maps, and everything the `bumpbake` command does, through
libbumpbake (the library behind the command), on numpy arrays and on files.

    import bumpbake
    maps = bumpbake.bake(height, scale=64, outputs=("normal", "ssbump", "ao"))
    maps["ssbump"]        # float32 array, (H, W, 3)
    reports = bumpbake.bake_files("heights/", "maps/", maps=("normal", "ao"), scale=16)
    assert bumpbake.compare("maps/rock_normal.png", "golden/rock_normal.png").passed
    assert bumpbake.check("goldens", heights=["heights/"], scale=16).passed

Arrays follow the library's conventions (include/bumpbake.h): row 0 is the
top row, x = column to the right, y = row downwards, z out of the surface;
normals are unit vectors in [-1, 1] (not 0.5 + 0.5 N as in 8-bit files);
ssbump, weights and ao are in [0, 1]. A flat, unoccluded texel gives normal
(0, 0, 1), ssbump 0.57735 per channel and ao 1. Float arrays are used as
they are, unsigned integer arrays as value / max code (as files are read).

Parameters, defaults and ranges are the command line's (`bumpbake bake
--help`); bad ones raise ArgumentError with the library's message. The
library runs without the GIL, so calls on several Python threads run side
by side. docs/python.md is the reference; how the shared library is found:
bumpbake._library.
"""

from ._common import ArgumentError, Error, NoteWarning, library_path, _ffi, _lib  # noqa: F401 (tests)
from ._check import CheckCase, CheckResult, check
from ._bake import (BAKE_PARAMETERS, DEFAULT_OUTPUTS, DEFAULTS, OUTPUTS, TRACED_OUTPUTS,
                    BakeContext, bake, basis, normal)
from ._files import (Comparison, DdsInfo, ImageInfo, VtfInfo, compare, file_hash, info, read,
                     write, write_vmt)
from ._jobs import BakeJob, BakeReport, bake_file, bake_files
from ._maps import combine, decode_normals, mips, normal2ssbump, program, ssbump2normal
from ._render import DEFAULT_LIGHT, RenderBump, render, renderbumpflat, run, sheet
from . import _library  # noqa: F401 (bumpbake._library.candidates, SONAME)

__all__ = [
    "ArgumentError", "BAKE_PARAMETERS", "BakeContext", "BakeJob", "BakeReport", "CheckCase",
    "CheckResult", "Comparison",
    "DdsInfo", "DEFAULT_LIGHT", "DEFAULT_OUTPUTS", "DEFAULTS", "Error", "ImageInfo", "NoteWarning",
    "OUTPUTS", "RenderBump", "TRACED_OUTPUTS", "bake", "bake_file", "bake_files", "basis",
    "check", "combine", "compare", "decode_normals", "file_hash", "info", "library_path", "mips",
    "normal", "normal2ssbump", "program", "read", "render", "renderbumpflat", "run", "sheet",
    "ssbump2normal", "VtfInfo", "write", "write_vmt",
]
