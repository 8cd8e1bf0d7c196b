"""bumpbake for Python: normal maps, Valve ssbump maps and ambient occlusion
baked from numpy height arrays by libbumpbake (the library behind the
``bumpbake`` command).

    import bumpbake
    maps = bumpbake.bake(height, scale=64, outputs=("normal", "ssbump", "ao"))
    maps["ssbump"]        # float32 array, (H, W, 3)
    n = bumpbake.normal(height, scale=64)

Arrays follow the library's conventions (include/bumpbake.h): row 0 is the
top row, x = column to the right, y = row downwards, z out of the surface;
normals are unit vectors in [-1, 1] (not 0.5 + 0.5 N as in 8-bit files);
ssbump, weights and ao are in [0, 1]. A flat, unoccluded texel gives normal
(0, 0, 1), ssbump 0.57735 per channel and ao 1.

Parameters, defaults and ranges are the command line's (`bumpbake bake
--help`); bad ones raise ArgumentError with the library's message. The
library runs without the GIL, so bakes on several Python threads run side
by side. How the shared library is found: see bumpbake._library.
"""

import os

import numpy as np

from . import _library

_ffi, _lib, library_path = _library.load()


def _output_kind_table():
    """{name: bb_output_kind} in the library's order (bb_output_kind_get)."""
    table = {}
    for k in range(_lib.BB_OUTPUT_KIND_COUNT):
        info = _lib.bb_output_kind_get(k)
        table[_ffi.string(info.name).decode()] = (k, bool(info.needs_trace))
    return table


_KINDS = _output_kind_table()
# The maps bake() can make, as the library (and `bumpbake bake`) names them.
OUTPUTS = tuple(_KINDS)
# Those that need the tracer (the others take no rays).
TRACED_OUTPUTS = tuple(k for k, (_, traced) in _KINDS.items() if traced)
# What `bumpbake bake -o PREFIX` writes.
DEFAULT_OUTPUTS = ("normal", "ssbump", "ao")

_INT_MIN, _INT_MAX = -(2**31), 2**31 - 1


class Error(Exception):
    """A libbumpbake call failed. str(e) is the library's message; e.status
    is the bb_status name ("bad argument", "out of memory", ...)."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class ArgumentError(Error, ValueError):
    """A parameter, or the height array, was refused (bad argument, value or
    size): the command line's usage errors and NaN or empty heights."""


_ARGUMENT_STATUSES = (_lib.BB_ERR_ARGUMENT, _lib.BB_ERR_VALUE, _lib.BB_ERR_SIZE)


def _raise_status(status, err):
    name = _ffi.string(_lib.bb_status_name(status)).decode()
    message = _ffi.string(err.message).decode("utf-8", "replace") or name
    cls = ArgumentError if status in _ARGUMENT_STATUSES else Error
    raise cls(message, name)


def _library_defaults():
    o = _ffi.new("bb_bake_options *")
    _lib.bb_bake_options_init(o)
    return {
        "rays": o.rays,
        "filter_radius": o.smooth.radius_texels,
        "filter_threshold": o.smooth.threshold,
        "bias": o.trace.bias_texels,
        "power": o.power,
        "basis": _ffi.string(o.basis.name).decode(),
        "normal_filter": _ffi.string(_lib.bb_normal_filter_name(o.normal_filter)).decode(),
        "normal_y": "up" if o.normal_y_up else "down",
        "clamp": o.smooth.addressing == _lib.BB_ADDRESS_CLAMP,
        "threads": o.trace.threads,
    }


# The library's defaults (bb_bake_options_init), which the CLI uses too; a
# parameter left at None keeps them.
DEFAULTS = _library_defaults()


# ------------------------------------------------------------ parameters

def _int_value(command, name, value):
    try:
        value = int(value.__index__())
    except AttributeError:
        raise TypeError(f"{command}: {name} must be an integer (got {value!r})") from None
    if not _INT_MIN <= value <= _INT_MAX:
        raise ArgumentError(f"{command}: {name} {value} is out of range", "bad argument")
    return value


