"""Bakes of numpy height arrays (bb_command_bake) and the bake options every baking
call shares, made from keyword arguments the way `bumpbake bake` makes them
from its options."""

import os

import numpy as np

from . import _command
from ._common import (_argument_error, _array, _check, _exception, _ffi,
                      _Image, _lib, _message, _parse, _parse_raw, _path, _progress_hooks, _shown,
                      _text)


def _output_kind_table():
    """{name: (bb_map_kind, needs trace, signed)} in the library's order."""
    table = {}
    for k in range(_lib.BB_MAP_BAKED_COUNT):
        info = _lib.bb_map_kind_get(k)
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
    """The defaults of bake's options, read by name from a new bake command
    (bb_command_value): what the command holds before anything is set."""
    c = _command.Command("bake", "bake")
    return {
        "rays": int(c.value("rays")),
        "filter_radius": int(c.value("filter-radius")),
        # held as a C float: its text (9 digits) is that float's exactly
        "filter_threshold": float(np.float32(c.value("filter-threshold"))),
        "bias": float(c.value("bias")),
        "power": float(c.value("power")),
        "basis": c.value("basis"),
        "normal_filter": c.value("normal-filter"),
        "normal_y": c.value("normal-y"),
        "clamp": c.value("clamp") == "1",
        "threads": int(c.value("threads")),
    }


# The library's defaults (a bake command's values), which the CLI uses too; a
# parameter left at None keeps them.
DEFAULTS = _library_defaults()

# The keyword arguments of every bake (bake(), bake_files(), sheet() ...):
# `bumpbake bake`'s options that are not about files, from the library's
# descriptions (scale and channel are named on their own).
BAKE_PARAMETERS = tuple(k for k in _command.keywords("bake", files=False)
                        if k not in ("scale", "channel"))


def _normal_y_up(command, normal_y):
    """normal_y ("down" or "up") by the library's parser of --normal-y
    (bb_option_parse)."""
    if not isinstance(normal_y, str):
        raise TypeError(f"{command}: normal_y must be a str (got {_shown(normal_y)})")
    st, up, err = _parse_raw("normal-y", normal_y, "normal_y")
    if st != _lib.BB_OK:
        raise _exception(st, f"{command}: {_message(err, st)}")
    return bool(up)


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
    v = np.require(v, requirements=("C", "A"))
    _check(_lib.bb_basis_from_vectors(_ffi.cast("const double (*)[3]", _ffi.from_buffer(v)),
                                      v.shape[0], out, err), err)
    return out, None


def basis(spec):
    """The unit directions of a basis, float64 (N, 3), in the order of the
    ssbump and weights channels a bake with basis=spec makes (spec as for
    bake())."""
    b, _ = _basis(spec)
    return np.array([[b.vector[c][k] for k in range(3)] for c in range(b.count)])


_IN_MEMORY = b"(array)"  # what an option naming a file reads when an array is given


class _BakeMaps:
    """The maps a bake of arrays multiplies by (bounce_albedo, brightness),
    each an array or a file's path: the option is set for the library's
    rules, the image handed to bb_command_bake. Keeps the images alive."""

    def __init__(self, command, values):
        self.images = {}
        self._keep, self._read = [], []
        for key in ("bounce_albedo", "brightness"):
            value = values.pop(key, None)
            if value is None:
                continue
            if isinstance(value, (str, bytes, os.PathLike)):
                command.set(key, value)
                img = _ffi.new("bb_image *")
                err = _ffi.new("bb_error *")
                _check(_lib.bb_image_read(_path(value, key), img, _ffi.NULL, err), err)
                self._read.append(img)
            else:
                command.set(key, _IN_MEMORY)
                src = _Image(f"{command.function}: {key}", value)
                self._keep.append(src)
                img = src.image
            self.images[key] = img

        # An (N, 3) array of directions has no command-line spelling: the
        # library makes the basis of it (bb_basis_from_vectors), handed over.
        spec = values.get("basis")
        self.basis = None
        if spec is not None and not isinstance(spec, (str, bytes, os.PathLike)):
            self.basis = _basis(values.pop("basis"))[0]

    def image(self, key):
        return self.images.get(key, _ffi.NULL)

    def free(self):
        for img in self._read:
            _lib.bb_image_free(img)
        self._read = []


def _bake_command(function, scale, options, mask, command="bake"):
    """The library's command for a bake of arrays: keywords set through its
    parsers, checked for images in memory with the maps asked (mask)."""
    c = _command.Command(command, function)
    options = dict(options)
    maps = _BakeMaps(c, options)
    c.set("scale", scale)
    c.set_all(options)
    c.in_memory(mask)
    c.check()
    return c, maps


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
    if channel is None:
        return _lib.BB_CHANNEL_AUTO
    return _parse("channel", channel, "channel")


def _height_field(command, height, channel):
    """The 1-channel bb_image the library bakes, by the library's channel rule
    (which also refuses NaN, infinite and empty heights). Free with bb_image_free."""
    src = _Image(f"{command}: height", height)
    which = channel if isinstance(channel, int) else _channel(channel)
    field = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_height_from_image(src.image, src.alpha, which, field, err)
    _check(st, err, arrays=True)
    return field


