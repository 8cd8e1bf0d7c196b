"""Image files: read, write, what a file is (info), its hash, and two files
compared as idiff compares them (compare)."""

import dataclasses
import math
import os
import typing

from ._bake import _KINDS
from ._common import (_Image, _argument_error, _array, _check, _depth, _ffi, _int, _lib,
                      _path, _text)


def read(path):
    """Reads an image file the way the command line does (OpenImageIO: PNG,
    TGA, TIFF, OpenEXR, JPEG, ...): float32, (H, W) for one channel, else
    (H, W, C); integer files are scaled to [0, 1] as value / max code. Raises
    Error with the library's message ("PATH: reason") when it cannot."""
    img = _ffi.new("bb_image *")
    info = _ffi.new("bb_image_info *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_image_read(_path(path), img, info, err)
    try:
        _check(st, err)
        return _array(img)
    finally:
        _lib.bb_image_free(img)
        _lib.bb_image_info_free(info)


def file_hash(path):
    """The 64-bit FNV-1a hash of a file's bytes, as an int: what every map
    bumpbake writes records of its input as input_file_hash (16 hex
    digits), so a pipeline can tell which input a map was baked from, and
    whether it changed since, without decoding it. Raises Error with the
    library's message when the file cannot be read."""
    value = _ffi.new("uint64_t *")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_file_hash(_path(path), value, err), err)
    return int(value[0])


# ------------------------------------------------------------------ info

_PROVENANCE_CLASSES = {_lib.BB_PROVENANCE_NONE: "none", _lib.BB_PROVENANCE_INTACT: "intact",
                       _lib.BB_PROVENANCE_DAMAGED: "damaged"}


def _provenance_dict(text):
    """The key=value lines of intact provenance as {key: value}, values as
    written (strings), as `bumpbake info --json` prints them; a repeated
    key keeps its first value, as the library reads it."""
    out = {}
    for line in text.splitlines():
        key, eq, value = line.partition("=")
        if eq:
            out.setdefault(key, value)
    return out


@dataclasses.dataclass
class ImageInfo:
    """What an image file is, from its header (bumpbake.info)."""
    path: str
    width: int
    height: int
    channels: int
    format: str             # OpenImageIO's format name: "png", "openexr", ...
    bits_per_sample: int    # 8, 16, 32
    is_float: bool          # float or half samples
    alpha_channel: int      # index of the alpha channel, or -1
    provenance_class: str   # "intact", "damaged" (cut or re-wrapped) or "none"
    provenance: typing.Optional[dict]  # {key: value} when intact, else None
    description: typing.Optional[str]  # the stored text (provenance or another
                                       # tool's ImageDescription), or None


def info(path):
    """What an image file is, from its header alone (no pixel is decoded),
    as `bumpbake info` reports it: an ImageInfo. Raises Error with the
    library's message when the file cannot be read."""
    w, h, c = (_ffi.new("int *") for _ in range(3))
    i = _ffi.new("bb_image_info *")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_image_read_info(_path(path), w, h, c, i, err), err)
    try:
        description = _text(i.description)
        klass = _PROVENANCE_CLASSES[_lib.bb_provenance_classify(i.description)]
        return ImageInfo(
            path=os.fsdecode(_path(path)),
            width=w[0], height=h[0], channels=c[0], format=_text(i.format_name),
            bits_per_sample=i.bits_per_sample, is_float=bool(i.is_float),
            alpha_channel=i.alpha_channel, provenance_class=klass,
            provenance=_provenance_dict(description) if klass == "intact" else None,
            description=description)
    finally:
        _lib.bb_image_info_free(i)


# ----------------------------------------------------------------- write

# Words for unit values besides the map kinds (which say their own range).
_UNIT_KINDS = ("height", "colour", "render")