def _choice(command, name, parse, text, words):
    """Parses an enum option with the library's own parser."""
    out = _ffi.new(f"{parse[1]} *")
    if not isinstance(text, str) or getattr(_lib, parse[0])(text.encode(), out, _ffi.NULL) != 0:
        raise ArgumentError(f"{command}: {name} must be one of {words} (got {text!r})",
                            "bad argument")
    return out[0]


def _common_options(command, scale, filter_radius, filter_threshold, normal_filter,
                    normal_y, clamp):
    """bb_bake_options with what normal() and bake() share."""
    o = _ffi.new("bb_bake_options *")
    _lib.bb_bake_options_init(o)
    o.height_scale = float(scale)
    if filter_radius is not None:
        o.smooth.radius_texels = _int_value(command, "filter_radius", filter_radius)
    if filter_threshold is not None:
        o.smooth.threshold = float(filter_threshold)
    if normal_filter is not None:
        o.normal_filter = _choice(command, "normal_filter",
                                  ("bb_normal_filter_parse", "bb_normal_filter"),
                                  normal_filter, "vertex|valve|central|sobel")
    if normal_y is not None:
        if normal_y not in ("down", "up"):
            raise ArgumentError(
                f"{command}: normal_y must be one of down|up (got {normal_y!r})", "bad argument")
        o.normal_y_up = normal_y == "up"
    if clamp is not None:
        o.smooth.addressing = _lib.BB_ADDRESS_CLAMP if clamp else _lib.BB_ADDRESS_PERIODIC
    return o


# The named bases; any other text is a basis file (as for `bumpbake bake --basis`).
_BASIS_NAMES = ("hl2", "hl2+z")


