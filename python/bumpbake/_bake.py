"""Bakes of numpy height arrays (bb_bake) and the bake options every baking
call shares, made from keyword arguments the way `bumpbake bake` makes them
from its options."""

import os

import numpy as np

from ._common import (_argument_error, _array, _check, _ffi, _Image, _int, _lib, _parse, _path,
                      _text)


def _output_kind_table():
    """{name: (bb_output_kind, needs trace, signed)} in the library's order."""
    table = {}
    for k in range(_lib.BB_OUTPUT_KIND_COUNT):
        info = _lib.bb_output_kind_get(k)
        table[_text(info.name)] = (k, bool(info.needs_trace),
                                   info.range == _lib.BB_RANGE_SIGNED)
    return table


_KINDS = _output_kind_table()
# The maps bake() can make, as the library (and `bumpbake bake`) names them.
OUTPUTS = tuple(_KINDS)
# Those that need the tracer (the others take no rays).
TRACED_OUTPUTS = tuple(k for k, (_, traced, _) in _KINDS.items() if traced)
# What `bumpbake bake -o PREFIX` and a batch write unless told.
DEFAULT_OUTPUTS = tuple(k for k, (i, _, _) in _KINDS.items() if (1 << i) & _lib.BB_JOB_DEFAULT_MAPS)


def _library_defaults():
    o = _ffi.new("bb_bake_options *")
    _lib.bb_bake_options_init(o)
    return {
        "rays": o.rays,
        "filter_radius": o.smooth.radius_texels,
        "filter_threshold": o.smooth.threshold,
        "bias": o.trace.bias_texels,
        "power": o.power,
        "basis": _text(o.basis.name),
        "normal_filter": _text(_lib.bb_normal_filter_name(o.normal_filter)),
        "normal_y": "up" if o.normal_y_up else "down",
        "clamp": o.smooth.addressing == _lib.BB_ADDRESS_CLAMP,
        "threads": o.trace.threads,
    }


# The library's defaults (bb_bake_options_init), which the CLI uses too; a
# parameter left at None keeps them.
DEFAULTS = _library_defaults()

# The keyword arguments of every bake (bake(), bake_files(), sheet() ...).
BAKE_PARAMETERS = ("rays", "slices", "filter_radius", "filter_threshold", "bias", "power",
                   "basis", "normal_filter", "normal_y", "clamp", "threads")


def _normal_y_up(command, normal_y):
    if normal_y not in ("down", "up"):
        raise _argument_error(f"{command}: normal_y must be one of down|up (got {normal_y!r})")
    return normal_y == "up"