def _signed(command, kind):
    """True when kind's values are signed unit vectors ([-1, 1]: normal and
    bent, as bb_output_kind_info says), False for unit values ([0, 1])."""
    if kind in _KINDS:
        return _KINDS[kind][2]
    if kind in _UNIT_KINDS:
        return False
    raise _argument_error(f"{command}: kind must be one of "
                          f"{', '.join(tuple(_KINDS) + _UNIT_KINDS)} (got {kind!r})")


def write(path, array, *, kind="colour", depth=None, mips=False, description=None):
    """Writes an array to path with the library's writer, as `bumpbake bake`
    writes its maps: the format from the extension (.png .tga .tif .tiff
    .exr), written to a temporary file and renamed into place (nothing is
    left at path on failure).

    kind says how values become integer codes: "normal" and "bent" arrays
    are signed unit vectors stored as 0.5 + 0.5 N (N itself in float files);
    the other map kinds ("weights", "ssbump", "ao", "filtered") and "height",
    "colour" and "render" are unit values stored as value x max code.
    Integer formats clamp and round to the nearest code.
    depth: None (8-bit for png/tga/tif, float for exr), 8, 16, "half" or
    "float". mips: a mip chain (tif and exr only), renormalised for normal
    and bent, averaged otherwise. description: text stored in the file's
    ImageDescription (bumpbake's provenance, or anything), or None.
    Raises ArgumentError for a format that cannot hold the depth, mips or
    channels, Error when the file cannot be written."""
    signed = _signed("write", kind)
    src = _Image("write: array", array)
    d = _depth(depth)
    p = _path(path)
    err = _ffi.new("bb_error *")
    c_path, c_kind = _ffi.new("char[]", p), _ffi.new("char[]", kind.encode())
    c_text = _ffi.new("char[]", description.encode()) if description is not None else _ffi.NULL
    spec = _ffi.new("bb_output_spec *", {"path": c_path, "kind": c_kind,
                                         "channels": src.image.channels, "depth": d,
                                         "mips": int(bool(mips))})
    _check(_lib.bb_outputs_check(spec, 1, _ffi.NULL, 0, err), err)
    f = _ffi.new("bb_output_file *", {
        "path": c_path, "kind": c_kind, "image": src.image,
        "range": _lib.BB_RANGE_SIGNED if signed else _lib.BB_RANGE_UNIT,
        "depth": d, "mips": int(bool(mips)), "description": c_text})
    _check(_lib.bb_outputs_write(f, 1, 1, err), err)


# --------------------------------------------------------------- compare

@dataclasses.dataclass
class Comparison:
    """Two images compared (bumpbake.compare), with idiff's verdict."""
    a: str
    b: str
    result: str        # "PASS", "WARNING", "FAILURE" or "DIFFERENT SIZE"
    exit_code: int     # idiff's (and `bumpbake compare`'s): 0, 1, 2 or 3
    width: int         # of a
    height: int
    channels: int
    b_shape: tuple     # (height, width, channels) of b
    pixels: int
    mean_abs: float
    rms: float
    max_abs: float
    worst: typing.Optional[tuple]  # (x, y, channel) of max_abs, None when 0
    over_fail: int     # pixels with a channel over fail
    over_warn: int     # pixels with a channel over warn
    provenance_a: str  # "intact", "damaged" or "none"
    provenance_b: str
    provenance_diff: typing.Optional[list]  # [(key, a value, b value)] (None
                                            # for a missing key); None when
                                            # either side is not intact
    provenance_lines: typing.Optional[list]  # the same as `bumpbake compare`
                                             # prints them: "key: A -> B"
    diff_written: bool
    diff_error: typing.Optional[str]

    @property
    def passed(self):
        """True when idiff would exit 0."""
        return self.exit_code == 0

    def __bool__(self):
        return self.passed