def _basis(command, spec):
    """A bb_basis from "hl2", "hl2+z", "dirs:N", a basis file's path, or an
    (N, 3) array of directions (each scaled to unit length by the library)."""
    out = _ffi.new("bb_basis *")
    err = _ffi.new("bb_error *")
    if isinstance(spec, str) and (spec in _BASIS_NAMES or spec.startswith("dirs:")):
        st = _lib.bb_basis_parse(spec.encode(), out, err)
    elif isinstance(spec, (str, bytes, os.PathLike)):
        path = os.fsencode(spec)
        if not os.path.exists(path):
            raise ArgumentError(
                f"{command}: basis must be hl2, hl2+z, dirs:N or a file of directions "
                f"(got {spec!r}: no such file)", "bad argument")
        st = _lib.bb_basis_load(path, out, err)
    else:
        v = np.asarray(spec, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ArgumentError(f"{command}: basis vectors must be an (N, 3) array "
                                f"(got shape {v.shape})", "bad argument")
        v = np.ascontiguousarray(v)
        st = _lib.bb_basis_from_vectors(_ffi.cast("const double (*)[3]", _ffi.from_buffer(v)),
                                        v.shape[0], out, err)
    if st != _lib.BB_OK:
        _raise_status(st, err)
    return out


def basis(spec):
    """The unit directions of a basis, float64 (N, 3), in the order of the
    ssbump and weights channels a bake with basis=spec makes (spec as for
    bake())."""
    b = _basis("basis", spec)
    return np.array([[b.vector[c][k] for k in range(3)] for c in range(b.count)])


def _output_kinds(outputs):
    kinds = (outputs,) if isinstance(outputs, str) else tuple(outputs)
    for k in kinds:
        if k not in OUTPUTS:
            raise ArgumentError(
                f"bake: unknown output {k!r} (one of {', '.join(OUTPUTS)})", "bad argument")
    if not kinds:
        raise ArgumentError("bake: nothing to make: outputs is empty", "bad argument")
    return tuple(dict.fromkeys(kinds))


# ---------------------------------------------------------------- arrays

def _height_image(command, height):
    """(bb_image *, the buffer its pixels point into, alpha channel index)."""
    a = np.asarray(height)
    if a.ndim == 2:
        a = a[:, :, np.newaxis]
    elif a.ndim != 3:
        raise ArgumentError(
            f"{command}: height must be an (H, W) or (H, W, C) array (got shape {a.shape})",
            "bad argument")
    if a.dtype.kind == "u":  # integer heights are value / max code, as in files
        a = a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
    elif a.dtype.kind != "f":
        raise TypeError(f"{command}: height must be a float or unsigned integer array "
                        f"(got {a.dtype})")
    a = np.ascontiguousarray(a, dtype=np.float32)
    rows, cols, channels = a.shape
    img = _ffi.new("bb_image *")
    img.width, img.height, img.channels = cols, rows, channels
    pixels = _ffi.from_buffer("float[]", a) if a.size else _ffi.NULL
    img.pixels = pixels
    # Grey + alpha and RGBA arrays carry alpha last, as OpenImageIO reports files.
    alpha = {2: 1, 4: 3}.get(channels, -1)
    return img, pixels, alpha


def _height_field(command, height, channel):
    """The 1-channel bb_image the library bakes, by the library's channel rule
    (which also refuses NaN, infinite and empty heights). Free with bb_image_free."""
    img, keep, alpha = _height_image(command, height)
    which = _choice(command, "channel", ("bb_channel_parse", "bb_channel"), channel,
                    "auto|r|g|b|a|luma|mean")
    field = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_height_from_image(img, alpha, which, field, err)
    del keep  # the pixels stay alive up to here; the library has copied them
    if st != _lib.BB_OK:
        _raise_status(st, err)
    return field


def _array(img):
    """A float32 copy of a bb_image: (H, W) for one channel, else (H, W, C)."""
    n = img.width * img.height * img.channels
    a = np.frombuffer(_ffi.buffer(img.pixels, n * 4), dtype=np.float32).copy()
    shape = (img.height, img.width) + ((img.channels,) if img.channels != 1 else ())
    return a.reshape(shape)


def _run_bake(height, channel, options, command):
    err = _ffi.new("bb_error *")
    st = _lib.bb_bake_options_check(options, err)  # bad options before a bad height
    if st != _lib.BB_OK:
        _raise_status(st, err)
    field = _height_field(command, height, channel)
    result = _ffi.new("bb_bake_result *")
    try:
        st = _lib.bb_bake(field, options, result, err)  # cffi releases the GIL here
        if st != _lib.BB_OK:
            _raise_status(st, err)
        return result
    finally:
        _lib.bb_image_free(field)


# ------------------------------------------------------------------- API

def read(path):
    """Reads an image file the way the command line does (OpenImageIO: PNG,
    TGA, TIFF, OpenEXR, JPEG, ...): float32, (H, W) for one channel, else
    (H, W, C); integer files are scaled to [0, 1] as value / max code. Raises
    Error with the library's message ("PATH: reason") when it cannot."""
    img = _ffi.new("bb_image *")
    info = _ffi.new("bb_image_info *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_image_read(os.fsencode(path), img, info, err)
    try:
        if st != _lib.BB_OK:
            _raise_status(st, err)
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
    st = _lib.bb_file_hash(os.fsencode(path), value, err)
    if st != _lib.BB_OK:
        _raise_status(st, err)
    return int(value[0])


def bake(height, scale, *, outputs=DEFAULT_OUTPUTS, rays=None, slices=None, filter_radius=None,
         filter_threshold=None, bias=None, power=None, basis=None, normal_filter=None,
         normal_y=None, clamp=None, channel="auto", threads=None):
    """Bakes the maps named in outputs from a height array in one pass and
    returns {name: float32 array}. See the module doc for the conventions."""
    kinds = _output_kinds(outputs)
    o = _common_options("bake", scale, filter_radius, filter_threshold, normal_filter,
                        normal_y, clamp)
    if rays is not None:
        o.rays = _int_value("bake", "rays", rays)
    if slices is not None:
        o.slices = _int_value("bake", "slices", slices)
        if o.slices == 0:
            raise ArgumentError("bake: slices must be in 1..256 (got 0)", "bad argument")
    if bias is not None:
        o.trace.bias_texels = float(bias)
    if power is not None:
        o.power = float(power)
    if threads is not None:
        o.trace.threads = _int_value("bake", "threads", threads)
    if basis is not None:
        o.basis = _basis("bake", basis)[0]
    o.outputs = sum(1 << _KINDS[k][0] for k in kinds)  # only these are computed
    result = _run_bake(height, channel, o, "bake")
    try:
        return {k: _array(_lib.bb_bake_result_image(result, _KINDS[k][0])) for k in kinds}
    finally:
        _lib.bb_bake_result_free(result)


def normal(height, scale, *, filter_radius=None, filter_threshold=None,
           normal_filter=None, normal_y=None, clamp=None, channel="auto"):
    """Smooths the height and returns its unit normals, float32 (H, W, 3),
    as `bumpbake normal` makes them (nothing is traced)."""
    o = _common_options("normal", scale, filter_radius, filter_threshold, normal_filter,
                        normal_y, clamp)
    o.outputs = 1 << _lib.BB_OUTPUT_NORMAL
    result = _run_bake(height, channel, o, "normal")
    try:
        return _array(result.normal)
    finally:
        _lib.bb_bake_result_free(result)


_PARAMETERS = f"""

Parameters (as `bumpbake bake --help`; None keeps the library's default):
    height: (H, W) heights, or (H, W, C) with C = 2 grey + alpha, 3 RGB,
        4 RGBA; float arrays are used as they are, unsigned integer ones as
        value / max code.
    scale: texels of displacement per unit of height, > 0 (required).
    outputs (bake): names from {", ".join(OUTPUTS)}; default
        {", ".join(DEFAULT_OUTPUTS)}. ssbump, ao and bent trace horizons.
    rays (bake): ray budget, default {DEFAULTS["rays"]}, 1..65536: round(sqrt(rays))
        azimuth slices, as Valve's tool counts rays.
    slices (bake): azimuth slices, 1..256; overrides rays.
    filter_radius: bilateral smoothing radius in texels, default
        {DEFAULTS["filter_radius"]}, 0..4096, 0 = off.
    filter_threshold: smoothing range threshold, default
        {DEFAULTS["filter_threshold"]:.7g}, > 0.
    bias (bake): ray origin lift in texels, default {DEFAULTS["bias"]:g}, 0..1e6.
    power (bake): exponent of the basis lobes, default {DEFAULTS["power"]:g}, 1..1e6.
    basis (bake): the directions of ssbump and weights, one channel each:
        "hl2" (default), "hl2+z" (adds (0, 0, 1)), "dirs:N" (N in 3..16
        evenly spread in azimuth at Half-Life 2's elevation), a basis file
        (lines "x y z", # comments) or an (N, 3) array of directions.
    normal_filter: "vertex" (centred on the texel's vertex), "valve"
        (Valve's), "central" or "sobel"; default "{DEFAULTS["normal_filter"]}".
    normal_y: "down" (Source, DirectX) or "up" (OpenGL); default
        "{DEFAULTS["normal_y"]}".
    clamp: extend the border texels instead of tiling; default {DEFAULTS["clamp"]}.
    channel: "auto" (grey, or the mean of R, G, B; alpha when the colour is
        constant and alpha is not, Valve's convention), "r", "g", "b", "a",
        "luma" or "mean".
    threads (bake): worker threads, default {DEFAULTS["threads"]} = all cores,
        0..4096; results are identical for any count.

Raises ArgumentError (a ValueError) with the library's message for a bad
parameter or height, TypeError for a wrong type, Error otherwise.
"""
bake.__doc__ += _PARAMETERS
normal.__doc__ += _PARAMETERS