def _basis(spec):
    """(bb_basis *, the file it came from or None) from "hl2", "hl2+z",
    "dirs:N", a basis file's path (bb_basis_resolve: a name wins over a file
    of the same name) or an (N, 3) array of directions."""
    out = _ffi.new("bb_basis *")
    err = _ffi.new("bb_error *")
    if isinstance(spec, (str, bytes, os.PathLike)):
        spelled = _path(spec, "basis")
        from_file = _ffi.new("int *")
        _check(_lib.bb_basis_resolve(spelled, out, from_file, err), err)
        return out, spelled if from_file[0] else None
    v = np.asarray(spec, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise _argument_error(f"basis vectors must be an (N, 3) array (got shape {v.shape})")
    v = np.ascontiguousarray(v)
    _check(_lib.bb_basis_from_vectors(_ffi.cast("const double (*)[3]", _ffi.from_buffer(v)),
                                      v.shape[0], out, err), err)
    return out, None


def basis(spec):
    """The unit directions of a basis, float64 (N, 3), in the order of the
    ssbump and weights channels a bake with basis=spec makes (spec as for
    bake())."""
    b, _ = _basis(spec)
    return np.array([[b.vector[c][k] for k in range(3)] for c in range(b.count)])


def _bake_options(command, scale, rays=None, slices=None, filter_radius=None,
                  filter_threshold=None, bias=None, power=None, basis=None, normal_filter=None,
                  normal_y=None, clamp=None, threads=None):
    """(bb_bake_options *, basis file or None) from bake's keyword arguments;
    None keeps the library's default. Checked by the library
    (bb_bake_options_check) once the outputs are known."""
    o = _ffi.new("bb_bake_options *")
    _lib.bb_bake_options_init(o)
    if scale is None:
        raise TypeError(f"{command}: scale is required (texels of displacement per unit "
                        "of height)")
    o.height_scale = float(scale)
    if rays is not None:
        o.rays = _int(command, "rays", rays)
    if slices is not None:
        o.slices = _int(command, "slices", slices)
        if o.slices == 0:  # 0 means "from rays" to the library
            raise _argument_error(f"{command}: slices must be in 1..{_lib.BB_MAX_SLICES} (got 0)")
    if filter_radius is not None:
        o.smooth.radius_texels = _int(command, "filter_radius", filter_radius)
    if filter_threshold is not None:
        o.smooth.threshold = float(filter_threshold)
    if bias is not None:
        o.trace.bias_texels = float(bias)
    if power is not None:
        o.power = float(power)
    basis_file = None
    if basis is not None:
        b, basis_file = _basis(basis)
        o.basis = b[0]
    if normal_filter is not None:
        o.normal_filter = _parse("bb_normal_filter_parse", "bb_normal_filter", normal_filter,
                                 "normal_filter")
    if normal_y is not None:
        o.normal_y_up = _normal_y_up(command, normal_y)
    if clamp is not None:
        o.smooth.addressing = _lib.BB_ADDRESS_CLAMP if clamp else _lib.BB_ADDRESS_PERIODIC
    if threads is not None:
        o.trace.threads = _int(command, "threads", threads)
    return o, basis_file


def _kinds_mask(command, kinds, what="outputs", noun="output"):
    kinds = (kinds,) if isinstance(kinds, str) else tuple(kinds)
    for k in kinds:
        if k not in _KINDS:
            raise _argument_error(f"{command}: unknown {noun} {k!r} "
                                  f"(one of {', '.join(OUTPUTS)})")
    if not kinds:
        raise _argument_error(f"{command}: nothing to make: {what} is empty")
    kinds = tuple(dict.fromkeys(kinds))
    return kinds, sum(1 << _KINDS[k][0] for k in kinds)


def _channel(channel):
    return _parse("bb_channel_parse", "bb_channel", channel, "channel")


def _height_field(command, height, channel):
    """The 1-channel bb_image the library bakes, by the library's channel rule
    (which also refuses NaN, infinite and empty heights). Free with bb_image_free."""
    src = _Image(f"{command}: height", height)
    which = _channel(channel)
    field = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_height_from_image(src.image, src.alpha, which, field, err)
    _check(st, err, arrays=True)
    return field


def _run_bake(command, height, channel, options):
    """bb_bake of an array: the result, to free with bb_bake_result_free, and
    the height field baked (to free with bb_image_free)."""
    err = _ffi.new("bb_error *")
    _check(_lib.bb_bake_options_check(options, err), err)  # bad options before a bad height
    field = _height_field(command, height, channel)
    result = _ffi.new("bb_bake_result *")
    st = _lib.bb_bake(field, options, result, err)  # cffi releases the GIL here
    if st != _lib.BB_OK:
        _lib.bb_image_free(field)
        _check(st, err, arrays=True)
    return result, field


def bake(height, scale, *, outputs=DEFAULT_OUTPUTS, rays=None, slices=None, filter_radius=None,
         filter_threshold=None, bias=None, power=None, basis=None, normal_filter=None,
         normal_y=None, clamp=None, channel="auto", threads=None):
    """Bakes the maps named in outputs from a height array in one pass and
    returns {name: float32 array}. See the module doc for the conventions."""
    kinds, mask = _kinds_mask("bake", outputs)
    o, _ = _bake_options("bake", scale, rays, slices, filter_radius, filter_threshold, bias,
                         power, basis, normal_filter, normal_y, clamp, threads)
    o.outputs = mask  # only these are computed
    result, field = _run_bake("bake", height, channel, o)
    try:
        return {k: _array(_lib.bb_bake_result_image(result, _KINDS[k][0])) for k in kinds}
    finally:
        _lib.bb_bake_result_free(result)
        _lib.bb_image_free(field)


def normal(height, scale, *, filter_radius=None, filter_threshold=None,
           normal_filter=None, normal_y=None, clamp=None, channel="auto"):
    """Smooths the height and returns its unit normals, float32 (H, W, 3),
    as `bumpbake normal` makes them (nothing is traced)."""
    o, _ = _bake_options("normal", scale, filter_radius=filter_radius,
                         filter_threshold=filter_threshold, normal_filter=normal_filter,
                         normal_y=normal_y, clamp=clamp)
    o.outputs = 1 << _lib.BB_OUTPUT_NORMAL
    result, field = _run_bake("normal", height, channel, o)
    try:
        return _array(result.normal)
    finally:
        _lib.bb_bake_result_free(result)
        _lib.bb_image_free(field)


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
    channel: "auto" (grey, or the mean of R, G, B; alpha when the image
        shows Valve's convention), "r", "g", "b", "a", "luma", "mean" or
        "valve".
    threads (bake): worker threads, default {DEFAULTS["threads"]} = all cores,
        0..4096; results are identical for any count.

Raises ArgumentError (a ValueError) with the library's message for a bad
parameter or height, TypeError for a wrong type, Error otherwise.
"""
bake.__doc__ += _PARAMETERS
normal.__doc__ += _PARAMETERS