def _bake_maps(function, height, scale, options, mask, progress, command="bake",
               context=_ffi.NULL):
    """The maps asked (mask) of a height array, by bb_command_bake of the
    library's command: ({bb_map_kind: float32 array}, the changed
    (x, y, width, height)). progress(done, total) may return True to
    cancel; an exception it raises (Ctrl-C's KeyboardInterrupt included: the
    callback always runs, on this thread) cancels the bake and is raised once
    the library has stopped."""
    c, maps = _bake_command(function, scale, options, mask, command)
    field = None
    out = _ffi.new("bb_image[]", _lib.BB_MAP_BAKED_COUNT)
    try:
        field = _height_field(function, height, c.word("channel"))  # its bb_channel
        raised = []
        hooks, _keep = _progress_hooks(progress, raised)
        changed = _ffi.new("bb_region *")
        err = _ffi.new("bb_error *")
        st = _lib.bb_command_bake(c.handle, field, maps.image("bounce_albedo"),
                                  maps.image("brightness"),
                                  _ffi.NULL if maps.basis is None else maps.basis,
                                  hooks, context, out, changed, err)  # cffi releases the GIL
        if st != _lib.BB_OK:
            if raised:
                raise raised[0]
            _check(st, err, arrays=True)
        arrays = {k: _array(out[k]) for k in range(_lib.BB_MAP_BAKED_COUNT)
                  if mask & (1 << k)}
        return arrays, (changed.x0, changed.y0, changed.width, changed.height)
    finally:
        for k in range(_lib.BB_MAP_BAKED_COUNT):
            _lib.bb_image_free(_ffi.addressof(out, k))
        maps.free()
        if field is not None:
            _lib.bb_image_free(field)


def bake(height, scale, *, outputs=DEFAULT_OUTPUTS, progress=None, **options):
    """Bakes the maps named in outputs from a height array in one pass and
    returns {name: float32 array}. See the module doc for the conventions.
    Options: `bumpbake bake`'s that are not about files (BAKE_PARAMETERS,
    channel), named as its long options with '_' for '-'."""
    kinds, mask = _kinds_mask("bake", outputs)
    arrays, _ = _bake_maps("bake", height, scale, options, mask, progress)
    return {k: arrays[_KINDS[k][0]] for k in kinds}


class BakeContext:
    """Bakes of a height that changes a little at a time, as an editor or a
    live preview makes them (bb_bake_context with bb_bake_context_keep):
    the first bake is whole, and keeps what it made (about 4 x slices + 70
    bytes a texel: 141 MB at 1024 x 1024); each later bake() of a height of
    the same size with the same scale, outputs and options bakes again only
    what the change can reach, and returns exactly the maps bake() would.
    Inter-reflection (bounce) bakes whole every time. `changed` is the
    rectangle (x, y, width, height) of texels whose maps may differ from the
    bake before (the whole image after a whole bake, width 0 when nothing
    changed). One bake at a time; close() (or a with block) lets the kept
    bake go."""

    def __init__(self):
        out = _ffi.new("bb_bake_context **")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_bake_context_new(out, err), err)
        self._context = out[0]
        _lib.bb_bake_context_keep(self._context, 1)
        self.changed = (0, 0, 0, 0)

    def bake(self, height, scale, *, outputs=DEFAULT_OUTPUTS, progress=None, **options):
        """bake()'s maps of height, {name: float32 array}, baked again only
        where height changed since the last bake (same parameters as bake())."""
        if self._context is None:
            raise ValueError("BakeContext.bake: the context is closed")
        kinds, mask = _kinds_mask("BakeContext.bake", outputs)
        arrays, self.changed = _bake_maps("BakeContext.bake", height, scale, options, mask,
                                          progress, context=self._context)
        return {k: arrays[_KINDS[k][0]] for k in kinds}

    def close(self):
        if self._context is not None:
            _lib.bb_bake_context_free(self._context)
            self._context = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()


def normal(height, scale, *, progress=None, **options):
    """Smooths the height and returns its unit normals, float32 (H, W, 3),
    as `bumpbake normal` makes them (nothing is traced). Options: `bumpbake
    normal`'s that are not about files."""
    arrays, _ = _bake_maps("normal", height, scale, options, 1 << _lib.BB_MAP_NORMAL,
                           progress, command="normal")
    return arrays[_lib.BB_MAP_NORMAL]


_PARAMETERS = f"""

Parameters (as the command line's, named with '_' for '-'; None or
absent keeps the library's default):
    height: (H, W) heights, or (H, W, C) with C = 2 grey + alpha, 3 RGB,
        4 RGBA; float arrays are used as they are, unsigned integer ones as
        value / max code.
    outputs (bake): names from {", ".join(OUTPUTS)}; default
        {", ".join(DEFAULT_OUTPUTS)}. ssbump, ao and bent trace horizons.
    bounce_albedo, brightness: an array or an image file's path.
    progress: progress(done, total) may return True to cancel (Ctrl-C
        cancels too).
{{options}}
Raises ArgumentError (a ValueError) with the library's message for a bad
parameter or height, TypeError for a wrong type or an unknown keyword,
Error otherwise.
"""
bake.__doc__ += _PARAMETERS.format(options=_command.doc("bake", files=False))
BakeContext.bake.__doc__ += _PARAMETERS.format(options=_command.doc("bake", files=False))
normal.__doc__ += _PARAMETERS.format(options=_command.doc("normal", files=False))