def _diff_pairs(text, a, b):
    """(key, value in a, value in b) for each key bb_provenance_diff names
    in text ("key: A -> B" lines), values taken from the files' own
    provenance (None where a file lacks the key), since a value may hold
    " -> " itself."""
    va, vb = (_provenance_dict(info(p).description or "") for p in (a, b))
    return [(key, va.get(key), vb.get(key))
            for key in (line.partition(": ")[0] for line in text.splitlines())]


def compare(a, b, *, fail=1e-6, failpercent=0.0, hardfail=math.inf, allowfailures=0,
            warn=1e-6, warnpercent=0.0, hardwarn=math.inf, diff=None):
    """Compares two image files channel by channel as OpenImageIO's idiff
    (and `bumpbake compare`) do, and their provenance key by key, and
    returns a Comparison: `assert bumpbake.compare(out, golden,
    fail=1e-4).passed` guards a golden image.

    Tolerances are idiff's, absolute, in the images' float units: a pixel
    fails when a channel differs by more than fail, warns by more than
    warn. Verdict: PASS when at most allowfailures pixels fail; else FAILURE
    when more than failpercent % fail or any difference exceeds hardfail;
    else WARNING when more than warnpercent % warn or any difference exceeds
    hardwarn; else PASS. Images of different size or channel count give
    "DIFFERENT SIZE" (exit code 3). diff: a path to write |A - B| to (raw
    in .exr, scaled so the largest difference is white elsewhere); a diff
    that cannot be written is reported (diff_error), not raised.
    Raises Error when a file cannot be read (idiff's exit 4),
    ArgumentError for a bad tolerance or diff path."""
    limits = _ffi.new("bb_compare_limits *")
    limits.fail, limits.fail_percent, limits.hard_fail = fail, failpercent, hardfail
    limits.warn, limits.warn_percent, limits.hard_warn = warn, warnpercent, hardwarn
    limits.allow_failures = _int("compare", "allowfailures", allowfailures)
    err = _ffi.new("bb_error *")
    _check(_lib.bb_compare_limits_check(limits, err), err)  # before the diff's path
    pa, pb = _path(a), _path(b)
    pd = _ffi.NULL
    if diff is not None:
        pd = _path(diff)
        strings = [_ffi.new("char[]", s) for s in (pd, b"diff", pa, pb)]
        spec = _ffi.new("bb_output_spec *", {"path": strings[0], "kind": strings[1]})
        reads = _ffi.new("char *[2]", strings[2:])
        _check(_lib.bb_outputs_check(spec, 1, reads, 2, err), err)
    r = _ffi.new("bb_compare_report *")
    _check(_lib.bb_compare_files(pa, pb, limits, pd, r, err), err)
    try:
        s = r.stats
        same = bool(r.same_shape)
        differences = r.provenance_differences
        return Comparison(
            a=os.fsdecode(pa), b=os.fsdecode(pb),
            result=_text(_lib.bb_compare_report_result(r)),
            exit_code=_lib.bb_compare_report_exit_code(r),
            width=r.width, height=r.height, channels=r.channels,
            b_shape=(r.b_height, r.b_width, r.b_channels),
            pixels=s.pixels if same else 0, mean_abs=s.mean_abs, rms=s.rms, max_abs=s.max_abs,
            worst=(s.worst_x, s.worst_y, s.worst_channel) if s.max_abs > 0 else None,
            over_fail=s.over_fail, over_warn=s.over_warn,
            provenance_a=_PROVENANCE_CLASSES[r.provenance_a],
            provenance_b=_PROVENANCE_CLASSES[r.provenance_b],
            provenance_diff=(_diff_pairs(_text(r.provenance_diff) or "", pa, pb)
                             if differences >= 0 else None),
            provenance_lines=((_text(r.provenance_diff) or "").splitlines()
                              if differences >= 0 else None),
            diff_written=bool(r.diff_written),
            diff_error=(_text(r.diff_error.message) or None)
            if diff is not None and not r.diff_written else None)
    finally:
        _lib.bb_compare_report_free(r)
